// erode:evolve — landscape evolution as a loop of process plugins: the spec gives the loop's body,
// one process a line, in braces after the call (orogen/process.hpp; libs/landscape/loop.hpp runs it).
#include <orogen/landscape/loop.hpp>
#include <orogen/landscape/model_node.hpp>
#include <orogen/landscape/processes.hpp>
#include <orogen/landscape/tiled.hpp>
#include <orogen/landscape/uplift.hpp>

#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/plugin.hpp>
#include <orogen/timelapse.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

namespace {

using namespace orogen;

constexpr double kSecondsPerYear = 31'557'600.0;  // the series' clock is in seconds (Julian years)

/// The heights after the run and what the loop itself knows as layers: eroded (the surface's change by
/// the processes other than uplift, m: negative where rock was removed; added to an earlier eroder's) and
/// uplifted (the rock uplift received, m). The processes add their own layers in finish().
void write_layers(NodeContext& ctx, landscape::ProcessLoop& loop, const std::vector<float>& before, std::int64_t last) {
    loop.finish();
    Heightmap& hm = loop.result();
    const std::vector<float>& out = hm.heights();
    ctx.check_finite(out, "height", last);
    const std::vector<double>& rock_uplift = loop.uplifted_so_far();
    GridView eroded = hm.layer("eroded", 0.0f);
    GridView uplifted = hm.layer("uplifted", 0.0f);
    for (std::size_t i = 0; i < out.size(); ++i) {
        eroded.data[i] += float(double(out[i]) - double(before[i]) - rock_uplift[i]);
        uplifted.data[i] += float(rock_uplift[i]);
    }
}

/// Under mpirun: the body lowered to erode:stream-power's model, which runs on each rank's tile (the same
/// bits as the loop: tests/plugins/erode/evolve); the kernel tiles this node only for such a body.
NodeOutputs run_tiled(NodeContext& ctx) {
    landscape::LoweredBody lowered = landscape::lower_to_model(ctx.processes(), ctx.seed());
    if (!lowered.why_not.empty()) throw Error("internal error: a tiled erode:evolve whose body " + lowered.why_not);
    lowered.settings.open = *landscape::parse_sides(ctx.text("open"));
    lowered.settings.substeps = int(ctx.integer("substeps"));
    return landscape::run_model(ctx, {lowered.settings, lowered.uplift, lowered.chi});
}

NodeOutputs run(NodeContext& ctx) {
    if (ctx.tiling()) return run_tiled(ctx);
    using clock = std::chrono::steady_clock;
    const auto started = clock::now();
    std::shared_ptr<Heightmap> hm = ctx.take_heightmap(0);
    const std::vector<float> before = hm->heights();
    std::vector<Value> inputs;
    for (std::size_t i = 0; i < ctx.input_count(); ++i) inputs.push_back(ctx.input(i));
    landscape::ProcessLoop::Options options;
    options.open = *landscape::parse_sides(ctx.text("open"));
    options.base_level = *landscape::parse_base_level(ctx.text("base_level"));
    options.substeps = int(ctx.integer("substeps"));
    options.years = ctx.real("years");
    options.seed = ctx.seed();
    options.info = [&ctx](std::string_view m) { ctx.info(m); };
    options.warn = [&ctx](std::string_view m) { ctx.warn(m); };
    landscape::ProcessLoop loop(ctx.processes(), hm, std::move(inputs), options);
    loop.start();

    const double years = ctx.real("years"), dt = ctx.real("dt");
    const std::int64_t every = ctx.integer("timelapse_every");
    Timelapse lapse(every, dt * kSecondsPerYear);
    lapse.record(0, *hm);
    std::vector<float> frame;
    std::int64_t last = 0;
    const std::vector<double>& heights = loop.heights();
    loop.run(years, dt, [&](std::int64_t step, std::int64_t steps) {
        ctx.check_cancelled();
        if (every > 0 && (step % every == 0 || step == steps)) {
            frame.assign(heights.begin(), heights.end());
            lapse.record(step, ConstGridView(frame.data(), hm->width(), hm->height(), hm->cell()));
        }
        last = steps;
        if (const std::int64_t bad = loop.first_non_finite(); bad >= 0) {
            std::ostringstream msg;
            msg << "non-finite height (" << heights[std::size_t(bad)] << ") at sample " << bad << " after step " << step
                << " of " << steps << "; the simulation became unstable (a process's time step too long? "
                << "give a smaller dt or more substeps)";
            throw Error(msg.str());
        }
        ctx.progress(double(step) / double(steps));
    });
    write_layers(ctx, loop, before, last);

    const std::vector<float>& out = hm->heights();
    const auto [lo, hi] = std::minmax_element(out.begin(), out.end());
    std::ostringstream msg;
    msg << last << " steps of " << dt << " yr";
    for (const auto& s : loop.summaries()) msg << "; " << s;
    msg << "; relief " << (*hi - *lo) << " m; " << std::chrono::duration<double>(clock::now() - started).count()
        << " s";
    ctx.info(msg.str());
    lapse.finish(last, *hm);
    NodeOutputs result(hm);
    if (lapse.enabled()) result.side["timelapse"] = Value(lapse.series());
    return result;
}

void check(CheckContext& ctx) {
    const auto sides = landscape::parse_sides(ctx.text("open"));
    if (!sides)
        ctx.error("open",
                  "'" + ctx.text("open") +
                      "' is not a set of sides; write the letters of the open sides (n, e, s, w), e.g. "
                      "\"nesw\", or all or none (every side closed: the lowest cell is the outlet)");
    if (!landscape::parse_base_level(ctx.text("base_level")))
        ctx.error("base_level",
                  "'" + ctx.text("base_level") +
                      "' is not a height; give edge (outlets keep their heights) or metres, e.g. \"0\"");
    if (ctx.real("dt") > ctx.real("years"))
        ctx.error("dt", "the time step is longer than the run (years); give dt <= years");
    // Each process's stability limit on this grid's cells.
    const ValueInfo* in = ctx.input(0);
    const double cell = in && in->cell > 0.0 ? in->cell : ctx.grid().cell;
    const double sub = ctx.real("dt") / double(ctx.integer("substeps"));
    const auto& processes = ctx.processes();
    for (std::size_t k = 0; k < processes.size(); ++k) {
        const ProcessCall& p = processes[k];
        if (!p.process->max_dt) continue;
        const double limit = p.process->max_dt(p, cell);
        if (sub > limit) {
            std::ostringstream msg;
            msg << "the sub-step dt/substeps = " << sub << " yr is longer than its stable step, " << limit << " yr on "
                << cell << " m cells; give the node dt <= " << limit * double(ctx.integer("substeps"))
                << " or substeps >= " << std::int64_t(std::ceil(ctx.real("dt") / limit));
            ctx.process_error(k, "", msg.str());
        }
    }
    // Glaciers erode in stream-power's detachment-limited sweep only (as erode:stream-power's).
    bool glaciers = false;
    for (std::size_t k = 0; k < processes.size(); ++k) {
        const ProcessCall& p = processes[k];
        glaciers = glaciers || p.process->name == "glaciers";
        if (glaciers && p.process->name == "stream-power" && p.real("deposition") > 0.0)
            ctx.process_error(k, "deposition",
                              "glaciers erode detachment-limited for now; give deposition=0 or drop glaciers()");
    }
    // Memory: the loop holds the heights and the uplift received (two doubles a cell) beside the processes'
    // fields; the flow graph's process holds about 40 bytes a cell more.
    const std::int64_t w = in && in->width > 0 ? in->width : ctx.grid().width;
    const std::int64_t h = in && in->height > 0 ? in->height : ctx.grid().height;
    const double need = double(w) * double(h) * (16.0 + 48.0 + 8.0 * double(processes.size()));
    const double have = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE));
    if (have > 0 && need > 0.5 * have)
        ctx.error("",
                  "a " + std::to_string(w) + " x " + std::to_string(h) + " grid needs about " + human_bytes(need) +
                      " for the loop's fields, more than half of this machine's " + human_bytes(have) +
                      "; use a smaller grid");
    check_timelapse(ctx, std::int64_t(std::ceil(ctx.real("years") / ctx.real("dt"))));
    for (const char* l : {"eroded", "uplifted"}) ctx.output().layers.insert(l);
}

}  // namespace

OROGEN_PLUGIN("erode-evolve", "0.1.0", registry) {
    registry.add({
        .kind = "erode",
        .name = "evolve",
        .summary = "landscape evolution as a loop of processes given in braces: uplift, flow, stream power, ...",
        .description =
            "Runs its body, the processes in braces after the call (one a line; `orogen list process`), every "
            "step of dt years, in the body's order: each in every sub-step of dt/substeps, but for the processes "
            "that run once a step (flow routing, rain), which run in the first. The processes share fields "
            "(elevation, uplifted, the flow graph, erodibility_factor, threshold_slope, ...): `orogen help "
            "PROCESS` says which each reads and writes, and the checker refuses a body whose fields are not "
            "made before they are read. Water leaves by the open sides, held at base level; with every side "
            "closed the lowest cell is the outlet. The same result on any number of threads. Adds the layers "
            "eroded (the surface's change by the processes other than uplift, m; added to an earlier eroder's) "
            "and uplifted (the rock uplift received, m), and each process's own (flow: drainage, "
            "flow_direction). docs/processes.md shows how to write a process of your own.",
        .inputs = {{"terrain", ValueType::heightmap, Need::required, "heightmap to evolve"},
                   {"uplift_history", ValueType::heightmap, Need::optional,
                    "heights over time (e.g. plates.timelapse), for the uplift process: the height change between "
                    "two frames is rock uplift over the years they map to",
                    Many::series}},
        .output = ValueType::heightmap,
        .side_outputs = {timelapse_output()},
        .params =
            {
                Param::real("years", 1e6).min(0.0, true).max(1e9).unit("yr").help("simulated time"),
                Param::real("dt", 1e4).min(0.0, true).max(1e8).unit("yr").help(
                    "time step; the processes that run once a step (routing) serve its substeps"),
                Param::integer("substeps", 1)
                    .min(1)
                    .max(1000)
                    .help("sub-steps a step: every process but the once-a-step ones runs this many times a step, "
                          "dt/substeps each"),
                Param::string("open", "nesw")
                    .help("the sides held at base level, where water leaves: letters n, e, s, w; all; or none "
                          "(every side closed: the lowest cell is the outlet)"),
                Param::string("base_level", "edge")
                    .help("the outlets' height: edge (they keep theirs) or metres, e.g. \"0\""),
                timelapse_param(),
            },
        .tile_halo = 1,
        .check = check,
        .run = run,
        .processes = true,
        .tiled_timelapse = true,
        .untiled_body_because =
            [](const std::vector<ProcessCall>& body) {
                const landscape::LoweredBody lowered = landscape::lower_to_model(body, 0);
                return lowered.why_not.empty() ? landscape::untiled_because(lowered.settings) : lowered.why_not;
            },
    });
}
