// process glaciers — valley glaciers' ice and the erosion it adds to the rivers': ice gathers above the
// ELA, flows down the flow graph (a river of ice), and where its flux is a glacier's it erodes
// K_g·Q^m_g·S^n in stream-power's implicit sweep, which comes after it. The troughs process carves the
// U-shaped valleys. libs/landscape/glaciers.hpp.
#include <orogen/landscape/glaciers.hpp>
#include <orogen/landscape/processes.hpp>

#include <orogen/parallel.hpp>
#include <orogen/plugin.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace {

using namespace orogen;

class GlaciersProcess final : public Process {
public:
    explicit GlaciersProcess(const landscape::GlaciersSpec& s)
        : glaciers_(landscape::to_glaciers(s, landscape::TroughsSpec{})) {}

    void step(ProcessState& state, double dt) override {
        const FlowGraph& flow = state.flow();
        std::vector<double>& ice = state.field("ice_flux");
        landscape::ice_flux(glaciers_, state.field(kElevation).data(), flow.stack.data(), flow.receivers.data(),
                            state.size(), state.cell(), ice);
        // K_g·dt·Q^m_g where the ice is a glacier (not at an outlet or a pit); stream-power divides by L^n.
        std::vector<double>& factor = state.field("glacial_factor");
        factor.assign(state.size(), 0.0);
        const landscape::Glaciers& g = glaciers_;
        parallel_for(0, std::int64_t(state.size()), 1 << 14, [&](std::int64_t b, std::int64_t e) {
            for (std::int64_t i = b; i < e; ++i)
                if (ice[std::size_t(i)] >= g.glacier_flux && flow.receivers[std::size_t(i)] != std::int32_t(i))
                    factor[std::size_t(i)] = g.erodibility * dt * std::pow(ice[std::size_t(i)], g.flux_exponent);
        });
    }

    /// The last step's ice flux as the layer ice_flux (m³/yr).
    void finish(ProcessState& state, Heightmap& out) override {
        const std::vector<double>& ice = state.field("ice_flux");
        for (const double q : ice) {
            glaciated_ += q >= glaciers_.glacier_flux ? 1 : 0;
            largest_ = std::max(largest_, q);
        }
        GridView q = out.layer("ice_flux", 0.0f);
        for (std::size_t i = 0; i < out.size() && i < ice.size(); ++i) q.data[i] = float(ice[i]);
    }

    std::string summary() const override {
        std::ostringstream s;
        s << glaciated_ << " cells under glaciers at the end, the largest ice flux " << largest_ << " m³/yr";
        return s.str();
    }

private:
    landscape::Glaciers glaciers_;
    std::int64_t glaciated_ = 0;
    double largest_ = 0.0;  // m³/yr
};

}  // namespace

OROGEN_PLUGIN("process-glaciers", "0.1.0", registry) {
    const ProcessParams<landscape::GlaciersSpec> p = landscape::glaciers_params();
    registry.add(ProcessDescriptor{
        .name = "glaciers",
        .summary = "valley glaciers: ice above the ELA flows down the valleys and erodes K_g Q^m_g S^n",
        .description =
            "Each sub-step routes ice down the flow graph: every cell adds its mass balance min(gradient*(z - ELA), "
            "max_balance) over its area to the ice it receives and passes on what is left (Braun et al. 1999's "
            "river of ice). Where the flux reaches min_flux the ice slides and erodes K_g*Q^m_g*S^n, solved in "
            "stream-power's implicit sweep (which must follow, with deposition=0; n is stream-power's). "
            "troughs(), after the incision, widens its valleys into U-shaped troughs. After the run: the layer "
            "ice_flux (m³/yr).",
        .params = p.params(),
        .fields = {{kElevation, FieldAccess::reads, "m", ""},
                   {kFlowGraph, FieldAccess::reads, "", "the ice follows the rivers"},
                   {"ice_flux", FieldAccess::writes, "m³/yr", "each cell's ice flux"},
                   {"glacial_factor", FieldAccess::writes, "m^(1-3m_g)·yr^m_g", "K_g·dt·Q^m_g of glacier cells"}},
        .adds_layers = {"ice_flux"},
        .tile_halo = 1,  // tiled under mpirun within erode:stream-power's model (landscape/processes.hpp)
        .make = [p](const ProcessCall& call) -> std::unique_ptr<Process> {
            return std::make_unique<GlaciersProcess>(p.bind(call.params));
        },
    });
}
