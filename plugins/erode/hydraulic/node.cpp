// erode:hydraulic — registers Olsen's hydraulic automaton (hydraulic.hpp) with the kernel.
#include "hydraulic.hpp"

#include <orogen/error.hpp>
#include <orogen/plugin.hpp>
#include <orogen/timelapse.hpp>

#include <algorithm>
#include <array>
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

/// One rank's tile of a tiled run (orogen/tiles.hpp). The step is a pure
/// function of the previous state (no global sums), so the rank works on its
/// tile grown by kTileHalo (TiledFields): before each sweep of kStepsPerSweep
/// steps the halo of terrain, water and sediment is refilled from the
/// neighbours; the sweep treats the grown tile's edge as the map's edge, whose
/// wrong effect travels 3 vertices a step, so after the sweep the owned
/// vertices hold the single process's bits and only the halo is stale. Once
/// more at the end, for the `flow` and `hardness` layers (stencils of 2 and 1
/// vertices).
std::shared_ptr<Series> run_tiled(NodeContext& ctx, Tiling& tiles, Heightmap& hm, const hydraulic::Settings& s,
                                  const float* layer, std::int64_t iterations) {
    TiledFields fields(tiles, hm.cell());
    GridView held_layer;
    if (layer) {  // the hardness of the halo too, once: it does not change
        held_layer = fields.grow(layer);
        fields.exchange(held_layer);
    }
    const float* hard = held_layer.data;
    // Two states (double-buffered): terrain, water, sediment each, the tile
    // grown by the halo. The tile's water and sediment layers (an input's, or
    // none: zero) move into the first state one at a time, each dropped as
    // soon as it is copied, after the hardness layer's copy (it may be one of
    // them): the peak is the tile's heights (kept as `before`) and `eroded`
    // beside the six grown grids, as one process holds 8 whole grids. Filling
    // all six first and dropping the two layers after was two grids more per
    // rank (docs/benchmarks.md, "Tiled Olsen hydraulic erosion").
    const GridView height = fields.grow(hm.heights().data());
    auto grow_layer = [&](const char* name) {
        if (!hm.has_layer(name)) return fields.zeros();
        const GridView g = fields.grow(std::as_const(hm).layer(name).data);
        hm.remove_layer(name);
        return g;
    };
    const GridView water = grow_layer("water");
    const GridView sediment = grow_layer("sediment");
    hydraulic::State a{height, water, sediment}, b{fields.zeros(), fields.zeros(), fields.zeros()};
    const int ox = fields.ox(), oy = fields.oy();
    // Snapshots after every step, as run()'s; rank 0 holds them. The first has the water layer run() makes.
    Timelapse lapse(ctx.integer("timelapse_every"), 1.0, tiles);  // time = step count
    lapse.record(0, a.height, a.water.data, ox, oy);
    fields.sweeps(
        iterations, kStepsPerSweep,
        [&] {
            return std::array{a.height, a.water, a.sediment};
        },
        [&](std::int64_t first, int k) {
            for (std::int64_t i = first + 1; i <= first + k; ++i) {
                hydraulic::step({a.height, a.water, a.sediment}, b, s, hard);
                std::swap(a, b);
                lapse.record(i, a.height, a.water.data, ox, oy);
                ctx.check_cancelled();
                if (i % 64 == 0 || i == iterations) {  // as run() checks
                    fields.check_finite(a.height, "height", i);
                    fields.check_finite(a.water, "water", i);
                    fields.check_finite(a.sediment, "sediment", i);
                    ctx.progress(double(i) / double(iterations));
                }
            }
        },
        [](std::int64_t) {});
    fields.exchange(std::array{a.height, a.water, a.sediment});  // the halo `flow` and `hardness` read
    ctx.info(fields.note(iterations));
    // The layers run() adds, from the final state (b's grids are free now: scratch for them).
    for (const char* l : {"flux_west", "flux_east", "flux_north", "flux_south"}) hm.remove_layer(l);
    hydraulic::outflow({a.height, a.water, a.sediment}, s, hard, b.height);
    const bool steep = s.hardness == hydraulic::Hardness::steepness;
    if (steep) hydraulic::steepness_hardness(a.height, b.water);
    // Each grid back as a tile, its owned part moved to its front in place (TiledFields::take).
    if (layer) fields.drop(held_layer);
    std::vector<float> after = fields.take(a.height);
    GridView eroded = hm.layer("eroded", 0.0f);
    for (std::size_t i = 0; i < after.size(); ++i) eroded.data[i] += after[i] - hm.heights()[i];
    hm.set_layer("water", fields.take(a.water));
    hm.set_layer("sediment", fields.take(a.sediment));
    hm.set_layer("flow", fields.take(b.height));
    if (steep) hm.set_layer("hardness", fields.take(b.water));
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
    if (s.hardness == hydraulic::Hardness::steepness)
        hydraulic::steepness_hardness(hm->view(), hm->layer("hardness", 0.0f));
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
