// process flow — water routing, once a step: D8 (or multiple flow directions for the drainage area),
// pits resolved over the basin graph (Cordonnier et al. 2019), drainage area accumulated (weighed by
// the rain_factor field when a rain process makes one). Publishes the flow graph the later processes
// share (fastscapelib's FlowGraph idea): made once, read by stream power, banks, floodplains.
#include <orogen/landscape/flow.hpp>
#include <orogen/landscape/stream_power.hpp>

#include <orogen/landscape/processes.hpp>
#include <orogen/parallel.hpp>
#include <orogen/plugin.hpp>

namespace {

using namespace orogen;

class FlowProcess final : public Process {
public:
    explicit FlowProcess(const landscape::FlowSpec& s)
        : mode_(landscape::to_depressions(s)), mfd_(landscape::to_mfd_exponent(s)) {}

    void start(ProcessState& state) override {
        const auto& outlets = state.outlets();
        std::int64_t sink = 0;  // with every side closed, the one outlet
        if (!state.open().any())
            for (std::size_t i = 0; i < outlets.size(); ++i)
                if (outlets[i]) {
                    sink = std::int64_t(i);
                    break;
                }
        router_.emplace(state.width(), state.height(), state.cell(), state.open(), sink);
    }

    void step(ProcessState& state, double dt) override {
        (void)dt;
        route(state, state.field(kElevation).data());
        pits_ += router_->pits();
    }

    /// The final surface's graph (a copy of the heights routed: lakes are not filled into the result), as
    /// the layers drainage and flow_direction, and published for the processes' finish (chi).
    void finish(ProcessState& state, Heightmap& out) override {
        std::vector<double> copy = state.field(kElevation);
        route(state, copy.data());
        const auto& area = router_->area();
        GridView drainage = out.layer("drainage", 0.0f);
        GridView direction = out.layer("flow_direction", -1.0f);
        for (std::size_t i = 0; i < area.size(); ++i) {
            drainage.data[i] = float(area[i]);
            direction.data[i] = float(directions_[i]);
        }
    }

    std::string summary() const override { return std::to_string(pits_) + " pits resolved"; }

private:
    void route(ProcessState& state, double* h) {
        const std::vector<double>& rain = state.field("rain_factor");
        const double* weight = rain.empty() ? nullptr : rain.data();
        router_->route(h, mode_);
        if (mfd_ > 0.0) router_->accumulate_multiple(h, mfd_, weight);
        else router_->accumulate(weight);
        FlowGraph g;
        g.width = state.width();
        g.height = state.height();
        g.cell = state.cell();
        g.receivers = router_->receivers();
        g.stack = router_->stack();
        g.chunks = router_->chunks();
        g.area = router_->area();
        g.outlets = router_->outlets();
        g.pits = router_->pits();
        // Each cell's direction to its receiver, once a step (banks and floodplains read it every sub-step).
        directions_.resize(router_->size());
        parallel_for(0, std::int64_t(directions_.size()), 1 << 15, [&](std::int64_t b, std::int64_t e) {
            for (std::int64_t i = b; i < e; ++i) directions_[std::size_t(i)] = std::int8_t(router_->direction(i));
        });
        g.directions = directions_;
        g.multiple = mfd_ > 0.0;
        state.set_flow(g);
    }

    landscape::Depressions mode_;
    double mfd_;
    std::optional<landscape::FlowRouter> router_;
    std::vector<std::int8_t> directions_;
    std::int64_t pits_ = 0;
};

void check(ProcessCheckContext& ctx) {
    if (ctx.text("routing") == "mfd" && ctx.text("depressions") == "route")
        ctx.error("routing",
                  "multiple flow directions need filled lakes (water crossing an unfilled lake would "
                  "flow back into it); use depressions=fill or routing=d8");
    if (ctx.text("routing") != "mfd" && ctx.given("mfd_exponent"))
        ctx.error("mfd_exponent", "mfd_exponent weights multiple flow directions; give routing=mfd as well");
}

}  // namespace

OROGEN_PLUGIN("process-flow", "0.1.0", registry) {
    const ProcessParams<landscape::FlowSpec> p = landscape::flow_params();
    registry.add(ProcessDescriptor{
        .name = "flow",
        .summary = "water routing once a step: D8 or multiple directions, lakes resolved, drainage area",
        .description =
            "Routes water over the current heights once a step (its first sub-step): each cell's receiver is its "
            "steepest lower neighbour; pits are resolved over the basin graph, each lake spilling at its lowest "
            "pass (Cordonnier et al. 2019), and with depressions=fill filled to it. Accumulates the drainage "
            "area (m², weighed by rain_factor when a rain process before it makes one) and publishes the flow "
            "graph. After the run: the layers drainage (m²) and flow_direction (0 east, 1 south-east, ... 7 "
            "north-east; -1 at an outlet) of the final surface.",
        .params = p.params(),
        .fields = {{kElevation, FieldAccess::updates, "m", "lakes filled to their spill level (depressions=fill)"},
                   {"rain_factor", FieldAccess::reads_if_present, "1", "rain over the background: weighs the area"},
                   {kFlowGraph, FieldAccess::writes, "", "receivers, stack and drainage area (m²)"}},
        .cadence = Cadence::once_per_step,
        .adds_layers = {"drainage", "flow_direction"},
        .tile_halo = 1,  // tiled under mpirun within erode:stream-power's model (landscape/processes.hpp)
        .check = check,
        .make = [p](const ProcessCall& call) -> std::unique_ptr<Process> {
            return std::make_unique<FlowProcess>(p.bind(call.params));
        },
    });
}
