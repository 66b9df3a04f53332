// erode:sph — registers the SPH hydraulic eroder (sph.hpp) with the kernel.
#include "sph.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>  // human_bytes, physical_memory
#include <orogen/plugin.hpp>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <sstream>
#include <utility>
#include <string>
#include <vector>

namespace {

using namespace orogen;

sph::Settings settings(const NodeContext& ctx) {
    sph::Settings s;
    s.radius = ctx.real("radius");
    s.rest_density = ctx.real("density");
    s.sound_speed = ctx.real("sound_speed");
    s.viscosity = ctx.real("viscosity");
    s.gravity = ctx.real("gravity");
    s.cfl = ctx.real("cfl");
    s.friction = ctx.real("friction");
    s.boundary = ctx.text("boundary") == "open" ? sph::Boundary::open : sph::Boundary::closed;
    s.sea_level = ctx.real("sea_level");
    s.capacity = ctx.real("capacity");
    s.deposit = ctx.real("deposit");
    s.min_slope = ctx.real("min_slope");
    s.max_dig = ctx.real("max_dig");
    return s;
}

NodeOutputs run(NodeContext& ctx) {
    auto hm = ctx.take_heightmap(0);
    const sph::Settings s = settings(ctx);
    const auto capacity = std::size_t(ctx.integer("particles"));
    const std::int64_t steps = ctx.integer("steps");
    const double dt = ctx.real("dt");
    const std::int64_t rain = ctx.integer("rain");
    const double rain_height = ctx.real("rain_height");
    const auto& springs = ctx.points("springs");
    const std::int64_t spring_rate = ctx.integer("spring_rate");
    const auto acidity = float(ctx.real("acidity"));
    const auto lifespan = std::int32_t(ctx.integer("lifespan"));
    const std::int64_t record_every = ctx.integer("record_every");
    const std::uint64_t seed = ctx.seed();

    const std::vector<float> before = hm->heights();
    auto series = std::make_shared<ParticleSeries>();
    sph::Simulation sim(std::as_const(*hm).view(), s, capacity);
    const double ex = (hm->width() - 1) * hm->cell(), ez = (hm->height() - 1) * hm->cell();
    auto record = [&](std::int64_t step) {
        ParticleFrame f;
        f.step = step;
        sim.record(f);
        series->frames.push_back(std::move(f));
    };
    if (record_every > 0) record(0);
    for (std::int64_t step = 1; step <= steps; ++step) {
        ctx.check_cancelled();
        sim.rain(rain, rain_height, seed, step, acidity, lifespan);
        for (std::size_t k = 0; k < springs.size(); ++k)
            sim.spring(springs[k].x * ex, springs[k].y * ez, spring_rate, seed, step, std::int64_t(k), acidity,
                       lifespan);
        sim.advance(dt, step);
        sim.end_step();
        if (record_every > 0 && step % record_every == 0) record(step);
        if (step % 8 == 0 || step == steps) ctx.progress(double(step) / double(steps));
    }
    const sph::Counts& c = sim.counts();
    {
        std::ostringstream msg;
        msg << steps << " steps in " << sim.substeps() << " sub-steps; particles: " << c.spawned << " spawned, "
            << sim.size() << " alive, " << c.evaporated << " evaporated, " << c.left << " left over the edges, "
            << c.sea << " reached the sea";
        ctx.info(msg.str());
        if (c.refused > 0) {
            std::ostringstream w;
            w << c.refused << " particles were not spawned: more than particles=" << capacity
              << " would have been alive at once; raise particles or lower rain/spring_rate";
            ctx.warn(w.str());
        }
    }
    sim.write_terrain(hm->view());
    ctx.check_finite(hm->heights(), "height", steps);
    GridView eroded = hm->layer("eroded", 0.0f);
    GridView deposited = hm->layer("deposited", 0.0f);
    const std::vector<float>& after = hm->heights();
    for (std::size_t i = 0; i < after.size(); ++i) {
        const float change = after[i] - before[i];
        eroded.data[i] += change;
        if (change > 0.0f) deposited.data[i] += change;
    }
    sim.write_water(hm->layer("water", 0.0f));
    NodeOutputs out(hm);
    out.side["particles"] = Value(std::shared_ptr<const ParticleSeries>(std::move(series)));
    return out;
}

void check(CheckContext& ctx) {
    const auto particles = std::uint64_t(ctx.integer("particles"));
    const double need = double(particles) * double(sph::Simulation::bytes_per_particle());
    const double limit = double(physical_memory()) / 4.0;
    if (need > limit) {
        ctx.error("particles",
                  std::to_string(particles) + " particles need " + human_bytes(need) + " of memory, more than the " +
                      human_bytes(limit) + " allowed here (a quarter of this machine's memory); use at most about " +
                      std::to_string(std::uint64_t(limit / double(sph::Simulation::bytes_per_particle()))));
    }
    if (ctx.integer("rain") == 0 && ctx.param("springs") == ParamValue(std::vector<Point2>{}))
        ctx.error("rain", "no water: rain=0 and no springs; give rain > 0 or springs=[(x, y), ...]");
    for (const char* l : {"eroded", "deposited", "water"}) ctx.output().layers.insert(l);
}

}  // namespace

OROGEN_PLUGIN("erode-sph", "0.1.0", registry) {
    registry.add({
        .kind = "erode",
        .name = "sph",
        .summary = "hydraulic erosion by SPH water particles (rain and springs) that dissolve, carry and drop terrain",
        .description =
            "The thesis's SPH eroder with a real fluid: weakly compressible SPH (Tait equation of state, "
            "Monaghan's artificial viscosity, CFL-limited sub-steps), a cell list with the particles sorted by "
            "cell every sub-step and vectorized neighbour sums, terrain contact by a Möller–Trumbore test of each "
            "particle's motion against "
            "the two triangles of the tile beneath it and an impulse along the normal interpolated from the "
            "tile's vertex normals (no particle ever ends below the surface). Rain spawns `rain` particles per "
            "step rain_height m above random points; springs spawn spring_rate per step at grid-relative points. "
            "A particle touching the terrain has a capacity capacity·volume·speed·max(sin slope, min_slope): "
            "below it, it dissolves acidity·dt of the deficit; above it, it drops deposit·dt of the excess; when "
            "it evaporates (lifespan steps) or reaches sea_level it leaves what it carries. Terrain + carried "
            "sediment (+ what left over open edges) is conserved. Layers: eroded (net change, m), deposited "
            "(m of growth), water (mean depth of water over the run, m). Side value `particles`: a frame every "
            "record_every steps with position, velocity, density, pressure, sediment (m³), acidity, age (steps).",
        .inputs = {{"terrain", ValueType::heightmap, Need::required, "heightmap to erode"}},
        .output = ValueType::heightmap,
        .side_outputs = {{"particles", ValueType::particles,
                          "particle frames every record_every steps (for export:vtk-particles / vdb-particles)"}},
        .params =
            {
                Param::integer("steps", 200).min(0).max(100'000'000).help("number of time steps"),
                Param::real("dt", 0.05)
                    .min(0.0, true)
                    .max(3600.0)
                    .unit("s")
                    .help("time step; split internally into CFL-limited sub-steps"),
                Param::integer("particles", 100'000)
                    .min(1)
                    .max(2'000'000'000)
                    .help("most particles alive at once (memory is reserved for them)"),
                Param::integer("rain", 100).min(0).max(100'000'000).help("rain particles spawned per step"),
                Param::real("rain_height", 2.0)
                    .min(0.0, true)
                    .max(1e5)
                    .unit("m")
                    .help("height above the terrain at which rain spawns"),
                Param::points("springs", std::vector<Point2>{})
                    .min(0)
                    .max(1)
                    .help("point sources, grid-relative (0..1, 0..1); [] none"),
                Param::integer("spring_rate", 10).min(0).max(1'000'000).help("particles per step per spring"),
                Param::real("radius", 0.5)
                    .min(0.0, true)
                    .max(1e4)
                    .unit("m")
                    .help("particle radius: spacing 2·radius, kernel support 4·radius"),
                Param::integer("lifespan", 500)
                    .min(1)
                    .max(2'000'000'000)
                    .help("steps a particle lives before it evaporates and leaves its sediment"),
                Param::real("acidity", 2.0)
                    .min(0.0)
                    .max(1e6)
                    .unit("1/s")
                    .help("rate at which a touching particle dissolves the deficit below its capacity"),
                Param::real("capacity", 0.5)
                    .min(0.0)
                    .unit("s/m")
                    .help("sediment capacity: m³ of terrain per m³ of water per m/s of speed along the slope"),
                Param::real("deposit", 1.0).min(0.0).unit("1/s").help("rate of dropping the excess over capacity"),
                Param::real("min_slope", 0.05).min(0.0).max(1.0).help("lower bound of sin(slope) in the capacity"),
                Param::real("max_dig", 0.05)
                    .min(0.0)
                    .unit("m")
                    .help("most a particle lowers a vertex in one sub-step (no drilled holes)"),
                Param::real("friction", 1.0)
                    .min(0.0)
                    .unit("1/s")
                    .help("decay rate of the speed along the terrain while touching it"),
                Param::real("viscosity", 0.05).min(0.0).max(10.0).help("Monaghan's artificial viscosity alpha"),
                Param::real("sound_speed", 20.0)
                    .min(0.0, true)
                    .max(1e5)
                    .unit("m/s")
                    .help("numerical speed of sound c0: density varies by about (v/c0)²; sub-steps shrink as it grows"),
                Param::real("density", 1000.0).min(0.0, true).unit("kg/m³").help("rest density of water"),
                Param::real("gravity", 9.81).min(0.0).max(1000.0).unit("m/s²").help("gravity"),
                Param::real("cfl", 0.4).min(0.0, true).max(1.0).help("Courant number of the sub-steps"),
                Param::choice("boundary", {"closed", "open"}, "closed")
                    .help("closed: the map's edges are walls; open: particles leave over them (counted)"),
                Param::real("sea_level", -1e30)
                    .unit("m")
                    .help("particles below this height are removed, leaving their sediment"),
                Param::integer("record_every", 10)
                    .min(0)
                    .max(100'000'000)
                    .help("steps between particle frames in .particles (0 = none)"),
            },
        .adds_layers = {"eroded", "deposited", "water"},
        .check = check,
        .run = run,
    });
}
