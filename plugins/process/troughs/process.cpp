// process troughs — glaciers widen their valleys into U-shaped troughs: every cell within a glacier's
// half-width R = R0·(Q/10⁶ m³/yr)^0.4 (Bahr 1997) is held below a parabola across the valley whose walls
// reach wall_angle at the margin. Reads the ice flux a glaciers process made. libs/landscape/glaciers.hpp.
#include <orogen/landscape/glaciers.hpp>
#include <orogen/landscape/processes.hpp>

#include <orogen/plugin.hpp>

namespace {

using namespace orogen;

class TroughsProcess final : public Process {
public:
    explicit TroughsProcess(const landscape::TroughsSpec& s) {
        landscape::GlaciersSpec ice;
        ice.min_flux = s.min_flux;
        glaciers_ = landscape::to_glaciers(ice, s);
    }

    void step(ProcessState& state, double dt) override {
        (void)dt;
        landscape::carve_troughs(glaciers_, state.field(kElevation).data(), state.field("ice_flux"),
                                 state.flow().receivers.data(), state.width(), state.height(), state.cell());
    }

private:
    landscape::Glaciers glaciers_;
};

}  // namespace

OROGEN_PLUGIN("process-troughs", "0.1.0", registry) {
    const ProcessParams<landscape::TroughsSpec> p = landscape::troughs_params();
    registry.add(ProcessDescriptor{
        .name = "troughs",
        .summary = "glaciers carve U-shaped troughs as wide as their ice flux asks",
        .description =
            "Each sub-step, after the incision, every cell within a glacier's half-width (half_width at 1e6 m³/yr, "
            "growing as Q^0.4) is held below a parabola across the valley whose walls reach wall_angle at the "
            "glacier's margin, following the glacier's gradient down the valley: V-shaped river valleys turn "
            "U-shaped and the heads, where the ice starts, into cirques.",
        .params = p.params(),
        .fields = {{kElevation, FieldAccess::updates, "m", "troughs carved"},
                   {kFlowGraph, FieldAccess::reads, "", "the glaciers' direction"},
                   {"ice_flux", FieldAccess::reads, "m³/yr", "from glaciers()"}},
        .tile_halo = 1,  // tiled under mpirun within erode:stream-power's model (landscape/processes.hpp)
        .make = [p](const ProcessCall& call) -> std::unique_ptr<Process> {
            return std::make_unique<TroughsProcess>(p.bind(call.params));
        },
    });
}
