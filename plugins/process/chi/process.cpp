// process chi — the rivers' χ (Perron & Royden 2013) of the final surface: χ = ∫ (A_0/A)^(m/n) dx from the
// outlet upstream, the coordinate in which a steady river of uniform rock and uplift is a straight line. An
// analysis, not a change: it only writes the layer chi after the run.
#include <orogen/landscape/processes.hpp>

#include <orogen/plugin.hpp>

#include <cmath>

namespace {

using namespace orogen;

class ChiProcess final : public Process {
public:
    explicit ChiProcess(const landscape::ChiSpec& s) : s_(s) {}

    void step(ProcessState& state, double dt) override {
        (void)state;
        (void)dt;
    }

    /// After flow's finish() published the final surface's graph.
    void finish(ProcessState& state, Heightmap& out) override {
        const FlowGraph& flow = state.flow();
        std::vector<double> chi(state.size(), 0.0);
        for (const std::int32_t i : flow.stack) {  // receivers first
            const std::int32_t r = flow.receivers[std::size_t(i)];
            if (r == i) continue;
            chi[std::size_t(i)] = chi[std::size_t(r)] +
                std::pow(s_.reference_area / flow.area[std::size_t(i)], s_.concavity) * flow.distance(i);
        }
        GridView layer = out.layer("chi", 0.0f);
        for (std::size_t i = 0; i < chi.size(); ++i) layer.data[i] = float(chi[i]);
    }

private:
    landscape::ChiSpec s_;
};

}  // namespace

OROGEN_PLUGIN("process-chi", "0.1.0", registry) {
    const ProcessParams<landscape::ChiSpec> p = landscape::chi_params();
    registry.add(ProcessDescriptor{
        .name = "chi",
        .summary = "the rivers' chi of the final surface, as a layer (m)",
        .description = "After the run (it comes after flow, whose graph of the final surface it reads): chi = "
                       "integral of (reference_area/A)^concavity dx from each outlet upstream, the layer chi (m).",
        .params = p.params(),
        .fields = {{kFlowGraph, FieldAccess::reads, "", "the final surface's receivers and drainage area"}},
        .adds_layers = {"chi"},
        .tile_halo = 1,  // tiled under mpirun within erode:stream-power's model (landscape/processes.hpp)
        .make = [p](const ProcessCall& call) -> std::unique_ptr<Process> {
            return std::make_unique<ChiProcess>(p.bind(call.params));
        },
    });
}
