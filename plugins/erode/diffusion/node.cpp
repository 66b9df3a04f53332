// erode:diffusion — registers implicit hillslope diffusion (diffusion.hpp) with the kernel.
#include <orogen/solvers/diffusion.hpp>

#include <orogen/error.hpp>
#include <orogen/plugin.hpp>
#include <orogen/timelapse.hpp>

#include <chrono>
#include <cmath>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace orogen;

/// "nesw"-style side letters → which sides are fixed; false if a letter is not one of n e s w.
bool parse_sides(const std::string& text, solvers::diffusion::FixedSides& out) {
    out = {};
    if (text == "none") return true;
    if (text == "all") {
        out = {true, true, true, true};
        return true;
    }
    for (char c : text) {
        switch (c) {
            case 'n': out.north = true; break;
            case 'e': out.east = true; break;
            case 's': out.south = true; break;
            case 'w': out.west = true; break;
            default: return false;
        }
    }
    return true;
}

NodeOutputs run(NodeContext& ctx) {
    auto hm = ctx.take_heightmap(0);
    solvers::diffusion::Settings s;
    s.diffusivity = ctx.real("diffusivity");
    s.scheme = ctx.text("scheme") == "adi" ? solvers::diffusion::Scheme::adi : solvers::diffusion::Scheme::implicit;
    parse_sides(ctx.text("fixed"), s.fixed);
    const double sc = ctx.real("critical_angle");
    s.critical_slope = sc > 0.0 ? std::tan(sc * std::numbers::pi / 180.0) : 0.0;

    const double years = ctx.real("years"), dt = ctx.real("dt");
    const auto steps = std::int64_t(std::ceil(years / dt * (1.0 - 1e-12)));
    std::vector<double> h(hm->heights().begin(), hm->heights().end());
    const std::vector<float> before = hm->heights();
    // In a tiled run (mpirun) the heightmap is this rank's tile and the solver sweeps across the tiles
    // (diffusion.hpp): the same bits as one process, the tile's share of the memory.
    Tiling* tiles = ctx.tiling();
    solvers::diffusion::Solver solver = tiles ? solvers::diffusion::Solver(*tiles, hm->cell(), s)
                                              : solvers::diffusion::Solver(hm->width(), hm->height(), hm->cell(), s);
    // A sample's index in the whole grid, for the messages.
    auto sample = [&](std::size_t k) {
        if (!tiles) return std::int64_t(k);
        const TileRect own = tiles->owned();
        const auto x = std::int64_t(k % std::size_t(own.width)), y = std::int64_t(k / std::size_t(own.width));
        return (own.y0 + y) * tiles->grid_width() + own.x0 + x;
    };
    using clock = std::chrono::steady_clock;
    const auto started = clock::now();
    const std::int64_t every = ctx.integer("timelapse_every");
    // The series' clock is in seconds (Julian years); in a tiled run rank 0 gathers the frames.
    Timelapse lapse = tiles ? Timelapse(every, dt * 31'557'600.0, *tiles) : Timelapse(every, dt * 31'557'600.0);
    lapse.record(0, *hm);
    std::vector<float> frame;
    for (std::int64_t i = 1; i <= steps; ++i) {
        ctx.check_cancelled();
        solver.step(h.data(), i < steps ? dt : years - dt * double(steps - 1));
        if (every > 0 && (i % every == 0 || i == steps)) {
            frame.assign(h.begin(), h.end());
            lapse.record(i, ConstGridView(frame.data(), hm->width(), hm->height(), hm->cell()));
        }
        if (i % 16 == 0 || i == steps) {
            for (std::size_t k = 0; k < h.size(); ++k)
                if (!std::isfinite(h[k])) {
                    std::ostringstream msg;
                    msg << "non-finite height (" << h[k] << ") at sample " << sample(k) << " after step " << i
                        << "; the simulation became unstable";
                    throw Error(msg.str());
                }
            ctx.progress(double(i) / double(steps));
        }
    }
    std::vector<float>& out = hm->heights();
    for (std::size_t k = 0; k < h.size(); ++k) out[k] = float(h[k]);
    ctx.check_finite(out, "height", steps);
    GridView eroded = hm->layer("eroded", 0.0f);
    for (std::size_t k = 0; k < out.size(); ++k) eroded.data[k] += out[k] - before[k];
    std::ostringstream msg;
    msg << steps << " steps of " << dt << " yr, D = " << s.diffusivity << " m²/yr";
    if (tiles) {
        const TileRect own = tiles->owned();
        msg << "; rank " << tiles->rank() << " of " << tiles->ranks() << ": tile " << own.width << "x" << own.height
            << " at (" << own.x0 << ", " << own.y0 << "), "
            << std::chrono::duration<double>(clock::now() - started).count() << " s in the sweeps";
    }
    ctx.info(msg.str());
    lapse.finish(steps, *hm);
    NodeOutputs result(hm);
    if (lapse.enabled()) result.side["timelapse"] = Value(lapse.series());
    return result;
}

void check(CheckContext& ctx) {
    solvers::diffusion::FixedSides f;
    if (!parse_sides(ctx.text("fixed"), f))
        ctx.error("fixed",
                  "'" + ctx.text("fixed") +
                      "' is not a set of sides; write the letters of the fixed sides (n, e, s, w), e.g. "
                      "\"ns\", or all or none");
    if (ctx.real("dt") > ctx.real("years"))
        ctx.error("dt", "the time step is longer than the run (years); give dt <= years");
    check_timelapse(ctx, std::int64_t(std::ceil(ctx.real("years") / ctx.real("dt"))));
    ctx.output().layers.insert("eroded");
}

}  // namespace

OROGEN_PLUGIN("erode-diffusion", "0.1.0", registry) {
    registry.add({
        .kind = "erode",
        .name = "diffusion",
        .summary = "hillslope diffusion (soil creep) over geological time, implicit so any time step is stable",
        .description =
            "dh/dt = div(D grad h): soil creep carries material down-slope at a rate proportional to the slope "
            "(Culling 1960), rounding ridge crests and filling hollows. Each step of dt years solves the rows, "
            "then the columns, as tridiagonal systems (scheme=implicit: backward Euler in each direction, monotone "
            "at any dt; scheme=adi: Peaceman-Rachford, second order, rings when D*dt/cell^2 >> 1). With "
            "critical_angle > 0 the flux grows without bound as the slope nears that angle (Roering et al. 1999), "
            "so hillslopes stop at a threshold angle. Sides are closed (no flux; volume is conserved) unless "
            "listed in fixed. Adds the layer eroded (net change, m).",
        .inputs = {{"terrain", ValueType::heightmap, Need::required, "heightmap to diffuse"}},
        .output = ValueType::heightmap,
        .side_outputs = {timelapse_output()},
        .params =
            {
                Param::real("diffusivity", 0.01)
                    .min(0.0, true)
                    .max(10.0)
                    .unit("m²/yr")
                    .help("D: 1e-3 to 1e-1 for soil-mantled hillslopes (Fernandes & Dietrich 1997)"),
                Param::real("years", 1e5).min(0.0, true).max(1e9).unit("yr").help("simulated time"),
                Param::real("dt", 1e4).min(0.0, true).max(1e8).unit("yr").help("time step (any size is stable)"),
                Param::choice("scheme", {"implicit", "adi"}, "implicit")
                    .help("implicit (backward Euler per direction: monotone) or adi (Peaceman-Rachford: second "
                          "order, as fastscape)"),
                Param::real("critical_angle", 0.0)
                    .min(0.0)
                    .max(80.0)
                    .unit("°")
                    .help("threshold hillslope angle for nonlinear diffusion (Roering: about 40-50°); 0 = linear"),
                Param::string("fixed", "none")
                    .help("sides whose heights stay (letters n e s w, all or none); the others let nothing through"),
                timelapse_param(),
            },
        .adds_layers = {"eroded"},
        // Tiled under mpirun: the sweeps carry their recurrences across the tiles (Tiling::carry) and read one
        // vertex of each neighbour's edge.
        .tile_halo = 1,
        .check = check,
        .run = run,
        .tiled_timelapse = true,  // rank 0 gathers the frames (Timelapse with the tiling)
    });
}
