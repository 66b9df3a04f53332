// model_node.cpp — a node that runs erode:stream-power's model (see model_node.hpp).
#include <orogen/landscape/model_node.hpp>

#include <orogen/landscape/tiled.hpp>

#include <orogen/error.hpp>
#include <orogen/timelapse.hpp>

#include <algorithm>
#include <chrono>
#include <functional>
#include <memory>
#include <sstream>

namespace orogen::landscape {

namespace {

/// The model of one process (Model) or of this rank's tile (TiledModel, joined with the other ranks'
/// tiles: the same bits as one process), behind the few calls the node makes.
struct Engine {
    std::unique_ptr<Model> whole;
    std::unique_ptr<TiledModel> tiled;

    std::vector<double>& heights() { return tiled ? tiled->heights() : whole->heights(); }
    bool is_outlet(std::size_t i) const {
        return tiled ? tiled->is_outlet(i) : whole->flow().is_outlet(std::int64_t(i));
    }
    void run(double years, double dt, const std::function<void(std::int64_t, std::int64_t)>& on_step) {
        if (tiled) tiled->run(years, dt, on_step);
        else whole->run(years, dt, on_step);
    }
    void route_only() {
        if (tiled) tiled->route_only();
        else whole->route_only();
    }
    std::int64_t pits() const { return tiled ? tiled->pits() : whole->flow().pits(); }
    std::int64_t first_non_finite() const { return tiled ? tiled->first_non_finite() : whole->first_non_finite(); }
    const std::vector<double>& area() const { return tiled ? tiled->area() : whole->flow().area(); }
    int direction(std::size_t i) const {
        return tiled ? tiled->direction(i) : whole->flow().direction(std::int64_t(i));
    }
    const std::vector<double>& uplifted() const { return tiled ? tiled->uplifted() : whole->uplifted(); }
    std::vector<double> chi() { return tiled ? tiled->chi(1.0) : whole->chi(1.0); }
};

/// The heights after the run and the final surface's flow graph as layers: drainage, flow_direction,
/// eroded (what the surface processes did: negative where rock was removed, positive where sediment
/// settled, as the other eroders' layer), uplifted (the rock uplift, kept apart so that on a rising range
/// `eroded` does not read +400 m where the rivers removed 100 m of 500 m of uplift) and chi if asked.
void write_layers(NodeContext& ctx, Heightmap& hm, Engine& engine, std::int64_t last, const ModelRun& run) {
    const std::size_t n = hm.size();
    const std::vector<double>& heights = engine.heights();
    const std::vector<float> before = hm.heights();
    std::vector<float>& out = hm.heights();
    for (std::size_t i = 0; i < n; ++i) out[i] = float(heights[i]);
    ctx.check_finite(out, "height", last);
    engine.route_only();
    GridView drainage = hm.layer("drainage", 0.0f);
    GridView direction = hm.layer("flow_direction", -1.0f);
    const auto& area = engine.area();
    for (std::size_t i = 0; i < n; ++i) {
        drainage.data[i] = float(area[i]);
        direction.data[i] = float(engine.direction(i));
    }
    const std::vector<double>& rock_uplift = engine.uplifted();
    GridView eroded = hm.layer("eroded", 0.0f);
    GridView uplifted = hm.layer("uplifted", 0.0f);
    for (std::size_t i = 0; i < n; ++i) {
        eroded.data[i] += float(double(out[i]) - double(before[i]) - rock_uplift[i]);
        uplifted.data[i] += float(rock_uplift[i]);
    }
    if (run.settings.glaciers.any() && engine.whole) {  // glaciers never tile: the whole grid's model
        const std::vector<double>& ice = engine.whole->ice_flux();
        GridView q = hm.layer("ice_flux", 0.0f);
        for (std::size_t i = 0; i < n && i < ice.size(); ++i) q.data[i] = float(ice[i]);
    }
    if (run.settings.orographic_rain) {
        const std::vector<double> rain = engine.tiled ? engine.tiled->rain() : engine.whole->rain();
        GridView r = hm.layer("rain", 0.0f);
        for (std::size_t i = 0; i < n && i < rain.size(); ++i) r.data[i] = float(rain[i]);
    }
    if (run.chi) {
        const std::vector<double> chi = engine.chi();
        GridView c = hm.layer("chi", 0.0f);
        for (std::size_t i = 0; i < n; ++i) c.data[i] = float(chi[i]);
    }
}

}  // namespace

NodeOutputs run_model(NodeContext& ctx, const ModelRun& run) {
    auto hm = ctx.take_heightmap(0);
    Tiling* tiles = ctx.tiling();
    using clock = std::chrono::steady_clock;
    const auto started = clock::now();
    const std::size_t n = hm->size();
    const Settings& s = run.settings;
    const UpliftSources& sources = run.uplift;
    const UpliftGrid grid{*hm, tiles, s.open};
    std::vector<double> uplift = steady_uplift(sources, grid);
    UpliftHistory history;
    if (ctx.has_input(1)) {
        std::shared_ptr<const Series> series;  // rank 0's, whole frames
        if (!tiles || tiles->rank() == 0) series = ctx.input(1).series();
        history = uplift_history(sources, grid, series, ctx.real("years"));
    }
    const auto base = *parse_base_level(ctx.text("base_level"));

    Engine engine;
    std::vector<double> h(hm->heights().begin(), hm->heights().end());
    if (tiles) engine.tiled = std::make_unique<TiledModel>(*tiles, hm->cell(), std::move(h), std::move(uplift), s);
    else
        engine.whole =
            std::make_unique<Model>(hm->width(), hm->height(), hm->cell(), std::move(h), std::move(uplift), s);
    if (history.rate) {
        if (tiles) engine.tiled->set_uplift_history(std::move(history));
        else engine.whole->set_uplift_history(std::move(history));
    }
    std::vector<double>& heights = engine.heights();
    if (base) {
        for (std::size_t i = 0; i < n; ++i)
            if (engine.is_outlet(i)) heights[i] = *base;
    }
    const double years = ctx.real("years"), dt = ctx.real("dt");
    constexpr double kSecondsPerYear = 31'557'600.0;  // the series' clock is in seconds (Julian years)
    const std::int64_t every = ctx.integer("timelapse_every");
    // In a tiled run rank 0 gathers the frames.
    Timelapse lapse = tiles ? Timelapse(every, dt * kSecondsPerYear, *tiles) : Timelapse(every, dt * kSecondsPerYear);
    lapse.record(0, *hm);
    std::vector<float> frame;
    std::int64_t pits = 0, last = 0;
    int rounds = 0;
    double sediment_out = 0.0;  // m³ that left by the outlets (deposition > 0)
    engine.run(years, dt, [&](std::int64_t step, std::int64_t steps) {
        ctx.check_cancelled();
        if (every > 0 && (step % every == 0 || step == steps)) {
            frame.assign(heights.begin(), heights.end());
            lapse.record(step, ConstGridView(frame.data(), hm->width(), hm->height(), hm->cell()));
        }
        pits += engine.pits();
        if (tiles) rounds = std::max(rounds, engine.tiled->rounds());
        if (engine.whole) sediment_out += engine.whole->sediment_out();
        last = steps;
        if (const std::int64_t bad = engine.first_non_finite(); bad >= 0) {
            std::ostringstream msg;
            msg << "non-finite height (" << heights[std::size_t(bad)] << ") at sample " << grid.sample(std::size_t(bad))
                << " after step " << step << " of " << steps << "; the simulation became unstable";
            throw Error(msg.str());
        }
        ctx.progress(double(step) / double(steps));
    });
    write_layers(ctx, *hm, engine, last, run);

    const std::vector<float>& out = hm->heights();
    auto [lo, hi] = std::minmax_element(out.begin(), out.end());
    float low = *lo, high = *hi;
    if (tiles) {
        low = tiles->reduce(low, Tiling::Reduce::min);
        high = tiles->reduce(high, Tiling::Reduce::max);
    }
    const double seconds = std::chrono::duration<double>(clock::now() - started).count();
    std::ostringstream msg;
    msg << last << " steps of " << dt << " yr; " << pits << " pits resolved; relief " << (high - low) << " m";
    if (s.deposition > 0.0) msg << "; " << sediment_out * 1e-9 << " km³ of sediment left by the outlets";
    if (tiles)
        msg << "; rank " << tiles->rank() << " of " << tiles->ranks() << ", up to " << rounds
            << " round(s) a step down rivers crossing tiles; " << seconds
            << " s in the node, of which joining the tiles " << engine.tiled->seconds_joining() << " s ("
            << 100.0 * engine.tiled->seconds_joining() / std::max(1e-9, seconds) << " %)";
    ctx.info(msg.str());
    lapse.finish(last, *hm);
    NodeOutputs result(hm);
    if (lapse.enabled()) result.side["timelapse"] = Value(lapse.series());
    return result;
}

}  // namespace orogen::landscape
