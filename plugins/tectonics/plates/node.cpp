// tectonics:plates — registers the plate simulation (plates.hpp) with the kernel.
#include "plates.hpp"

#include <orogen/error.hpp>
#include <orogen/plugin.hpp>
#include <orogen/tiles.hpp>
#include <orogen/timelapse.hpp>

#include <algorithm>
#include <memory>
#include <string>
#include <utility>

namespace {

using namespace orogen;

plates::Params params_from(NodeContext& ctx) {
    plates::Params p;
    p.steps = int(ctx.integer("steps"));
    p.dt = ctx.real("dt");
    p.drive = *plates::parse_drive(ctx.text("drive"));  // Param::choice has checked the name
    p.speed = ctx.real("speed");
    p.restitution = ctx.real("restitution");
    p.cones = int(ctx.integer("cones"));
    p.height = ctx.real("height");
    p.jitter = ctx.real("jitter");
    p.ranges = *plates::parse_range_style(ctx.text("ranges"));
    p.saturation = ctx.real("saturation");
    p.rift_depth = ctx.real("rift_depth");
    p.ridge_height = ctx.real("ridge_height");
    p.trench_depth = ctx.real("trench_depth");
    p.arc_height = ctx.real("arc_height");
    p.rift_threshold = ctx.real("rift_threshold");
    p.record_every = int(ctx.integer("record_every"));
    return p;
}

NodeOutputs run(NodeContext& ctx) {
    auto hm = ctx.take_heightmap(0);
    // In a tiled (MPI) run `hm` is this rank's tile: rank 0 runs the simulation for the whole grid (Box2D is
    // serial and touches no grid), every rank draws its outcome into its own tile (plates::draw_tile).
    Tiling* tiling = ctx.tiling();
    const int width = tiling ? tiling->grid_width() : hm->width();
    const int height = tiling ? tiling->grid_height() : hm->height();
    const plates::Params params = params_from(ctx);
    plates::Params bounded = params;
    bounded.max_plates = plates::max_plates(width, height);

    const auto start = plates::random_plates(plates::area_size(width, height), int(ctx.integer("plates")),
                                             ctx.real("oceanic_fraction"), params.speed, ctx.seed());
    plates::Layers layers;
    layers.uplift = hm->layer("uplift", 0.0f);  // added to an earlier tectonics node's uplift
    layers.boundary = hm->layer("boundary", 0.0f);
    layers.plate = hm->layer("plate", -1.0f);
    layers.terrain = hm->view();

    const auto on_step = [&](std::int64_t step) {
        ctx.check_cancelled();
        if (step % 32 == 0) ctx.progress(double(step) / double(params.steps));
    };
    plates::Result result;
    const std::int64_t every = ctx.integer("timelapse_every");
    // Time in simulated seconds; in a tiled run every rank draws its tile of each frame and rank 0 gathers them.
    Timelapse lapse = tiling ? Timelapse(every, params.dt, *tiling) : Timelapse(every, params.dt);
    lapse.record(0, *hm);
    if (tiling) {
        std::string replay;
        if (tiling->rank() == 0) {
            result = plates::simulate_events(start, bounded, ctx.seed(), width, height, hm->cell(), on_step);
            replay = plates::encode(result.replay);
        }
        tiling->share_from_rank0(replay);
        if (tiling->rank() != 0) result.replay = plates::decode_replay(replay);
        plates::draw_tile(result.replay, bounded, ctx.seed(), layers, tiling->owned(), every,
                          [&](std::int64_t step, ConstGridView tile) { lapse.record(step, tile); });
    } else {
        result = plates::simulate(start, bounded, ctx.seed(), layers, on_step, every,
                                  [&](std::int64_t step, ConstGridView terrain) { lapse.record(step, terrain); });
    }
    lapse.finish(params.steps, *hm);
    ctx.check_finite(hm->heights(), "height", params.steps);
    const auto& s = result.stats;
    if (!tiling || tiling->rank() == 0)  // the simulation's counts are rank 0's (the others only drew its outcome)
        ctx.info(std::to_string(s.events[1]) + " convergent (" + std::to_string(s.subductions) + " subducting), " +
                 std::to_string(s.events[2]) + " divergent, " + std::to_string(s.events[3]) + " transform contacts; " +
                 std::to_string(s.rifts) + " rifts; " + std::to_string(result.final_plates.size()) +
                 " plates at the end");

    NodeOutputs out(hm);
    out.side["plates"] = Value(std::make_shared<PlateHistory>(std::move(result.history)));
    if (lapse.enabled()) out.side["timelapse"] = Value(lapse.series());
    return out;
}

void check(CheckContext& ctx) {
    const ValueInfo* in = ctx.input(0);
    const int w = in && in->width > 0 ? in->width : ctx.grid().width;
    const int h = in && in->height > 0 ? in->height : ctx.grid().height;
    const int most = plates::max_plates(w, h);
    const std::int64_t n = ctx.integer("plates");
    if (n > most)
        ctx.error("plates",
                  "a " + std::to_string(w) + " × " + std::to_string(h) + " heightmap holds at most " +
                      std::to_string(most) +
                      " plates (each needs 16 × 16 samples); ask for fewer plates "
                      "or a larger grid");
    for (const char* layer : {"uplift", "boundary", "plate"}) ctx.output().layers.insert(layer);
    check_timelapse(ctx, ctx.integer("steps"));
}

}  // namespace

OROGEN_PLUGIN("tectonics-plates", "0.1.0", registry) {
    std::vector<std::string> drives(plates::drive_names.begin(), plates::drive_names.end());
    std::vector<std::string> range_styles(plates::range_style_names.begin(), plates::range_style_names.end());
    registry.add({
        .kind = "tectonics",
        .name = "plates",
        .summary = "Box2D plate tectonics: colliding plates raise ranges; diverging plates rift, dense plates subduct",
        .description =
            "The thesis's plate simulation (section 3.6) and its future work. The area is cut into `plates` convex "
            "plates (at most 8 vertices, Box2D's limit) that move in a 2-D Box2D world, kept inside and in motion "
            "by four kinematic beams (`drive`). Each new two-point contact between two plates is classified by "
            "their relative velocity: approaching → a jagged mountain range along the contact (`height`; "
            "ranges=cells: the thesis's Voronoi cells), or, if one plate is clearly denser (oceanic under "
            "continental), a narrow trench on its side and a chain of volcanoes inland on the other; separating → "
            "a rift valley stepping down in fault blocks, with a rough ridge on its axis; sliding past → no "
            "change. Repeated contacts at one place saturate at `saturation` contacts' worth of relief. A plate whose "
            "collision impulse passes `rift_threshold` splits in two and the parts move "
            "apart. The simulation area (36 units on the longer side) covers the heightmap. Adds the layers "
            "uplift (m), boundary (1 convergent, 2 divergent, 3 transform) and plate (id of the plate over each "
            "sample at the end, -1 none), and the side value `plates` (polygons every `record_every` steps and "
            "every contact event).",
        .inputs = {{"crust", ValueType::heightmap, Need::required, "the heightmap before tectonics"}},
        .output = ValueType::heightmap,
        .side_outputs = {{"plates", ValueType::plates, "plate polygons over time and the boundary events"},
                         timelapse_output()},
        .params =
            {
                Param::integer("plates", 12).min(2).max(256).help("number of plates cut from the area at the start"),
                Param::integer("steps", 1000).min(1).max(10'000'000).help("Box2D steps to simulate"),
                Param::real("dt", 0.1).min(0.0, true).max(10.0).unit("s").help("simulated time per step"),
                Param::choice("drive", drives, "converge")
                    .help("how the beams move: converge (opposite beams push inward together, one axis after the "
                          "other), rotate (faces convey round the box), shear (north and south faces convey in "
                          "opposite directions), thesis (all beams in phase: the box shakes), still (no beams "
                          "moving: plates keep their start velocities)"),
                Param::real("speed", 1.0)
                    .min(0.0, true)
                    .max(20.0)
                    .unit("u/s")
                    .help("beam speed and the plates' largest start speed, in simulation units (the area is 36 u "
                          "across, as in the thesis)"),
                Param::real("restitution", 0.5).min(0.0).max(1.0).help("bounciness of plate contacts (thesis 0.5)"),
                Param::integer("cones", 100)
                    .min(1)
                    .max(100'000)
                    .help("sets the scale of all boundary relief: widths are multiples of the Voronoi cell size "
                          "sqrt(area / cones) (a range reaches 0.8 cells either side of its contact); with "
                          "ranges=cells, the Voronoi sites over the grid for each range (thesis 100)"),
                Param::choice("ranges", range_styles, "peaks")
                    .help("how a collision raises its range: peaks (a crest of jagged peaks along the contact, "
                          "the same peaks every time the place is hit, saturating) or cells (the thesis: the "
                          "Voronoi cells the contact crosses, a fresh diagram per contact, summed)"),
                Param::real("height", 80.0).min(0.0).unit("m").help("raise of a mountain range per convergent contact"),
                Param::real("jitter", 0.5)
                    .min(0.0)
                    .max(1.0)
                    .help("per-peak, per-volcano (and with ranges=cells per-cell) height variation (thesis 4.2)"),
                Param::real("rift_depth", 20.0)
                    .min(0.0)
                    .unit("m")
                    .help("depth of a rift valley per divergent contact; its flanks step down in fault blocks "
                          "half this high"),
                Param::real("ridge_height", 10.0)
                    .min(0.0)
                    .unit("m")
                    .help("height of the rough ridge along a rift's axis"),
                Param::real("trench_depth", 25.0).min(0.0).unit("m").help("depth of a subduction trench per contact"),
                Param::real("arc_height", 35.0)
                    .min(0.0)
                    .unit("m")
                    .help("height of the volcanoes of an arc per subduction contact"),
                Param::real("saturation", 5.0)
                    .min(1.0)
                    .max(1000.0)
                    .help("contacts' worth of relief one place can take: where a boundary is hit again and again, "
                          "its relief tends to saturation × one contact's (ranges=cells ranges are not limited)"),
                Param::real("oceanic_fraction", 0.5)
                    .min(0.0)
                    .max(1.0)
                    .help("share of oceanic (dense) plates; where oceanic meets continental, the oceanic subducts"),
                Param::real("rift_threshold", 20000.0)
                    .min(0.0)
                    .unit("N·s")
                    .help("collision impulse (simulation units) a plate takes before it splits in two; 0 = never"),
                Param::integer("record_every", 10).min(1).help("record the plate polygons every this many steps"),
                timelapse_param(),
            },
        .adds_layers = {"uplift", "boundary", "plate"},
        .tile_halo = 0,  // tiled: Box2D on rank 0, its outcome drawn by every rank into its tile
        .check = check,
        .run = run,
        .tiled_timelapse = true,  // every rank draws its tile of each frame from the replay, rank 0 gathers them
    });
}
