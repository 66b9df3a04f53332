// process uplift — rock uplift: a uniform rate, a layer of the terrain read over some years (the
// plates' 'uplift'), or the height change of a history (the loop node's second input); spread by the
// bending crust and tapered towards the sides held at base level (libs/landscape/uplift.hpp).
#include <orogen/landscape/uplift.hpp>

#include <orogen/plugin.hpp>

namespace {

using namespace orogen;

struct Uplift {
    double rate = 1.0;  // mm/yr
    std::string layer;
    double layer_years = 1e6;  // yr
    double smoothing = 0.0;  // m
    double edge_taper = 0.0;  // m
    double history_years = 0.0;  // yr (0: the run's)
};

class UpliftProcess final : public Process {
public:
    explicit UpliftProcess(const Uplift& s) : s_(s) {}

    void start(ProcessState& state) override {
        const landscape::UpliftSources sources{s_.rate,          s_.layer, s_.layer_years, s_.smoothing, s_.edge_taper,
                                               s_.history_years, ""};
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
    Uplift s_;
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
    ProcessParams<Uplift> p;
    p.real(&Uplift::rate, "rate")
        .min(0.0)
        .max(landscape::kMaxUpliftMmYr)
        .unit("mm/yr")
        .help("uniform rock uplift rate (0.1-10 mm/yr in active ranges)");
    p.text(&Uplift::layer, "layer")
        .help("a layer of the terrain read as uplift (m) gained over layer_years, added to `rate`; \"\" = none");
    p.real(&Uplift::layer_years, "layer_years")
        .min(1.0)
        .max(1e9)
        .unit("yr")
        .help("years over which the layer's metres were gained (1e6: metres per Myr = mm/yr)");
    p.real(&Uplift::smoothing, "smoothing")
        .min(0.0)
        .max(1e6)
        .unit("m")
        .help("spread the layer's or history's uplift over about this distance (flexure of the crust; 0 = as is)");
    p.real(&Uplift::edge_taper, "edge_taper")
        .min(0.0)
        .max(1e6)
        .unit("m")
        .help(
            "all of the uplift falls smoothly to zero over this distance towards the open sides, as a range's "
            "falls to its foreland (0 = the same right up to the sides)");
    p.real(&Uplift::history_years, "history_years")
        .min(0.0)
        .max(1e9)
        .unit("yr")
        .help("the years the history's frames span, its first frame year 0 of the run (0 = the run's years)");
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
        .check = check,
        .make = [p](const ProcessCall& call) -> std::unique_ptr<Process> {
            return std::make_unique<UpliftProcess>(p.bind(call.params));
        },
    });
}
