// erode:hydraulic — registers Olsen's hydraulic automaton (hydraulic.hpp) with the kernel.
#include "hydraulic.hpp"

#include <orogen/error.hpp>
#include <orogen/plugin.hpp>
#include <orogen/timelapse.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace {

using namespace orogen;

/// A tiled run's steps per halo exchange (temporal blocking, as erode:thermal's sweeps).
constexpr int kStepsPerSweep = 4;
/// One step reads 3 vertices across a tile edge: a cell's inflow needs its
/// axis neighbours' flow factors, a factor needs its axis neighbours'
/// altitude after rain and dissolving, which needs their axis neighbours'
/// terrain (the slope). So a sweep of kStepsPerSweep steps needs this many.
constexpr int kTileHalo = 3 * kStepsPerSweep;

/// check_finite()'s message, with the sample's index in the whole grid (a tiled run holds a tile).
void check_finite_owned(ConstGridView held, const TileRect& own, int ox, int oy, int grid_width, const char* what,
                        std::int64_t step) {
    for (int y = 0; y < own.height; ++y)
        for (int x = 0; x < own.width; ++x)
            if (const float v = held.row(y + oy)[ox + x]; !std::isfinite(v)) {
                std::ostringstream msg;
                msg << "non-finite " << what << " (" << v << ") at sample "
                    << std::int64_t(own.y0 + y) * grid_width + (own.x0 + x) << " after step " << step
                    << "; the simulation became unstable";
                throw Error(msg.str());
            }
}

/// One rank's tile of a tiled run (orogen/tiles.hpp). The step is a pure
/// function of the previous state (no global sums), so the rank works on its
/// tile grown by kTileHalo: before each sweep of kStepsPerSweep steps the
/// halo of terrain, water and sediment is refilled from the neighbours; the
/// sweep treats the grown tile's edge as the map's edge, whose wrong effect
/// travels 3 vertices a step, so after the sweep the owned vertices hold the
/// single process's bits and only the halo is stale. Once more at the end,
/// for the `flow` and `hardness` layers (stencils of 2 and 1 vertices).
std::shared_ptr<Series> run_tiled(NodeContext& ctx, Tiling& tiles, Heightmap& hm, const hydraulic::Settings& s,
                                  const float* layer, std::int64_t iterations) {
    const TileRect own = tiles.owned(), grown = tiles.grown(kTileHalo);
    const int ox = own.x0 - grown.x0, oy = own.y0 - grown.y0;
    const std::size_t n = std::size_t(grown.width) * std::size_t(grown.height);
    const double cell = hm.cell();
    auto to_grown = [&](const float* tile, float* held) {
        for (int y = 0; y < own.height; ++y)
            std::copy(tile + std::size_t(y) * std::size_t(own.width), tile + std::size_t(y + 1) * std::size_t(own.width),
                      held + std::size_t(y + oy) * std::size_t(grown.width) + std::size_t(ox));
    };
    std::vector<float> held_layer;
    if (layer) {  // the hardness of the halo too, once: it does not change
        held_layer.assign(n, 0.0f);
        to_grown(layer, held_layer.data());
        tiles.exchange_halo({held_layer.data(), grown.width, grown.height, cell}, kTileHalo);
    }
    const float* hard = layer ? held_layer.data() : nullptr;
    // Two states (double-buffered): terrain, water, sediment each, the tile
    // grown by the halo. The tile's water and sediment layers (an input's, or
    // none: zero) move into the first state one at a time, each dropped as
    // soon as it is copied, after the hardness layer's copy (it may be one of
    // them): the peak is the tile's heights (kept as `before`) and `eroded`
    // beside the six grown grids, as one process holds 8 whole grids. Filling
    // all six first and dropping the two layers after was two grids more per
    // rank (docs/benchmarks.md, "Tiled Olsen hydraulic erosion").
    std::vector<float> storage[6];
    auto grid = [&](int k) { return GridView{storage[k].data(), grown.width, grown.height, cell}; };
    storage[0].assign(n, 0.0f);
    to_grown(hm.heights().data(), storage[0].data());
    for (int k : {1, 2}) {
        const char* name = k == 1 ? "water" : "sediment";
        storage[k].assign(n, 0.0f);
        if (hm.has_layer(name)) {
            to_grown(std::as_const(hm).layer(name).data, storage[k].data());
            hm.remove_layer(name);
        }
    }
    for (int k : {3, 4, 5}) storage[k].assign(n, 0.0f);
    hydraulic::State a{grid(0), grid(1), grid(2)}, b{grid(3), grid(4), grid(5)};
    // Snapshots after every step, as run()'s; rank 0 holds them. The first has the water layer run() makes.
    Timelapse lapse(ctx.integer("timelapse_every"), 1.0, tiles);  // time = step count
    lapse.record(0, a.height, a.water.data, ox, oy);
    using clock = std::chrono::steady_clock;
    clock::duration exchanging{}, sweeping{};  // for the info line (docs/benchmarks.md)
    const double waited_before = tiles.seconds_waiting();
    auto exchange = [&] {
        const auto t0 = clock::now();
        const GridView grids[] = {a.height, a.water, a.sediment};
        tiles.exchange_halos(grids, kTileHalo);
        exchanging += clock::now() - t0;
    };
    for (std::int64_t i = 0; i < iterations;) {
        const int k = int(std::min<std::int64_t>(kStepsPerSweep, iterations - i));
        exchange();
        const auto t1 = clock::now();
        for (int j = 0; j < k; ++j) {
            hydraulic::step({a.height, a.water, a.sediment}, b, s, hard);
            std::swap(a, b);
            ++i;
            lapse.record(i, a.height, a.water.data, ox, oy);
            ctx.check_cancelled();
            if (i % 64 == 0 || i == iterations) {  // as run() checks
                check_finite_owned(a.height, own, ox, oy, tiles.grid_width(), "height", i);
                check_finite_owned(a.water, own, ox, oy, tiles.grid_width(), "water", i);
                check_finite_owned(a.sediment, own, ox, oy, tiles.grid_width(), "sediment", i);
                ctx.progress(double(i) / double(iterations));
            }
        }
        sweeping += clock::now() - t1;
    }
    exchange();  // the halo `flow` and `hardness` read
    const double ex = std::chrono::duration<double>(exchanging).count(), sw = std::chrono::duration<double>(sweeping).count();
    ctx.info(tiles.sweep_note(iterations, sw, ex, waited_before));
    // The layers run() adds, from the final state (b's grids are free now: scratch for them).
    for (const char* l : {"flux_west", "flux_east", "flux_north", "flux_south"}) hm.remove_layer(l);
    hydraulic::outflow({a.height, a.water, a.sediment}, s, hard, b.height);
    const bool steep = s.hardness == hydraulic::Hardness::steepness;
    if (steep) hydraulic::steepness_hardness(a.height, b.water);
    // Each grid back as a tile, its owned part moved to its front in place (a
    // copy into fresh memory costs page faults: seconds of system time at
    // 4097² on a loaded machine). Row y's destination never passes its source.
    auto take = [&](const GridView& g) {
        std::vector<float>* owner = nullptr;
        for (auto& v : storage)
            if (v.data() == g.data) owner = &v;
        for (int y = 0; y < own.height; ++y)
            std::memmove(owner->data() + std::size_t(y) * std::size_t(own.width),
                         owner->data() + std::size_t(y + oy) * std::size_t(grown.width) + std::size_t(ox),
                         std::size_t(own.width) * sizeof(float));
        owner->resize(std::size_t(own.width) * std::size_t(own.height));
        return std::move(*owner);
    };
    std::vector<float>().swap(held_layer);
    std::vector<float> after = take(a.height);
    GridView eroded = hm.layer("eroded", 0.0f);
    for (std::size_t i = 0; i < after.size(); ++i) eroded.data[i] += after[i] - hm.heights()[i];
    hm.set_layer("water", take(a.water));
    hm.set_layer("sediment", take(a.sediment));
    hm.set_layer("flow", take(b.height));
    if (steep) hm.set_layer("hardness", take(b.water));
    hm.heights() = std::move(after);
    lapse.finish(iterations, hm);
    return lapse.enabled() ? lapse.series() : nullptr;
}

NodeOutputs run(NodeContext& ctx) {
    auto hm = ctx.take_heightmap(0);
    hydraulic::Settings s;
    s.rain = ctx.real("rain");
    s.solubility = ctx.real("solubility");
    s.evaporation = ctx.real("evaporation");
    s.capacity = ctx.real("capacity");
    const std::string& hardness = ctx.text("hardness");
    const float* layer = nullptr;
    if (hardness == "steepness") {
        s.hardness = hydraulic::Hardness::steepness;
    } else if (hardness == "constant") {
        s.hardness = hydraulic::Hardness::constant;
    } else {
        s.hardness = hydraulic::Hardness::layer;
        if (!hm->has_layer(hardness)) throw BadInput("hardness: the input has no layer '" + hardness + "'");
    }
    const std::int64_t iterations = ctx.integer("iterations");
    if (Tiling* tiles = ctx.tiling()) {
        hm->layer("eroded", 0.0f);
        if (s.hardness == hydraulic::Hardness::layer) layer = std::as_const(*hm).layer(hardness).data;
        auto series = run_tiled(ctx, *tiles, *hm, s, layer, iterations);  // takes the water and sediment layers itself
        NodeOutputs out(hm);
        if (series) out.side["timelapse"] = Value(series);
        return out;
    }
    // An input that already carries water and sediment continues from them.
    GridView water = hm->layer("water", 0.0f);
    GridView sediment = hm->layer("sediment", 0.0f);
    GridView eroded = hm->layer("eroded", 0.0f);
    if (s.hardness == hydraulic::Hardness::layer) layer = std::as_const(*hm).layer(hardness).data;
    const std::vector<float> before = hm->heights();
    Timelapse lapse(ctx.integer("timelapse_every"), 1.0);  // time = step count
    lapse.record(0, *hm);
    hydraulic::erode({hm->view(), water, sediment}, iterations, s, layer,
                     [&](std::int64_t i, const hydraulic::ConstState& st) {
                         ctx.check_cancelled();
                         lapse.record(i, st.height, st.water.data);
                         if (i % 64 == 0 || i == iterations) {
                             ctx.check_finite(st.height.span(), "height", i);
                             ctx.check_finite(st.water.span(), "water", i);
                             ctx.check_finite(st.sediment.span(), "sediment", i);
                             ctx.progress(double(i) / double(iterations));
                         }
                     });
    const std::vector<float>& after = hm->heights();
    for (std::size_t i = 0; i < after.size(); ++i) eroded.data[i] += after[i] - before[i];
    // Where the water runs: what each cell would send downhill next step. This
    // automaton moved the water itself, so a pipe model's flux state from an
    // earlier node no longer describes it (and erode:pipe reads `flow` as its
    // speed only together with its fluxes): drop them.
    for (const char* l : {"flux_west", "flux_east", "flux_north", "flux_south"}) hm->remove_layer(l);
    GridView flow = hm->layer("flow", 0.0f);
    hydraulic::outflow({hm->view(), water, sediment}, s, layer, flow);
    if (s.hardness == hydraulic::Hardness::steepness) hydraulic::steepness_hardness(hm->view(), hm->layer("hardness", 0.0f));
    lapse.finish(iterations, *hm);
    NodeOutputs out(hm);
    if (lapse.enabled()) out.side["timelapse"] = Value(lapse.series());
    return out;
}

void check(CheckContext& ctx) {
    const std::string& hardness = ctx.text("hardness");
    if (hardness != "steepness" && hardness != "constant") {
        ctx.require_layer(0, "hardness", hardness, "use steepness, constant or the name of an existing layer");
    }
    for (const char* l : {"water", "sediment", "eroded", "flow"}) ctx.output().layers.insert(l);
    if (hardness == "steepness") ctx.output().layers.insert("hardness");
    check_timelapse(ctx, ctx.integer("iterations"));
}

}  // namespace

OROGEN_PLUGIN("erode-hydraulic", "0.1.0", registry) {
    registry.add({
        .kind = "erode",
        .name = "hydraulic",
        .summary = "Olsen's hydraulic erosion automaton: rain dissolves terrain, water carries it downhill",
        .description =
            "Olsen's four-step cellular automaton (thesis section 3.5.1, fig. 3.18). Each step: rain on every "
            "cell; water dissolves solubility * water * softness of terrain (softness = (1 - |n_y|)^3, the "
            "thesis's steepness hardness, by default); water and its sediment flow to lower 4-neighbours by "
            "Olsen's two cases (level out, or drain completely); a fraction of the water evaporates and sediment "
            "above capacity * water is deposited. Water and sediment persist between steps and between nodes: "
            "an input carrying water and sediment layers continues from them. Terrain + sediment is conserved. "
            "Adds the layers water (m), sediment (m), eroded (net terrain change, m), flow (water each cell "
            "sends downhill per step at the end, m) and, with hardness=steepness, hardness (1 on flat ground, "
            "falling toward 0 on cliffs).",
        .inputs = {{"terrain", ValueType::heightmap, Need::required, "heightmap to erode"}},
        .output = ValueType::heightmap,
        .side_outputs = {timelapse_output()},
        .params =
            {
                Param::integer("iterations", 100).min(0).max(10'000'000).help("number of steps"),
                Param::real("rain", 0.01).min(0.0).unit("m").help("water added to every cell per step (Kr)"),
                Param::real("solubility", 0.01)
                    .min(0.0)
                    .max(1.0)
                    .help("terrain dissolved per metre of water per step, before hardness (Ks)"),
                Param::real("evaporation", 0.5)
                    .min(0.0)
                    .max(1.0)
                    .help("fraction of the water that evaporates per step (Ke)"),
                Param::real("capacity", 0.05)
                    .min(0.0)
                    .help("sediment a metre of water can hold, in metres (Kc); the rest is deposited"),
                Param::string("hardness", "steepness")
                    .help("steepness (the thesis's (1 - |n_y|)^3: flat ground resists), constant, or the name of a "
                          "layer holding hardness 0..1"),
                timelapse_param(),
            },
        .adds_layers = {"water", "sediment", "eroded", "flow"},
        .tile_halo = kTileHalo,
        .check = check,
        .run = run,
        .tiled_timelapse = true,  // rank 0 gathers the frames (Timelapse with the tiling)
    });
}
