// erode:pipe — registers the Mei et al. pipe model (pipe.hpp) with the kernel.
#include "pipe.hpp"

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

// The pipe fluxes are state too (the water's momentum): kept as layers so a
// following erode:pipe continues exactly where this one stopped.
constexpr const char* kFluxLayers[] = {"flux_west", "flux_east", "flux_north", "flux_south"};

/// The whole grid's suspended sediment summed after the last sub-step's
/// transport (m, summed over the cells), to the last bit (17 digits): the
/// closed-wall fix-up's total, which a tiled run sums in the single
/// process's order (tests/mpi compares the two lines).
std::string suspended_line(const pipe::Solver& solver) {
    std::ostringstream msg;
    msg.precision(17);
    msg << "suspended sediment " << solver.total_sediment() << " m, summed over the cells";
    return msg.str();
}

/// One rank's tile of a tiled run (orogen/tiles.hpp). The state moves into
/// grids covering the tile grown by pipe::kTileHalo (the tile's own layers
/// are dropped meanwhile, so memory stays about the single process's per
/// cell); the solver refills their halo before every sub-step and reduces
/// across ranks (pipe.hpp), so the owned cells end with the single
/// process's bits; then the owned part goes back into the tile's layers.
NodeOutputs run_tiled(NodeContext& ctx, Tiling& tiles, std::shared_ptr<Heightmap> hm, const pipe::Settings& s,
                      std::vector<float> mask) {
    TiledFields fields(tiles, hm->cell());
    const TileRect own = fields.owned();
    const int ox = fields.ox(), oy = fields.oy();
    // 0 height, 1 water, 2 sediment, 3-6 fluxes, 7 flow (speed).
    const char* names[] = {"",    "water", "sediment", kFluxLayers[0], kFluxLayers[1], kFluxLayers[2], kFluxLayers[3],
                           "flow"};
    GridView held[8];
    held[0] = fields.grow(hm->heights().data());
    for (int k = 1; k < 8; ++k) {
        if (hm->has_layer(names[k])) {
            held[k] = fields.grow(std::as_const(*hm).layer(names[k]).data);
            hm->remove_layer(names[k]);
        } else {
            held[k] = fields.zeros();  // a new state starts at 0, as the layer would
        }
    }
    GridView held_mask;
    if (!mask.empty()) {  // the rain factors of the halo too, once: they do not change
        held_mask = fields.grow(mask.data());
        std::vector<float>().swap(mask);
        fields.exchange(held_mask);
    }
    pipe::State st{held[0], held[1], held[2], held[3], held[4], held[5], held[6], held[7]};
    const std::int64_t steps = ctx.integer("steps");
    const double dt = ctx.real("dt");
    using clock = std::chrono::steady_clock;
    const double waited_before = tiles.seconds_waiting();
    const auto t0 = clock::now();
    const double cpu0 = pipe::process_cpu_seconds();
    // Snapshots as run()'s, rank 0 holding them; the first has the water layer run() makes (0 if new).
    Timelapse lapse(ctx.integer("timelapse_every"), dt, tiles);  // time in seconds
    lapse.record(0, st.height, st.water.data, ox, oy);
    {
        pipe::Solver solver(st, s, held_mask.data, &tiles);
        for (std::int64_t i = 1; i <= steps; ++i) {
            ctx.check_cancelled();
            solver.advance(dt, i);
            if (i < steps) lapse.record(i, solver.current_height(), st.water.data, ox, oy);
            if (i % 16 == 0 || i == steps) ctx.progress(double(i) / double(steps));
        }
        solver.finish();
        const double total = std::chrono::duration<double>(clock::now() - t0).count();
        const double ex = solver.seconds_exchanging(), red = solver.seconds_reducing();
        const double cpu = pipe::process_cpu_seconds() - cpu0;
        const double cpu_other = solver.cpu_seconds_exchanging() + solver.cpu_seconds_reducing();
        std::ostringstream msg;
        msg.precision(3);
        msg << "rank " << tiles.rank() << " of " << tiles.ranks() << ": tile " << own.width << "x" << own.height
            << " at (" << own.x0 << ", " << own.y0 << "), " << steps << " steps of " << dt << " s in "
            << solver.substeps() << " sub-steps: " << total << " s, halo exchange " << ex << " s ("
            << (total > 0 ? 100.0 * ex / total : 0.0) << " %), reductions " << red << " s ("
            << (total > 0 ? 100.0 * red / total : 0.0) << " %), of which waiting for the other ranks "
            << tiles.seconds_waiting() - waited_before << " s; CPU " << cpu
            << " s, of which halo exchange and reductions " << cpu_other << " s";
        ctx.info(msg.str());
        if (tiles.rank() == 0) ctx.info(suspended_line(solver));
    }
    if (held_mask.data) fields.drop(held_mask);
    // The owned parts back into the tile (moved within each grid, TiledFields::take).
    std::vector<float> after = fields.take(held[0]);
    for (int k = 1; k < 8; ++k) hm->set_layer(names[k], fields.take(held[k]));
    // As run() checks: in a tiled run the solver's own check covers each sub-step already.
    fields.check_finite({after.data(), own.width, own.height, hm->cell()}, "height", steps);
    fields.check_finite(std::as_const(*hm).layer("water"), "water", steps);
    fields.check_finite(std::as_const(*hm).layer("sediment"), "sediment", steps);
    GridView eroded = hm->layer("eroded", 0.0f);
    for (std::size_t i = 0; i < after.size(); ++i) eroded.data[i] += after[i] - hm->heights()[i];
    hm->heights() = std::move(after);
    lapse.finish(steps, *hm);
    NodeOutputs out(hm);
    if (lapse.enabled()) out.side["timelapse"] = Value(lapse.series());
    return out;
}

NodeOutputs run(NodeContext& ctx) {
    auto hm = ctx.take_heightmap(0);
    pipe::Settings s;
    s.rain = ctx.real("rain");
    s.evaporation = ctx.real("evaporation");
    s.capacity = ctx.real("capacity");
    s.dissolve = ctx.real("dissolve");
    s.deposit = ctx.real("deposit");
    s.gravity = ctx.real("gravity");
    s.pipe_area = ctx.real("pipe_area");
    s.min_slope = ctx.real("min_slope");
    s.erosion_depth = ctx.real("erosion_depth");
    s.creep = ctx.real("creep");
    s.boundary = ctx.text("boundary") == "open" ? pipe::Boundary::open : pipe::Boundary::closed;

    // Rain mask: a layer of the input, or a second heightmap of the same size.
    std::vector<float> mask;
    const std::string& mask_layer = ctx.text("rain_mask");
    if (!mask_layer.empty()) {
        if (!hm->has_layer(mask_layer)) throw BadInput("rain_mask: the input has no layer '" + mask_layer + "'");
        const ConstGridView m = std::as_const(*hm).layer(mask_layer);
        mask.assign(m.data, m.data + m.size());
    } else if (ctx.has_input(1)) {
        const auto& m = *ctx.input(1).heightmap();
        if (m.width() != hm->width() || m.height() != hm->height()) {
            std::ostringstream msg;
            msg << "the rain mask is " << m.width() << "x" << m.height() << " but the terrain is " << hm->width() << "x"
                << hm->height() << "; give a mask of the terrain's size";
            throw BadInput(msg.str());
        }
        mask = m.heights();
    }
    for (float& v : mask)
        if (!(v >= 0.0f))
            throw BadInput("rain_mask: the mask holds a negative or NaN value; rain factors must be >= 0");

    // State: continue from water/sediment/flux layers when the input has them.
    // `flow` is this model's speed only in a pipe state (one with the flux
    // layers); erode:hydraulic writes its own `flow` (water per step, m) and
    // drops the fluxes, and its `flow` must not set the first sub-step's CFL limit.
    bool pipe_state = true;
    for (const char* l : kFluxLayers) pipe_state = pipe_state && hm->has_layer(l);
    if (!pipe_state) hm->remove_layer("flow");
    if (Tiling* tiles = ctx.tiling()) return run_tiled(ctx, *tiles, std::move(hm), s, std::move(mask));
    pipe::State st;
    st.height = hm->view();
    st.water = hm->layer("water", 0.0f);
    st.sediment = hm->layer("sediment", 0.0f);
    st.flux_west = hm->layer(kFluxLayers[0], 0.0f);
    st.flux_east = hm->layer(kFluxLayers[1], 0.0f);
    st.flux_north = hm->layer(kFluxLayers[2], 0.0f);
    st.flux_south = hm->layer(kFluxLayers[3], 0.0f);
    st.speed = hm->layer("flow", 0.0f);
    GridView eroded = hm->layer("eroded", 0.0f);
    const std::vector<float> before = hm->heights();

    const std::int64_t steps = ctx.integer("steps");
    const double dt = ctx.real("dt");
    Timelapse lapse(ctx.integer("timelapse_every"), dt);  // time in seconds
    lapse.record(0, *hm);
    {
        pipe::Solver solver(st, s, mask.empty() ? nullptr : mask.data());
        for (std::int64_t i = 1; i <= steps; ++i) {
            ctx.check_cancelled();
            solver.advance(dt, i);
            if (i < steps) lapse.record(i, solver.current_height(), st.water.data);
            if (i % 16 == 0 || i == steps) ctx.progress(double(i) / double(steps));
        }
        solver.finish();
        std::ostringstream msg;
        msg << steps << " steps of " << dt << " s in " << solver.substeps() << " sub-steps";
        ctx.info(msg.str());
        ctx.info(suspended_line(solver));
    }
    ctx.check_finite(hm->heights(), "height", steps);
    ctx.check_finite(st.water.span(), "water", steps);
    ctx.check_finite(st.sediment.span(), "sediment", steps);
    const std::vector<float>& after = hm->heights();
    for (std::size_t i = 0; i < after.size(); ++i) eroded.data[i] += after[i] - before[i];
    lapse.finish(steps, *hm);
    NodeOutputs out(hm);
    if (lapse.enabled()) out.side["timelapse"] = Value(lapse.series());
    return out;
}

void check(CheckContext& ctx) {
    const std::string& mask_layer = ctx.text("rain_mask");
    const ValueInfo* in = ctx.input(0);
    const ValueInfo* mask = ctx.input(1);
    if (!mask_layer.empty()) {
        if (mask) ctx.error("rain_mask", "give the rain mask either as a layer name or as a second input, not both");
        ctx.require_layer(0, "rain_mask", mask_layer);
    }
    if (mask && in && mask->width > 0 && in->width > 0 && (mask->width != in->width || mask->height != in->height)) {
        std::ostringstream msg;
        msg << "the rain mask is " << mask->width << "x" << mask->height << " but the terrain is " << in->width << "x"
            << in->height << "; give a mask of the terrain's size";
        ctx.error("", msg.str());
    }
    for (const char* l : {"water", "sediment", "flow", "eroded"}) ctx.output().layers.insert(l);
    for (const char* l : kFluxLayers) ctx.output().layers.insert(l);
    check_timelapse(ctx, ctx.integer("steps"));
}

}  // namespace

OROGEN_PLUGIN("erode-pipe", "0.1.0", registry) {
    registry.add({
        .kind = "erode",
        .name = "pipe",
        .summary = "Mei et al.'s virtual-pipe hydraulic erosion, sub-stepped so it is stable at any time step",
        .description =
            "The shallow-water 'virtual pipe' model of Mei, Decaudin & Hu (2007): water flows through pipes to "
            "the 4 neighbours, accelerated by the surface drop and limited so no cell goes negative; its "
            "velocity sets a sediment capacity (capacity * sin(tilt) * speed, the speed capped at sqrt(g*depth) so "
            "thin films do not scour like rivers, ramped down in water shallower than erosion_depth); the terrain "
            "erodes where the water carries less than that (never below its lowest neighbour) and receives "
            "deposits where it carries more (never above its highest); creep diffuses the terrain a little; "
            "sediment moves with the water (semi-Lagrangian, at most one cell per sub-step); water evaporates. Each "
            "step of dt seconds is split into sub-steps under "
            "a CFL limit, so any dt runs without blowing up. Walls are closed unless boundary=open. Terrain + "
            "sediment (and, without rain and evaporation, water) is conserved. State layers: water (m), "
            "sediment (m), flow (speed carrying sediment, m/s), flux_west/east/north/south (m^3/s), eroded (net "
            "change, m); an "
            "input that carries them continues the simulation.",
        .inputs = {{"terrain", ValueType::heightmap, Need::required, "heightmap to erode"},
                   {"rain_mask", ValueType::heightmap, Need::optional,
                    "rain factor per cell (its heights, >= 0), same size as the terrain"}},
        .output = ValueType::heightmap,
        .side_outputs = {timelapse_output()},
        .params =
            {
                Param::integer("steps", 200).min(0).max(100'000'000).help("number of time steps"),
                Param::real("dt", 0.25)
                    .min(0.0, true)
                    .max(3600.0)
                    .unit("s")
                    .help("time step; split internally into sub-steps under a CFL limit"),
                Param::real("rain", 0.001).min(0.0).unit("m/s").help("rain rate on every cell (times the mask)"),
                Param::string("rain_mask", "")
                    .help("name of a layer of the input holding a rain factor (>= 0) per cell; \"\" = none"),
                Param::real("evaporation", 0.01)
                    .min(0.0)
                    .unit("1/s")
                    .help("fraction of water evaporating per second (exponential decay)"),
                Param::real("capacity", 1.0)
                    .min(0.0)
                    .unit("s")
                    .help("sediment capacity Kc: metres carried per unit sin(tilt) and m/s of speed"),
                Param::real("dissolve", 0.5).min(0.0).unit("1/s").help("rate Ks of taking up the capacity deficit"),
                Param::real("deposit", 1.0).min(0.0).unit("1/s").help("rate Kd of dropping the capacity excess"),
                Param::real("gravity", 9.81).min(0.0, true).max(1000.0).unit("m/s²").help("gravity"),
                Param::real("pipe_area", 1.0)
                    .min(0.0, true)
                    .unit("m²")
                    .help("cross-section A of each virtual pipe: flux gains dt*g*A*drop/cell per step"),
                Param::real("min_slope", 0.05)
                    .min(0.0)
                    .max(1.0)
                    .help("lower bound of sin(tilt) in the capacity, so water on flat ground still carries"),
                Param::real("erosion_depth", 0.05)
                    .min(0.0)
                    .unit("m")
                    .help("water shallower than this carries in proportion to its depth, so films of rain do not "
                          "scour like rivers (0 = Mei's original capacity)"),
                Param::real("creep", 0.2)
                    .min(0.0)
                    .unit("m²/s")
                    .help("soil creep: a linear diffusion of the terrain that damps the cell-sized ripples erosion "
                          "alone amplifies (0 = Mei's original; at most 0.2*cell²/dt per sub-step)"),
                Param::choice("boundary", {"closed", "open"}, "closed")
                    .help("closed: walls keep the water in; open: water flows off the edges"),
                timelapse_param(),
            },
        .adds_layers = {"water", "sediment", "flow", "eroded", "flux_west", "flux_east", "flux_north", "flux_south"},
        .tile_halo = pipe::kTileHalo,
        .check = check,
        .run = run,
        .tiled_timelapse = true,  // rank 0 gathers the frames (Timelapse with the tiling)
    });
}
