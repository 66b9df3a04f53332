// process banks — rivers widen their valleys as they cut down (lateral erosion, after Langston & Tucker
// 2018): after each incision the two cells across a river are lowered by a share of the river's own
// lowering, the outer bank of a bend the most; large rivers push on past a bank cut down to its floor.
// libs/landscape/banks.hpp.
#include <orogen/landscape/banks.hpp>

#include <orogen/landscape/processes.hpp>
#include <orogen/plugin.hpp>

namespace {

using namespace orogen;

class BanksProcess final : public Process {
public:
    explicit BanksProcess(const landscape::BanksSpec& s) : banks_(landscape::to_banks(s)) {}

    void step(ProcessState& state, double dt) override {
        (void)dt;
        if (!banks_.any()) return;
        const FlowGraph& flow = state.flow();
        eroder_.erode(banks_, state.width(), state.height(), state.cell(),
                      {flow.directions.data(), flow.area.data(), state.outlets().data()},
                      state.field("incision").data(), state.field(kElevation).data());
    }

private:
    landscape::Banks banks_;
    landscape::BankEroder eroder_;
};

void check(ProcessCheckContext& ctx) {
    landscape::check_banks(ctx, [](std::string_view p) { return std::string(p); });
}

}  // namespace

OROGEN_PLUGIN("process-banks", "0.1.0", registry) {
    const ProcessParams<landscape::BanksSpec> p = landscape::banks_params();
    registry.add(ProcessDescriptor{
        .name = "banks",
        .summary = "rivers cut their banks as they cut down, widening their valley floors downstream",
        .description =
            "After each incision (it reads the incision field, so it comes after stream-power) the two cells "
            "across every river are lowered by `erosion` times the river's lowering, scaled by 1 - exp(-A/area), "
            "the outer bank of a bend taking more, never below the river plus floor_slope; rivers draining more "
            "than wide_area, wider_area and on push past a bank cut down to its floor, so floors widen "
            "downstream (Langston & Tucker 2018). Outlets stay.",
        .params = p.params(),
        .fields = {{kElevation, FieldAccess::updates, "m", "banks lowered"},
                   {kFlowGraph, FieldAccess::reads, "", "each river's direction and drainage area"},
                   {"incision", FieldAccess::reads, "m", "the river's lowering this sub-step"}},
        .tile_halo = 1,  // tiled under mpirun within erode:stream-power's model (landscape/processes.hpp)
        .check = check,
        .make = [p](const ProcessCall& call) -> std::unique_ptr<Process> {
            return std::make_unique<BanksProcess>(p.bind(call.params));
        },
    });
}
