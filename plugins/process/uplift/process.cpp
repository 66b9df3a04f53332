// process uplift — rock uplift: a uniform rate, a layer of the terrain read over some years (the
// plates' 'uplift'), or the height change of a history (the loop node's second input); spread by the
// bending crust and tapered towards the sides held at base level (libs/landscape/uplift.hpp).
#include <orogen/landscape/uplift.hpp>

#include <orogen/landscape/processes.hpp>
#include <orogen/plugin.hpp>

namespace {

using namespace orogen;

class UpliftProcess final : public Process {
public:
    explicit UpliftProcess(const landscape::UpliftSpec& s) : s_(s) {}

    void start(ProcessState& state) override {
        const landscape::UpliftSources sources = landscape::to_sources(s_);
        const landscape::UpliftGrid grid{state.terrain(), state.tiling(), state.open()};
        rate_ = landscape::steady_uplift(sources, grid);
        if (const Value& history = state.node_input(1); history) {
            // Its frames map to history_years, else to the whole run.
            history_ = landscape::uplift_history(sources, grid, history.series(), state.run_years());
        }
    }

    void step(ProcessState& state, double dt) override {
        // The sub-step's span of the run's clock: [t + k·dt, t + (k+1)·dt], the last ending at the step's end.
        const int k = state.substep();
        const double t0 = state.time() + k * dt;
        const double t1 = k + 1 == state.substeps() ? state.time() + state.step_years() : state.time() + (k + 1) * dt;
        double* h = state.field(kElevation).data();
        double* uplifted = state.field(kUplifted).data();
        const auto n = std::int64_t(state.size());
        landscape::add_uplift(rate_.data(), state.outlets().data(), dt, h, uplifted, n);
        if (history_.rate)
            landscape::for_history_intervals(
                history_, history_k_, history_rate_, state.size(), t0, t1, [&](const double* rate, double overlap) {
                    landscape::add_uplift(rate, state.outlets().data(), overlap, h, uplifted, n);
                });
    }

private:
    landscape::UpliftSpec s_;
    std::vector<double> rate_;
    landscape::UpliftHistory history_;
    std::size_t history_k_ = std::size_t(-1);
    std::vector<double> history_rate_;
};

void check(ProcessCheckContext& ctx) {
    const std::string& layer = ctx.text("layer");
    const ValueInfo* history = ctx.node_input(1);
    if (history && !layer.empty())
        ctx.error("layer",
                  "give a layer or an uplift history (the node's second input), not both (the plates' "
                  "'uplift' layer is the sum of their history's height changes: it would count twice)");
    if (!history && ctx.given("history_years"))
        ctx.error("history_years",
                  "history_years spreads an uplift history; give one as the node's second input, e.g. "
                  "plates.timelapse");
    if (layer.empty() && ctx.given("layer_years"))
        ctx.error("layer_years", "layer_years scales an uplift layer; name one with layer");
    if (layer.empty() && !history && ctx.given("smoothing"))
        ctx.error("smoothing",
                  "smoothing spreads an uplift layer or history; name a layer with layer or give a "
                  "history as the node's second input");
    const ValueInfo* terrain = ctx.node_input(0);
    if (!layer.empty() && terrain && terrain->layers_known && !terrain->layers.count(layer))
        ctx.error("layer",
                  "no layer '" + layer + "' on the terrain (" + describe_layers(*terrain) +
                      "); tectonics:plates writes 'uplift', or give \"\" for none");
}

}  // namespace

OROGEN_PLUGIN("process-uplift", "0.1.0", registry) {
    const ProcessParams<landscape::UpliftSpec> p = landscape::uplift_params();
    registry.add(ProcessDescriptor{
        .name = "uplift",
        .summary = "rock uplift: a uniform rate, plus a layer read over years or a history's height changes",
        .description =
            "Raises every cell but the outlets by its rate each sub-step and counts what each received (the "
            "'uplifted' field, and layer). The rate is `rate` plus, with `layer`, that layer's metres gained over "
            "layer_years; or, with a history as the loop node's second input (plates.timelapse), the height "
            "change between its frames over the years they map to. Refuses a rate faster than any measured "
            "range (20 mm/yr).",
        .params = p.params(),
        .fields = {{kElevation, FieldAccess::updates, "m", "raised"},
                   {kUplifted, FieldAccess::updates, "m", "the uplift each cell received so far"}},
        .tile_halo = 1,  // tiled under mpirun within erode:stream-power's model (landscape/processes.hpp)
        .check = check,
        .make = [p](const ProcessCall& call) -> std::unique_ptr<Process> {
            return std::make_unique<UpliftProcess>(p.bind(call.params));
        },
    });
}
