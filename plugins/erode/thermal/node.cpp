// erode:thermal — registers Olsen's thermal erosion (thermal.hpp) with the kernel.
#include "thermal.hpp"

#include <orogen/error.hpp>
#include <orogen/plugin.hpp>
#include <orogen/timelapse.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numbers>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace {

using namespace orogen;

/// A step changes a vertex from the 5 × 5 vertices around it (F of a
/// neighbour looks one vertex further), so a sweep of kStepsPerSweep steps
/// needs this many vertices of the neighbouring tiles.
constexpr int kTileHalo = 2 * thermal::kStepsPerSweep;

/// Adds the layers run() adds (eroded, and hardness for Hardness::height) from the heights before and after.
void add_layers(Heightmap& hm, const float* before, const float* after, const thermal::Settings& s) {
    GridView eroded = hm.layer("eroded", 0.0f);
    for (std::size_t i = 0; i < hm.size(); ++i) eroded.data[i] += after[i] - before[i];
    if (s.hardness == thermal::Hardness::height) {
        GridView k = hm.layer("hardness", 0.0f);
        for (std::size_t i = 0; i < hm.size(); ++i)
            k.data[i] = thermal::height_hardness(after[i], s.height_min, s.height_max);
    }
}

/// One rank's tile of a tiled run (orogen/tiles.hpp). The rank works on its
/// tile grown by kTileHalo vertices (TiledFields): before each sweep of
/// kStepsPerSweep steps the halo is refilled from the neighbours; the sweep
/// treats the edge of the grown tile as a wall, whose wrong effect travels 2
/// vertices a step, so after the sweep the owned vertices are exactly the
/// whole grid's (the same operations on the same inputs, bit for bit), and
/// only the halo is stale.
NodeOutputs run_tiled(NodeContext& ctx, Tiling& tiles, std::shared_ptr<Heightmap> hm, const thermal::Settings& s,
                      const float* layer) {
    TiledFields fields(tiles, hm->cell());
    const GridView view = fields.grow(hm->heights().data());
    GridView held_layer;
    if (layer) {  // the hardness of the halo too, once: it does not change
        held_layer = fields.grow(layer);
        fields.exchange(held_layer);
    }
    const std::int64_t iterations = ctx.integer("iterations");
    // Snapshots at the ends of the sweeps, as run()'s (erode() calls back once a sweep); rank 0 holds them.
    Timelapse lapse(ctx.integer("timelapse_every"), 1.0, tiles);
    lapse.record(0, *hm);
    fields.sweeps(
        iterations, thermal::kStepsPerSweep, [&] { return std::array{view}; },
        [&](std::int64_t, int k) { thermal::steps(view, view, k, s, held_layer.data); },
        [&](std::int64_t i) {
            lapse.record(i, view, nullptr, fields.ox(), fields.oy());
            ctx.check_cancelled();
            if (i % 64 == 0 || i == iterations) {  // as run() does
                fields.check_finite(view, "height", i);
                ctx.progress(double(i) / double(iterations));
            }
        });
    ctx.info(fields.note(iterations));
    if (layer) fields.drop(held_layer);
    // The owned part back into the tile; the tile's old heights are `before` for the layers.
    std::vector<float> after = fields.take(view);
    add_layers(*hm, hm->heights().data(), after.data(), s);
    hm->heights() = std::move(after);
    lapse.finish(iterations, *hm);
    NodeOutputs out(hm);
    if (lapse.enabled()) out.side["timelapse"] = Value(lapse.series());
    return out;
}

NodeOutputs run(NodeContext& ctx) {
    auto hm = ctx.take_heightmap(0);
    thermal::Settings s;
    s.neighbourhood = thermal::parse_neighbourhood(ctx.text("neighbourhood"));
    s.talus_slope = std::tan(ctx.real("talus") * std::numbers::pi / 180.0);
    s.talus_height = ctx.real("talus_height") > 0.0 ? ctx.real("talus_height") : -1.0;
    s.rate = ctx.real("rate");
    const std::string& hardness = ctx.text("hardness");
    const float* layer = nullptr;
    if (hardness == "constant") {
        s.hardness = thermal::Hardness::constant;
    } else if (hardness == "height") {
        s.hardness = thermal::Hardness::height;
        const auto [lo, hi] = std::minmax_element(hm->heights().begin(), hm->heights().end());
        s.height_min = hm->heights().empty() ? 0.0f : *lo;
        s.height_max = hm->heights().empty() ? 1.0f : *hi;
        if (Tiling* tiles = ctx.tiling()) {  // the whole grid's range
            s.height_min = tiles->reduce(s.height_min, Tiling::Reduce::min);
            s.height_max = tiles->reduce(s.height_max, Tiling::Reduce::max);
        }
    } else {
        s.hardness = thermal::Hardness::layer;
        if (!hm->has_layer(hardness)) throw BadInput("hardness: the input has no layer '" + hardness + "'");
        layer = std::as_const(*hm).layer(hardness).data;
    }

    if (Tiling* tiles = ctx.tiling()) return run_tiled(ctx, *tiles, std::move(hm), s, layer);
    const std::vector<float> before = hm->heights();
    const std::int64_t iterations = ctx.integer("iterations");
    Timelapse lapse(ctx.integer("timelapse_every"), 1.0);  // time = step count
    lapse.record(0, *hm);
    thermal::erode(hm->view(), iterations, s, layer, [&](std::int64_t i, ConstGridView current) {
        ctx.check_cancelled();
        lapse.record(i, current);
        if (i % 64 == 0 || i == iterations) {
            ctx.check_finite(current.span(), "height", i);
            ctx.progress(double(i) / double(iterations));
        }
    });

    // eroded: net change in metres, added to an earlier eroder's if present.
    add_layers(*hm, before.data(), hm->heights().data(), s);
    lapse.finish(iterations, *hm);
    NodeOutputs out(hm);
    if (lapse.enabled()) out.side["timelapse"] = Value(lapse.series());
    return out;
}

void check(CheckContext& ctx) {
    if (ctx.given("talus") && ctx.given("talus_height"))
        ctx.error("talus_height", "give either talus (an angle) or talus_height (Olsen's height difference), not both");
    const std::string& hardness = ctx.text("hardness");
    if (hardness == "height") {
        ctx.output().layers.insert("hardness");
    } else if (hardness != "constant") {
        ctx.require_layer(0, "hardness", hardness, "use constant, height or the name of an existing layer");
    }
    ctx.output().layers.insert("eroded");
    check_timelapse(ctx, ctx.integer("iterations"));
}

}  // namespace

OROGEN_PLUGIN("erode-thermal", "0.1.0", registry) {
    registry.add({
        .kind = "erode",
        .name = "thermal",
        .summary = "Olsen's thermal erosion: material slides to lower neighbours steeper than the talus angle",
        .description =
            "A cellular automaton (thesis section 3.4, after Olsen 2004). Each step, a cell whose drop d_i to a "
            "neighbour exceeds the talus threshold T_i gives rate * (max_i(d_i - T_i)) of material, shared among "
            "those neighbours in proportion to d_i. The threshold is tan(talus) * distance (distance = cell, or "
            "cell * sqrt 2 for diagonal neighbours), or one height difference for all (talus_height). Material "
            "is conserved exactly; the result is the same for any thread count. Adds the layer eroded (net change, "
            "m) and, with hardness=height, hardness.",
        .inputs = {{"terrain", ValueType::heightmap, Need::required, "heightmap to erode"}},
        .output = ValueType::heightmap,
        .side_outputs = {timelapse_output()},
        .params =
            {
                Param::integer("iterations", 50).min(0).max(10'000'000).help("number of steps"),
                Param::real("talus", 35.0)
                    .min(0.0, true)
                    .max(90.0, true)
                    .unit("°")
                    .help("talus angle: slopes steeper than this shed material"),
                Param::real("talus_height", 0.0)
                    .min(0.0)
                    .unit("m")
                    .help("Olsen's form: one height difference for every neighbour, instead of talus (0 = use talus)"),
                Param::real("rate", 0.5)
                    .min(0.0, true)
                    .max(1.0)
                    .help("fraction of the excess above the threshold moved per step (Olsen 0.5, the thesis 0.01)"),
                Param::choice("neighbourhood", {"von-neumann", "rotated", "moore"}, "moore")
                    .help("neighbours considered: the 4 axis ones, the 4 diagonals (the thesis's rotated von "
                          "Neumann: never exchanges material between the two checkerboard sub-lattices, so it "
                          "leaves a diagonal hatching), or all 8"),
                Param::string("hardness", "constant")
                    .help("constant; height (the thesis's height-aware hardness: high ground is hard, "
                          "softness ((max - h)/(max - min))^2); or the name of a layer holding hardness 0..1"),
                timelapse_param(),
            },
        .adds_layers = {"eroded"},
        .tile_halo = kTileHalo,
        .check = check,
        .run = run,
        .tiled_timelapse = true,  // rank 0 gathers the frames (Timelapse with the tiling)
    });
}
