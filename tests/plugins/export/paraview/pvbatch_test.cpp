// export:paraview-state in ParaView itself: Debian's pvbatch 5.11 (unpacked by
// tools/paraview.sh into build/paraview, the ctest fixture paraview_fetch) runs
// the shipped script under Xvfb after the run's folder has been moved, saves a
// picture and reports what it built (inspect_state.py); and the README's own
// `tools/pvbatch` line, run as written without a display, on a scaled-down demo.
// Skips, saying why, only when the packages could not be downloaded
// (build/paraview/unavailable).
#include "orogen_test.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include "test_picture.hpp"
#include <png.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <regex>
#include <set>

using namespace orogen::test;
namespace fs = std::filesystem;

namespace {

int distance(const std::array<int, 3>& a, const std::array<int, 3>& b) {
    return std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) + std::abs(a[2] - b[2]);
}

/// Fraction of pixels that differ from the background (the top-left corner's colour).
double foreground_fraction(const Picture& p) {
    const auto background = p.at(0, 0);
    std::size_t n = 0;
    for (int y = 0; y < p.height; ++y)
        for (int x = 0; x < p.width; ++x) n += distance(p.at(x, y), background) > 24;
    return double(n) / (double(p.width) * p.height);
}

/// Distinct colours among the foreground pixels, quantised to 4 bits a channel.
std::size_t foreground_colours(const Picture& p) {
    const auto background = p.at(0, 0);
    std::set<int> colours;
    for (int y = 0; y < p.height; ++y)
        for (int x = 0; x < p.width; ++x) {
            const auto c = p.at(x, y);
            if (distance(c, background) > 24) colours.insert((c[0] >> 4) << 8 | (c[1] >> 4) << 4 | (c[2] >> 4));
        }
    return colours.size();
}

/// The share of the foreground pixels in the most common colour, colours told
/// apart by chromaticity (r, g, b over their sum, in 16 × 16 bins), so the
/// terrain's shading does not split one colour into many: a map drawn in one
/// flat colour scores near 1 however it is lit.
double dominant_colour_share(const Picture& p) {
    const auto background = p.at(0, 0);
    std::map<int, std::size_t> bins;
    std::size_t n = 0;
    for (int y = 0; y < p.height; ++y)
        for (int x = 0; x < p.width; ++x) {
            const auto c = p.at(x, y);
            if (distance(c, background) <= 24) continue;
            const double sum = std::max(1, c[0] + c[1] + c[2]);
            ++bins[int(c[0] / sum * 15.999) * 16 + int(c[1] / sum * 15.999)];
            ++n;
        }
    std::size_t most = 0;
    for (const auto& [bin, count] : bins) most = std::max(most, count);
    return n ? double(most) / double(n) : 1.0;
}

/// How the colour bar's range [bar_low, bar_high] and the data's 2–98 % range
/// [p2, p98] overlap: the smaller of the overlap's shares of each (1: the same
/// range; below 0.5: the bar misses more than half of the data, or spends more
/// than half of its colours where there is none). On a log scale, in decades.
double range_agreement(double bar_low, double bar_high, double p2, double p98, bool log) {
    if (log) {
        if (bar_low <= 0 || p2 <= 0) return 0.0;
        bar_low = std::log10(bar_low), bar_high = std::log10(bar_high), p2 = std::log10(p2), p98 = std::log10(p98);
    }
    const double overlap = std::min(bar_high, p98) - std::max(bar_low, p2);
    if (overlap <= 0) return 0.0;
    return std::min(overlap / std::max(bar_high - bar_low, 1e-12), overlap / std::max(p98 - p2, 1e-12));
}

/// The picture and colour checks of issue 52: most of the terrain is not one colour, and the colour bar
/// spans the coloured array's 2–98 % (computed by ParaView's numpy, not by orogen) within half.
void expect_shows_something(const nlohmann::json& report, const Picture& picture) {
    EXPECT_GT(foreground_fraction(picture), 0.2);
    EXPECT_GT(foreground_colours(picture), 40u);
    EXPECT_LT(dominant_colour_share(picture), 0.5) << "most of the terrain is one colour";
    const auto points = report["rgb_points"].get<std::vector<double>>();
    ASSERT_GE(points.size(), 8u);
    const double bar_low = points.front(), bar_high = points[points.size() - 4];
    const auto data = report["data_p2_p98"].get<std::vector<double>>();
    EXPECT_GE(range_agreement(bar_low, bar_high, data[0], data[1], report["log_scale"] == 1), 0.5)
        << "colour bar " << bar_low << " .. " << bar_high << ", data's 2-98 % " << data[0] << " .. " << data[1];
}

/// pvbatch from tools/paraview.sh, or a skip naming why the download was impossible.
class Pvbatch : public ::testing::Test {
protected:
    fs::path pvbatch = fs::path(OROGEN_PARAVIEW_DIR) / "pvbatch";

    void SetUp() override {
        const fs::path unavailable = fs::path(OROGEN_PARAVIEW_DIR) / "unavailable";
        if (fs::exists(unavailable)) GTEST_SKIP() << "ParaView could not be downloaded: " << slurp(unavailable);
        ASSERT_TRUE(fs::exists(pvbatch)) << pvbatch << " is missing: tools/paraview.sh (the ctest fixture "
                                         << "paraview_fetch) did not run or failed; run it: tools/paraview.sh "
                                         << OROGEN_PARAVIEW_DIR;
    }

    /// Runs inspect_state.py on `state` (a shipped script) under Xvfb; the report and pictures go to `out`.
    nlohmann::json inspect(const fs::path& state, const fs::path& out) {
        fs::create_directories(out);
        const std::string cmd = std::string(OROGEN_XVFB_RUN) + " " + q(pvbatch) + " " + q(OROGEN_INSPECT_STATE) + " " +
            q(state) + " " + q(out) + " >" + q(out / "pvbatch.log") + " 2>&1";
        // tests/viewer/xvfb-run.sh lets Xvfb pick its own free display, so tests started in the
        // same instant (ctest -j2) cannot share one.
        const int status = std::system(cmd.c_str());
        EXPECT_EQ(status, 0) << cmd << "\n" << slurp(out / "pvbatch.log");
        if (!fs::exists(out / "report.json")) {
            ADD_FAILURE() << "no report: " << slurp(out / "pvbatch.log");
            return {};
        }
        return nlohmann::json::parse(slurp(out / "report.json"));
    }
};

}  // namespace

// A small run with everything the state shows: a terrain with layers (plates
// add plate/boundary/uplift, SPH adds eroded), a plate history, particle frames.
TEST_F(Pvbatch, TheShippedStateOpensTheMovedRunWarpedColouredAndPlaying) {
    TempDir dir;
    const auto spec = dir.write("run.orogen",
                                "orogen 1\nseed 5\ngrid 65 cell=40\n"
                                "crust  = generate:diamond-square(roughness=0.55, amplitude=150)\n"
                                "plates = tectonics:plates(crust, plates=5, steps=60, record_every=20)\n"
                                "wet    = erode:sph(plates, steps=20, rain=30, record_every=10, lifespan=100)\n"
                                "export:paraview-state(wet, wet.particles, plates.plates, path=\"view/run.py\", "
                                "layer=\"eroded\")\n"
                                "export:raw(wet, path=\"wet.r32\")\n");
    const RunResult r = run_orogen("run " + q(spec) + " --quiet --out " + q(dir / "out"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    // The heights as ParaView must see them (export:raw: float32 little-endian).
    const std::string raw = slurp(dir / "out" / "wet.r32");
    ASSERT_EQ(raw.size(), 65u * 65u * 4u);
    std::vector<float> h(65 * 65);
    std::memcpy(h.data(), raw.data(), raw.size());
    const auto [lo, hi] = std::minmax_element(h.begin(), h.end());

    // Move the folder: the script must find its files relative to itself.
    fs::rename(dir / "out" / "view", dir / "moved");
    const nlohmann::json report = inspect(dir / "moved" / "run.py", dir / "pictures");
    ASSERT_FALSE(report.is_null());

    // Warped by height along Z with the script's exaggeration.
    const double e = report["exaggeration"];
    EXPECT_GE(e, 1.0);
    const auto bounds = report["terrain_bounds"].get<std::vector<double>>();
    EXPECT_NEAR(bounds[0], 0.0, 1e-6);
    EXPECT_NEAR(bounds[1], 64 * 40.0, 1e-6);  // X east
    EXPECT_NEAR(bounds[2], -64 * 40.0, 1e-6);  // Y north
    EXPECT_NEAR(bounds[3], 0.0, 1e-6);
    EXPECT_NEAR(bounds[4], *lo * e, 1e-3 * std::max(1.0, std::fabs(*lo * e)));
    EXPECT_NEAR(bounds[5], *hi * e, 1e-3 * std::max(1.0, std::fabs(*hi * e)));
    EXPECT_GT(bounds[5] - bounds[4], 10.0);
    EXPECT_EQ(report["terrain_points"], 65 * 65);

    // Coloured by the chosen layer (erosion and deposition: both signs) with a diverging map
    // symmetric about 0 and a scalar bar.
    EXPECT_EQ(report["colour_array"][0], "POINTS");
    EXPECT_EQ(report["colour_array"][1], "eroded");
    EXPECT_EQ(report["categorical"], 0);
    EXPECT_EQ(report["colour_space"], "Diverging");
    const auto points = report["rgb_points"].get<std::vector<double>>();
    ASSERT_GE(points.size(), 12u);
    EXPECT_DOUBLE_EQ(points.front(), -points[points.size() - 4]);
    EXPECT_EQ(report["scalar_bar"], 1);
    EXPECT_NE(report["scalar_bar_title"].get<std::string>().find("eroded"), std::string::npos);

    // Plates, collisions and particles loaded; time steps of both series; oblique camera.
    for (const char* s : {"terrain", "plates (draped)", "collisions (draped)", "particles (stretched)", "caption"})
        EXPECT_TRUE(std::count(report["sources"].begin(), report["sources"].end(), s)) << s;
    EXPECT_GE(report["times"].size(), 4u);  // plate snapshots 0, 20, 40, 60 and SPH frames
    EXPECT_EQ(report["play_mode"], "Snap To TimeSteps");
    EXPECT_EQ(report["opened_at"], report["times"].back());  // it opens where the series end
    EXPECT_GT(report["shown_at_first"]["plates (draped)"], 0);
    EXPECT_GT(report["shown_at_last"]["particles (stretched)"], 0);  // rain falls after the first frame
    // The water carrying the most sediment (its top tenth over the run) drawn apart: some, not all.
    EXPECT_GT(report["shown_at_last"]["sediment-laden particles"], 0);
    EXPECT_LT(report["shown_at_last"]["sediment-laden particles"], report["shown_at_last"]["particles (stretched)"]);
    EXPECT_GT(report["shown_at_last"]["collisions (draped)"], 0);
    // The plates lie on the terrain: their heights span its relief (not a flat plane above it) and
    // stay within a lift of 0.2 % of the side above its highest point, at the first step and the last.
    for (const char* when : {"plates_z_at_first", "plates_z_at_last"}) {
        const auto z = report[when].get<std::vector<double>>();
        EXPECT_GT(z[1] - z[0], 0.5 * (bounds[5] - bounds[4])) << when;
        EXPECT_GE(z[0], bounds[4] - 1e-3) << when;
        EXPECT_LE(z[1], bounds[5] + 0.005 * 64 * 40) << when;
    }
    const auto eye = report["camera_position"].get<std::vector<double>>();
    const auto focus = report["camera_focal_point"].get<std::vector<double>>();
    const double dx = eye[0] - focus[0], dy = eye[1] - focus[1], dz = eye[2] - focus[2];
    const double elevation = std::atan2(dz, std::hypot(dx, dy)) * 180 / M_PI;
    EXPECT_NEAR(elevation, 30.0, 0.5);  // oblique: neither from above nor from the side
    EXPECT_EQ(report["camera_view_up"], (std::vector<double>{0, 0, 1}));

    // --save-state wrote ParaView's XML state naming the moved run's terrain.
    const std::string pvsm = slurp(dir / "pictures" / "view.pvsm");
    EXPECT_NE(pvsm.find("<ServerManagerState version=\"5."), std::string::npos);
    EXPECT_NE(pvsm.find((dir / "moved" / "run.vti").string()), std::string::npos);

    // The picture shows something: a large share of non-background pixels in many colours.
    const Picture first = read_picture(dir / "pictures" / "first.png");
    ASSERT_EQ(first.width, 640);
    ASSERT_EQ(first.height, 400);
    EXPECT_GT(foreground_fraction(first), 0.2);
    EXPECT_GT(foreground_colours(first), 40u);
    const Picture opened = read_picture(dir / "pictures" / "state.png");
    EXPECT_GT(foreground_fraction(opened), 0.2);
    // And the last time step differs from the first (plates and particles moved).
    const Picture last = read_picture(dir / "pictures" / "last.png");
    EXPECT_GT(differing_pixels(first, last), 500u);

    // A file of the run missing: the state stops, naming it and where it looked, and draws nothing.
    fs::remove(dir / "moved" / "run-plates.pvd");
    const std::string cmd = std::string(OROGEN_XVFB_RUN) + " " + q(pvbatch) + " " + q(dir / "moved" / "run.py") +
        " --screenshot " + q(dir / "missing.png") + " >" + q(dir / "missing.log") + " 2>&1";
    EXPECT_NE(std::system(cmd.c_str()), 0);
    const std::string log = slurp(dir / "missing.log");
    EXPECT_NE(log.find("cannot find run-plates.pvd in " + (dir / "moved").string()), std::string::npos) << log;
    EXPECT_FALSE(fs::exists(dir / "missing.png"));
}

// Categorical colours for the plate layer: the annotations are the ids present.
TEST_F(Pvbatch, ThePlateLayerIsColouredByCategory) {
    TempDir dir;
    const auto spec = dir.write("run.orogen",
                                "orogen 1\nseed 5\ngrid 65 cell=40\n"
                                "crust  = generate:diamond-square(roughness=0.55, amplitude=150)\n"
                                "plates = tectonics:plates(crust, plates=5, steps=40)\n"
                                "export:paraview-state(plates, path=\"run.py\", layer=\"plate\", exaggeration=3)\n");
    const RunResult r = run_orogen("run " + q(spec) + " --quiet --out " + q(dir / "out"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json report = inspect(dir / "out" / "run.py", dir / "pictures");
    ASSERT_FALSE(report.is_null());
    EXPECT_EQ(report["exaggeration"], 3.0);
    EXPECT_EQ(report["colour_array"][1], "plate");
    EXPECT_EQ(report["categorical"], 1);
    const auto annotations = report["annotations"].get<std::vector<std::string>>();
    ASSERT_GE(annotations.size(), 4u);  // value, name pairs: at least two plates
    EXPECT_EQ(annotations[1].rfind("plate ", 0) == 0 || annotations[1] == "no plate", true) << annotations[1];
    EXPECT_TRUE(report["times"].empty());  // no series: nothing to play
    const Picture picture = read_picture(dir / "pictures" / "state.png");
    ASSERT_EQ(picture.width, 640);
    EXPECT_GT(foreground_fraction(picture), 0.2);
}

// Issue 52: the README's ParaView line, exactly as written, on the demo's
// pipeline scaled down (257² of its 1025², the same processes and the same
// export:paraview-state line), run without a display: tools/pvbatch chooses
// Xvfb itself. The picture shows the erosion in more than one colour and the
// colour bar spans the data's 2–98 %.
TEST_F(Pvbatch, TheReadmeCommandDrawsTheDemoHeadless) {
    const fs::path source = OROGEN_SOURCE_DIR;
    const std::string readme = slurp(source / "README.md");
    std::smatch m;
    ASSERT_TRUE(std::regex_search(readme, m, std::regex("`(tools/pvbatch ([^` ]+) [^`]*--screenshot ([^` ]+)[^`]*)`")))
        << "README.md has no `tools/pvbatch STATE --screenshot PNG` line";
    const std::string line = m[1], state = m[2], png = m[3];

    // The demo, scaled down: its grid line made 257², its lines before the renderings but its
    // exports, and its export:paraview-state line.
    std::ifstream demo(source / "pipelines" / "default.orogen");
    std::string spec, text, paraview_line;
    bool rendering = false;
    while (std::getline(demo, text)) {
        rendering = rendering || text.find("render:") != std::string::npos;
        if (text.rfind("export:paraview-state(", 0) == 0) paraview_line = text;
        if (rendering || text.rfind("export:", 0) == 0) continue;
        if (text.rfind("grid ", 0) == 0) text = "grid 257 cell=30";
        spec += text + "\n";
    }
    ASSERT_FALSE(paraview_line.empty()) << "pipelines/default.orogen has no export:paraview-state line";
    spec += paraview_line + "\n";
    TempDir dir;
    const auto spec_file = dir.write("demo.orogen", spec);
    const RunResult r = run_orogen("run " + q(spec_file) + " --quiet --no-cache --out " + q(dir / "out"));
    ASSERT_EQ(r.exit_code, 0) << r.err << "\n" << spec;
    ASSERT_TRUE(fs::exists(dir / state)) << state << " is not where the README's line looks for it";

    // The README's line from a folder like the clone's top: tools/ and out/ side by side; no display.
    fs::create_directory_symlink(source / "tools", dir / "tools");
    const std::string cmd = "cd " + q(dir.path()) + " && env -u DISPLAY OROGEN_PARAVIEW_DIR=" + q(OROGEN_PARAVIEW_DIR) +
        " " + line + " >" + q(dir / "pvbatch.log") + " 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << line << "\n" << slurp(dir / "pvbatch.log");
    const Picture picture = read_picture(dir / png);
    EXPECT_EQ(picture.width, 1600);  // the script's default size
    EXPECT_EQ(picture.height, 900);
    EXPECT_GT(foreground_fraction(picture), 0.2);
    EXPECT_GT(foreground_colours(picture), 40u);
    EXPECT_LT(dominant_colour_share(picture), 0.5) << "most of the terrain is one colour";

    // The same state inspected: colour bar against the data, plates on the terrain.
    const nlohmann::json report = inspect(dir / state, dir / "pictures");
    ASSERT_FALSE(report.is_null());
    expect_shows_something(report, read_picture(dir / "pictures" / "state.png"));
    const auto bounds = report["terrain_bounds"].get<std::vector<double>>();
    const auto z = report["plates_z_at_last"].get<std::vector<double>>();
    EXPECT_GT(z[1] - z[0], 0.5 * (bounds[5] - bounds[4]));
}
