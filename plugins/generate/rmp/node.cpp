// generate:rmp and generate:range — register the RMP cores as nodes.
#include "cones.hpp"
#include <orogen/relief/range.hpp>
#include "rmp.hpp"

#include <orogen/plugin.hpp>
#include <orogen/random.hpp>
#include <orogen/tiles.hpp>

#include <cmath>
#include <sstream>

using namespace orogen;

namespace {

/// The terrain to raise: the input, or the spec's grid flat at 0 m; in a tiled (MPI) run this rank's tile of it.
std::shared_ptr<Heightmap> base_or_grid(NodeContext& ctx) {
    const Tiling* tiles = ctx.tiling();
    const TileRect area = tiles ? tiles->owned() : TileRect{0, 0, ctx.grid().width, ctx.grid().height};
    return ctx.has_input(0) ? ctx.take_heightmap(0)
                            : std::make_shared<Heightmap>(area.width, area.height, ctx.grid().cell);
}

/// Where `hm` lies in the whole grid (all of it in one process), and the whole grid's size.
struct Placed {
    relief::Window window;
    int width, height;
};
Placed placed(NodeContext& ctx, Heightmap& hm) {
    const Tiling* tiles = ctx.tiling();
    if (!tiles) return {{hm.view()}, hm.width(), hm.height()};
    return {{hm.view(), tiles->owned().x0, tiles->owned().y0}, tiles->grid_width(), tiles->grid_height()};
}

std::string point_text(Point2 p) {
    std::ostringstream s;
    s << "(" << p.x << ", " << p.y << ")";
    return s.str();
}

// Polygons n cuts can make at most (the lazy caterer's sequence, thesis eq. 4.1).
std::int64_t max_polygons(std::int64_t cuts) { return (cuts * cuts + cuts + 2) / 2; }

std::uint64_t node_seed(NodeContext& ctx) {
    const std::int64_t s = ctx.integer("seed");
    return s < 0 ? ctx.seed() : orogen::random::hash(std::uint64_t(s));
}

constexpr const char* kRmpDescription =
    "Each iteration cuts the map into random regions and raises the region under each peak\n"
    "by `height` (times decay^iteration). More cones (or cuts) per iteration make a steeper,\n"
    "narrower mountain; more iterations a higher one. Methods find the regions differently:\n"
    "  voronoi  exact Voronoi cells on the CPU, only the raised ones (default, fastest)\n"
    "  cones    the thesis's GPU trick: flat cones drawn from above through OSMesa\n"
    "  graph    faces of `cuts` random lines; the first `regions` faces of a depth-first\n"
    "           search from each peak's face rise\n"
    "voronoi and cones use the same sites for a seed, so they give the same mountain.\n"
    "With no input, starts from the spec's grid, flat at 0 m.";

std::vector<Param> rmp_params() {
    return {
        Param::choice("method", {"voronoi", "cones", "graph"}, "voronoi")
            .help("how the regions are found: exact Voronoi cells, OSMesa-drawn cones, or line cuts"),
        Param::points("peaks", std::vector<Point2>{{0.5, 0.5}})
            .min(0)
            .max(1)
            .at_most(1024)
            .help("where the mountains stand, grid-relative (0..1 on both axes)"),
        Param::integer("iterations", 100).min(1).max(1'000'000).help("raises; height grows with them"),
        Param::integer("cones", 100)
            .min(1)
            .max(10'000'000)
            .help("Voronoi sites per iteration (voronoi, cones): more give a steeper, narrower mountain"),
        Param::real("height", 5.0).min(-1e5).max(1e5).unit("m").help("raise of the first iteration"),
        Param::real("decay", 1.0)
            .min(0, true)
            .max(1)
            .help("the raise is multiplied by this after each iteration (the thesis: 1 - 1/iterations)"),
        Param::real("jitter", 0.0)
            .min(0)
            .max(1)
            .help("0: every region by the same amount; >0: each by height*(1 + jitter*u), u in [-1, 1) "
                  "(the thesis's dynamic areal height, 4.2)"),
        Param::integer("seed", -1)
            .min(-1)
            .max(9.0e18)
            .help("-1: the node's own seed (from the spec's seed and the node's name); otherwise this "
                  "seed, so variants of a node can share their random regions"),
        Param::integer("cuts", 5).min(1).max(5000).help("random lines per iteration (graph)"),
        Param::integer("regions", 2)
            .min(1)
            .max(1'000'000)
            .help("polygons raised per peak per iteration, first in depth-first order (graph)"),
    };
}

constexpr const char* kRangeDescription =
    "Each iteration draws a fresh Voronoi diagram of `cones` sites and raises every cell the\n"
    "segment from `from` to `to` passes through (and every cell of its Bresenham line's\n"
    "vertices), as the plate simulation does at each collision. With no input, starts from\n"
    "the spec's grid, flat at 0 m.";

std::vector<Param> range_params() {
    return {
        Param::point("from", Point2{0.2, 0.5}).min(0).max(1).help("one end of the range, grid-relative"),
        Param::point("to", Point2{0.8, 0.5}).min(0).max(1).help("the other end, grid-relative"),
        Param::integer("iterations", 50).min(1).max(1'000'000).help("raises, each with new cells"),
        Param::integer("cones", 100)
            .min(1)
            .max(10'000'000)
            .help("Voronoi sites per iteration: more give a narrower range"),
        Param::real("height", 5.0).min(-1e5).max(1e5).unit("m").help("raise per iteration"),
        Param::real("jitter", 0.0)
            .min(0)
            .max(1)
            .help("0: every crossed cell by `height`; >0: each by height*(1 + jitter*u), u in [-1, 1)"),
        Param::integer("seed", -1)
            .min(-1)
            .max(9.0e18)
            .help("-1: the node's own seed (from the spec's seed and the node's name); otherwise this "
                  "seed, so variants of a node can share their random regions"),
        Param::boolean("uplift", false).help("also add the raise to the heightmap's 'uplift' layer (m)"),
    };
}

}  // namespace

OROGEN_PLUGIN("generate-rmp", "0.1.0", registry) {
    registry.add({
        .kind = "generate",
        .name = "rmp",
        .summary = "Repeated Magnification and Probing (thesis 3.3): mountains at given peaks",
        .description = kRmpDescription,
        .inputs = {{"base", ValueType::heightmap, Need::optional,
                    "terrain to raise mountains on (default: the spec's grid, flat at 0 m)"}},
        .output = ValueType::heightmap,
        .params = rmp_params(),
        .tile_halo = 0,  // a sample's raise is a pure function of the seed and its position
        .check =
            [](CheckContext& ctx) {
                const std::string& method = ctx.text("method");
                if (method == "graph") {
                    const std::int64_t cuts = ctx.integer("cuts"), regions = ctx.integer("regions");
                    if (regions > max_polygons(cuts))
                        ctx.error("regions",
                                  "regions=" + std::to_string(regions) + " is more than the " +
                                      std::to_string(max_polygons(cuts)) + " polygons " + std::to_string(cuts) +
                                      " cuts can make at most (n(n+1)/2 + 1); "
                                      "lower regions or raise cuts");
                }
                if (method != "graph" && (ctx.given("cuts") || ctx.given("regions")))
                    ctx.error(ctx.given("cuts") ? "cuts" : "regions",
                              "cuts and regions apply to method=graph only; this node uses method=" + method);
                if (method == "graph" && ctx.given("cones"))
                    ctx.error("cones", "cones applies to method=voronoi and method=cones; method=graph uses cuts");
                if (method == "cones") {
                    // llvmpipe draws at most 16384 × 16384 pixels, one per vertex.
                    const ValueInfo* base = ctx.input(0);
                    const int w = base && base->width > 0 ? base->width : ctx.grid().width;
                    const int h = base && base->height > 0 ? base->height : ctx.grid().height;
                    if (w > 16384 || h > 16384)
                        ctx.error("method",
                                  "method=cones draws one pixel per vertex and OSMesa draws at most "
                                  "16384 × 16384; this grid is " +
                                      std::to_string(w) + " × " + std::to_string(h) +
                                      ": use method=voronoi (the same diagram)");
                }
                if (method == "cones" && ctx.integer("cones") > 16'777'214)
                    ctx.error("cones",
                              "method=cones encodes a cone's index in a 24-bit colour: at most 16777214 "
                              "cones; use method=voronoi for more");
            },
        .run = [](NodeContext& ctx) -> NodeOutputs {
            auto hm = base_or_grid(ctx);
            rmp::RmpParams p;
            p.peaks = ctx.points("peaks");
            p.iterations = int(ctx.integer("iterations"));
            p.cones = int(ctx.integer("cones"));
            p.height = ctx.real("height");
            p.decay = ctx.real("decay");
            p.jitter = ctx.real("jitter");
            p.cuts = int(ctx.integer("cuts"));
            p.regions = int(ctx.integer("regions"));
            const auto hook = [&](int k) {
                ctx.check_cancelled();
                ctx.progress(double(k + 1) / p.iterations);
            };
            const std::string& method = ctx.text("method");
            const std::uint64_t seed = node_seed(ctx);
            // In a tiled run every rank draws each iteration's regions over the whole grid and raises its tile.
            const Placed at = placed(ctx, *hm);
            if (method == "voronoi") rmp::rmp_voronoi(at.window, at.width, at.height, p, seed, hook);
            else if (method == "cones") rmp::rmp_cones(hm->view(), p, seed, hook);  // never tiled (untiled_because)
            else rmp::rmp_graph(at.window, at.width, at.height, p, seed, hook);
            ctx.check_finite(hm->heights(), "height", p.iterations);
            return hm;
        },
        .untiled_because =
            [](const std::map<std::string, ParamValue, std::less<>>& params, const std::vector<bool>&) {
                return std::get<std::string>(params.at("method")) == "cones"
                    ? std::string(
                          "method=cones draws the whole grid through OSMesa (method=voronoi draws "
                          "the same mountain and tiles)")
                    : std::string();
            },
    });

    registry.add({
        .kind = "generate",
        .name = "range",
        .summary = "A mountain range between two points: RMP along a line (thesis 3.6.2)",
        .description = kRangeDescription,
        .inputs = {{"base", ValueType::heightmap, Need::optional,
                    "terrain to raise the range on (default: the spec's grid, flat at 0 m)"}},
        .output = ValueType::heightmap,
        .params = range_params(),
        .tile_halo = 0,  // as generate:rmp: every rank raises its tile of the whole grid's range
        .check =
            [](CheckContext& ctx) {
                const Point2 a = std::get<Point2>(ctx.param("from")), b = std::get<Point2>(ctx.param("to"));
                if (a == b)
                    ctx.error("to",
                              "the range's two end points are the same point " + point_text(a) +
                                  "; give `from` and `to` different points");
                if (ctx.flag("uplift")) ctx.output().layers.insert("uplift");
            },
        .run = [](NodeContext& ctx) -> NodeOutputs {
            auto hm = base_or_grid(ctx);
            const Placed whole = placed(ctx, *hm);
            const Point2 a = rmp::to_samples(ctx.point("from"), whole.width, whole.height);
            const Point2 b = rmp::to_samples(ctx.point("to"), whole.width, whole.height);
            relief::RangeParams p;
            p.cones = int(ctx.integer("cones"));
            p.height = ctx.real("height");
            p.jitter = ctx.real("jitter");
            const int iterations = int(ctx.integer("iterations"));
            GridView uplift;
            if (ctx.flag("uplift")) uplift = hm->layer("uplift");
            const std::uint64_t seed = node_seed(ctx);
            const Placed at = placed(ctx, *hm);  // in a tiled run, this rank's tile of the whole grid's range
            for (int k = 0; k < iterations; ++k) {
                relief::raise_range(hm->view(), relief::GridWindow{at.width, at.height, at.window.x0, at.window.y0}, a,
                                    b, p, rmp::iteration_seed(seed, k), ctx.flag("uplift") ? &uplift : nullptr);
                ctx.check_cancelled();
                ctx.progress(double(k + 1) / iterations);
            }
            ctx.check_finite(hm->heights(), "height", iterations);
            return hm;
        },
    });
}
