// process banks — rivers widen their valleys as they cut down (lateral erosion, after Langston & Tucker
// 2018): after each incision the two cells across a river are lowered by a share of the river's own
// lowering, the outer bank of a bend the most; large rivers push on past a bank cut down to its floor.
// libs/landscape/banks.hpp.
#include <orogen/landscape/banks.hpp>

#include <orogen/parallel.hpp>
#include <orogen/plugin.hpp>

#include <cmath>
#include <numbers>

namespace {

using namespace orogen;

struct BankSettings {
    double erosion = 4.0;
    double area = 1e6;  // m²
    double floor_slope = 1.0;  // °
    double wide_area = 0.0;  // m²
    double wider_area = 0.0;  // m²
    int widest_floor = 0;  // cells
};

class BanksProcess final : public Process {
public:
    explicit BanksProcess(const BankSettings& s) {
        constexpr double rad = std::numbers::pi / 180.0;
        banks_.erosion = s.erosion;
        banks_.area = s.area;
        banks_.floor_slope = std::tan(s.floor_slope * rad);
        banks_.wide_area = s.wide_area;
        banks_.wider_area = s.wider_area;
        banks_.widest_floor = s.widest_floor;
    }

    void step(ProcessState& state, double dt) override {
        (void)dt;
        if (!banks_.any()) return;
        const FlowGraph& flow = state.flow();
        dir_.resize(state.size());
        parallel_for(0, std::int64_t(dir_.size()), 1 << 15, [&](std::int64_t b, std::int64_t e) {
            for (std::int64_t i = b; i < e; ++i) dir_[std::size_t(i)] = std::int8_t(flow.direction(i));
        });
        eroder_.erode(banks_, state.width(), state.height(), state.cell(), dir_.data(), flow.area.data(),
                      state.field("incision").data(), state.outlets().data(), state.field(kElevation).data());
    }

private:
    landscape::Banks banks_;
    landscape::BankEroder eroder_;
    std::vector<std::int8_t> dir_;  // each cell's direction to its receiver
};

void check(ProcessCheckContext& ctx) {
    if (ctx.real("wider_area") > 0.0) {
        if (!(ctx.real("wide_area") > 0.0))
            ctx.error("wider_area", "wider_area widens the floors wide_area makes; give wide_area as well");
        else if (ctx.real("wider_area") < ctx.real("wide_area"))
            ctx.error("wider_area",
                      "wider_area is smaller than wide_area: the seven-cell floors start where the "
                      "five-cell ones do at the earliest; give wider_area >= wide_area");
    }
    if (const auto widest = ctx.integer("widest_floor"); widest > 0) {
        if (widest % 2 == 0 || widest < 7)
            ctx.error("widest_floor",
                      "widest_floor is " + std::to_string(widest) +
                          ": floors are an odd number of cells wide, the river in the middle, and "
                          "seven or more (wider_area makes seven); give 7, 9, 11, …");
        else if (!(ctx.real("wider_area") > ctx.real("wide_area") && ctx.real("wide_area") > 0.0))
            ctx.error("widest_floor",
                      "widest_floor widens the floors past seven cells each time the drainage area "
                      "grows by wider_area / wide_area; give wider_area > wide_area > 0");
    }
}

}  // namespace

OROGEN_PLUGIN("process-banks", "0.1.0", registry) {
    ProcessParams<BankSettings> p;
    p.real(&BankSettings::erosion, "erosion")
        .min(0.0)
        .max(10.0)
        .help(
            "each incision lowers the two cells across a river by this many times the river's own lowering, "
            "shared between them (straight on, half each; at a bend the outer bank takes more), never below the "
            "river; 4 = a floor three cells wide; 0 = banks stand");
    p.real(&BankSettings::area, "area")
        .min(1.0)
        .max(1e12)
        .unit("m²")
        .help(
            "drainage area over which a river is wide and deep enough to undercut its banks: bank erosion is "
            "scaled by 1 - exp(-A/area)");
    p.real(&BankSettings::floor_slope, "floor_slope")
        .min(0.0)
        .max(30.0)
        .unit("°")
        .help(
            "a bank the river has cut down still rises from the river at this angle, as the aprons along a "
            "valley's foot do (0 = dead flat floors, which hold pits)");
    p.real(&BankSettings::wide_area, "wide_area")
        .min(0.0)
        .max(1e12)
        .unit("m²")
        .help(
            "rivers draining more keep floors five cells wide rather than three: a bank cut down to its floor "
            "passes the river's push on to the cell beyond it; 0 = three cells everywhere");
    p.real(&BankSettings::wider_area, "wider_area")
        .min(0.0)
        .max(1e12)
        .unit("m²")
        .help("rivers draining more (and wide_area) keep floors seven cells wide; 0 = five cells at most");
    p.integer(&BankSettings::widest_floor, "widest_floor")
        .min(0)
        .max(35)
        .unit("cells")
        .help(
            "floors keep widening past seven cells, two cells more each time the drainage area grows by "
            "wider_area / wide_area, up to this many; each two cells cost a pass; 0 = seven at most");
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
        .check = check,
        .make = [p](const ProcessCall& call) -> std::unique_ptr<Process> {
            return std::make_unique<BanksProcess>(p.bind(call.params));
        },
    });
}
