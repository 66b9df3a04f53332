// process floodplains — large rivers plane their valley floors: every cell within a river's floodplain
// half-width W(A) = width·(A/area)^exponent is lowered to its nearest such river plus a gentle slope
// (never raised), along reaches gentler than max_slope. libs/landscape/floodplain.hpp.
#include <orogen/landscape/floodplain.hpp>

#include <orogen/landscape/processes.hpp>
#include <orogen/plugin.hpp>

namespace {

using namespace orogen;

class FloodplainsProcess final : public Process {
public:
    explicit FloodplainsProcess(const landscape::FloodplainsSpec& s) : fp_(landscape::to_floodplain(s)) {}

    void step(ProcessState& state, double dt) override {
        (void)dt;
        if (!fp_.any()) return;
        const FlowGraph& flow = state.flow();
        landscape::carve_floodplains(fp_, state.width(), state.height(), state.cell(),
                                     {flow.directions.data(), flow.area.data(), state.outlets().data()},
                                     state.field(kElevation).data(), nearest_, floor_);
    }

private:
    landscape::Floodplain fp_;
    std::vector<double> nearest_, floor_;  // scratch
};

}  // namespace

OROGEN_PLUGIN("process-floodplains", "0.1.0", registry) {
    const ProcessParams<landscape::FloodplainsSpec> p = landscape::floodplains_params();
    registry.add(ProcessDescriptor{
        .name = "floodplains",
        .summary = "large rivers plane floodplains: floors lowered to the river plus a gentle slope",
        .description =
            "Each sub-step every cell within the half-width width·(A/area)^exponent of a river draining more "
            "than `area` (along a reach no steeper than max_slope) is lowered to its nearest such river plus "
            "`slope` over the distance, never raised. Outlets stay.",
        .params = p.params(),
        .fields = {{kElevation, FieldAccess::updates, "m", "floors planed"},
                   {kFlowGraph, FieldAccess::reads, "", "the rivers and their drainage area"}},
        .tile_halo = 1,  // tiled under mpirun within erode:stream-power's model (landscape/processes.hpp)
        .make = [p](const ProcessCall& call) -> std::unique_ptr<Process> {
            return std::make_unique<FloodplainsProcess>(p.bind(call.params));
        },
    });
}
