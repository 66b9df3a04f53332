// process floodplains — large rivers plane their valley floors: every cell within a river's floodplain
// half-width W(A) = width·(A/area)^exponent is lowered to its nearest such river plus a gentle slope
// (never raised), along reaches gentler than max_slope. libs/landscape/floodplain.hpp.
#include <orogen/landscape/floodplain.hpp>

#include <orogen/parallel.hpp>
#include <orogen/plugin.hpp>

#include <cmath>
#include <numbers>

namespace {

using namespace orogen;

struct Floodplains {
    double area = 2e6;  // m²
    double width = 30.0;  // m
    double exponent = 0.5;
    double slope = 2.0;  // °
    double max_slope = 0.0;  // °
};

class FloodplainsProcess final : public Process {
public:
    explicit FloodplainsProcess(const Floodplains& s) {
        constexpr double rad = std::numbers::pi / 180.0;
        fp_.area = s.area;
        fp_.width = s.width;
        fp_.exponent = s.exponent;
        fp_.slope = std::tan(s.slope * rad);
        fp_.max_slope = std::tan(s.max_slope * rad);
    }

    void step(ProcessState& state, double dt) override {
        (void)dt;
        if (!fp_.any()) return;
        const FlowGraph& flow = state.flow();
        dir_.resize(state.size());
        parallel_for(0, std::int64_t(dir_.size()), 1 << 15, [&](std::int64_t b, std::int64_t e) {
            for (std::int64_t i = b; i < e; ++i) dir_[std::size_t(i)] = std::int8_t(flow.direction(i));
        });
        landscape::carve_floodplains(fp_, state.width(), state.height(), state.cell(), dir_.data(), flow.area.data(),
                                     state.outlets().data(), state.field(kElevation).data(), nearest_, floor_);
    }

private:
    landscape::Floodplain fp_;
    std::vector<std::int8_t> dir_;
    std::vector<double> nearest_, floor_;  // scratch
};

}  // namespace

OROGEN_PLUGIN("process-floodplains", "0.1.0", registry) {
    ProcessParams<Floodplains> p;
    p.real(&Floodplains::area, "area")
        .min(0.0)
        .max(1e12)
        .unit("m²")
        .help("rivers draining more than this have floodplains (3e6 = from 3 km²); 0 = none");
    p.real(&Floodplains::width, "width")
        .min(0.0, true)
        .max(1e5)
        .unit("m")
        .help("the floodplain's half-width for a river draining `area`");
    p.real(&Floodplains::exponent, "exponent")
        .min(0.0)
        .max(1.0)
        .help(
            "how fast floodplains widen downstream: half-width ∝ A^exponent (real 30 m valleys widen as "
            "A^0.2-0.3 10 m above their rivers)");
    p.real(&Floodplains::slope, "slope")
        .min(0.0)
        .max(30.0)
        .unit("°")
        .help("a floodplain rises from its river at this angle (0 = dead flat, which holds pits)");
    p.real(&Floodplains::max_slope, "max_slope")
        .min(0.0)
        .max(60.0)
        .unit("°")
        .help(
            "only rivers no steeper than this (to their receiver) plane a floodplain, as real ones lie along "
            "gentle reaches and none in gorges (2.3 = a 4 % gradient); 0 = every river");
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
        .make = [p](const ProcessCall& call) -> std::unique_ptr<Process> {
            return std::make_unique<FloodplainsProcess>(p.bind(call.params));
        },
    });
}
