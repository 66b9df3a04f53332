// End to end through the real binary: erode:stream-power and erode:diffusion's
// check-time errors, their layers, and the realism check on the output of
// pipelines/orogeny.orogen against published statistics of real ranges
// (docs/landscape.md cites the bands).
#include "orogen_test.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <sstream>
#include <unistd.h>

namespace {

using namespace orogen::test;

/// `spec` run on 1 thread and on 2 (`flags` after `run SPEC`), each into its own folder under `dir`:
/// the runs and their folders, for the determinism tests below to compare.
struct OneAndTwoThreads {
    RunResult run[2];
    std::string out[2];
};
OneAndTwoThreads run_on_one_and_two_threads(const TempDir& dir, const std::filesystem::path& spec,
                                            const std::string& flags = "") {
    OneAndTwoThreads r;
    for (int t = 0; t < 2; ++t) {
        r.out[t] = (dir / ("out" + std::to_string(t + 1))).string();
        r.run[t] =
            run_orogen("run " + q(spec) + flags + " --threads " + std::to_string(t + 1) + " --out " + q(r.out[t]));
    }
    return r;
}

TEST(LandscapeCli, OutOfRangeParametersAreCheckTimeErrors) {
    TempDir dir;
    const auto spec =
        dir.write("bad.orogen",
                  "orogen 1\n"
                  "grid 65 cell=30\n"
                  "base = generate:shape(kind=pyramid, height=300)\n"
                  "a = erode:stream-power(base, m=5, n=0.1, erodibility=1, uplift=100)\n"
                  "b = erode:stream-power(base, diffusivity=100, dt=0, years=-1)\n"
                  "c = erode:stream-power(base, uplift_layer=\"uplift\", open=\"nxw\", base_level=\"sea\")\n"
                  "d = erode:diffusion(base, diffusivity=0)\n"
                  "e = erode:diffusion(base, years=10, dt=100, fixed=\"top\")\n"
                  "f = erode:stream-power(base, routing=mfd, depressions=route)\n"
                  "g = erode:stream-power(base, mfd_exponent=2)\n");
    const RunResult r = run_orogen("check " + q(spec));
    EXPECT_EQ(r.exit_code, 2);
    for (const char* want : {
             "bad.orogen:4:32: error: 'm' of erode:stream-power is 5, out of range [0.1, 1.5]",
             "'n' of erode:stream-power is 0.1, out of range [0.5, 4]",
             "'erodibility' of erode:stream-power is 1, out of range (0, 0.01] m^(1-2m)/yr",
             "'uplift' of erode:stream-power is 100, out of range [0, 20] mm/yr",
             "'diffusivity' of erode:stream-power is 100, out of range [0, 10] m²/yr",
             "'dt' of erode:stream-power is 0, out of range (0, 100000000] yr",
             "'years' of erode:stream-power is -1, out of range (0, 1000000000] yr",
             "bad.orogen:6:43: error: erode:stream-power: no layer 'uplift' on the input (the input has no layers); "
             "tectonics:plates writes 'uplift'",
             "erode:stream-power: 'nxw' is not a set of sides",
             "erode:stream-power: 'sea' is not a height",
             "'diffusivity' of erode:diffusion is 0, out of range (0, 10] m²/yr",
             "bad.orogen:8:40: error: erode:diffusion: the time step is longer than the run (years); give dt <= years",
             "erode:diffusion: 'top' is not a set of sides",
             "erode:stream-power: multiple flow directions need filled lakes",
             "erode:stream-power: mfd_exponent weights multiple flow directions; give routing=mfd as well",
         })
        EXPECT_NE(r.err.find(want), std::string::npos) << "missing: " << want << "\n" << r.err;
}

TEST(LandscapeCli, AGridTooLargeForMemorySaysHowMuchItNeeds) {
    // A grid the kernel accepts (its heightmap, 4 bytes a vertex, fits in a quarter of memory) but
    // the model, about 70 bytes a cell, does not fit in half: about memory / 50 cells.
    const double memory = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE));
    const int side = int(std::sqrt(memory / 50.0));
    TempDir dir;
    const auto spec = dir.write("huge.orogen",
                                "orogen 1\n"
                                "grid " +
                                    std::to_string(side) +
                                    " cell=30\n"
                                    "base = generate:shape(kind=flat)\n"
                                    "a = erode:stream-power(base)\n");
    const RunResult r = run_orogen("check " + q(spec));
    EXPECT_EQ(r.exit_code, 2);
    const std::string want = "huge.orogen:4:5: error: erode:stream-power: a " + std::to_string(side) + " x " +
        std::to_string(side) + " grid needs ";
    EXPECT_NE(r.err.find(want), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("iB for the landscape model, more than half of this machine's "), std::string::npos) << r.err;
}

TEST(LandscapeCli, RunsWritesItsLayersAndGivesTheSameBytesOnOneAndTwoThreads) {
    TempDir dir;
    const auto spec = dir.write("cone.orogen",
                                "orogen 1\n"
                                "grid 97 cell=30\n"
                                "base = generate:shape(kind=cone, height=400)\n"
                                "a = erode:stream-power(base, years=2e5, dt=1e4, uplift=2, chi=true)\n"
                                "b = erode:diffusion(a, years=1e4, dt=1e3, critical_angle=40)\n"
                                "export:raw(b, path=\"b.r32\")\n"
                                "export:png(b, path=\"drainage.png\", layer=\"drainage\", bits=16)\n"
                                "export:png(b, path=\"direction.png\", layer=\"flow_direction\")\n"
                                "export:png(b, path=\"chi.png\", layer=\"chi\", bits=16)\n");
    const OneAndTwoThreads runs = run_on_one_and_two_threads(dir, spec, " --quiet");
    std::string bytes[2];
    for (int t = 0; t < 2; ++t) {
        const std::string& out = runs.out[t];
        ASSERT_EQ(runs.run[t].exit_code, 0) << runs.run[t].err;
        bytes[t] = slurp(out + "/b.r32");
        bytes[t] += slurp(out + "/drainage.png") + slurp(out + "/direction.png") + slurp(out + "/chi.png");
        // The heights changed: rivers cut the cone.
        ASSERT_EQ(slurp(out + "/b.r32").size(), std::size_t(97 * 97 * 4));
    }
    EXPECT_FALSE(bytes[0].empty());
    EXPECT_EQ(bytes[0], bytes[1]);
}

TEST(LandscapeCli, DepositionAndUpliftHistoryAreCheckedBeforeTheRun) {
    TempDir dir;
    const auto spec = dir.write("bad.orogen",
                                "orogen 1\n"
                                "grid 65 cell=30\n"
                                "base = generate:shape(kind=pyramid, height=300)\n"
                                "a = erode:stream-power(base, deposition=20)\n"
                                "b = erode:stream-power(base, deposition=-0.5)\n"
                                "c = erode:stream-power(base, base)\n"
                                "p = tectonics:plates(base, plates=3, steps=20)\n"
                                "d = erode:stream-power(p, p.timelapse)\n"
                                "q = tectonics:plates(base, plates=3, steps=20, timelapse_every=5)\n"
                                "e = erode:stream-power(q, q.timelapse, uplift_layer=\"uplift\")\n"
                                "f = erode:stream-power(base, uplift_history_years=1e6)\n");
    const RunResult r = run_orogen("check " + q(spec));
    EXPECT_EQ(r.exit_code, 2);
    for (const char* want : {
             "bad.orogen:4:41: error: 'deposition' of erode:stream-power is 20, out of range [0, 10]",
             "bad.orogen:5:41: error: 'deposition' of erode:stream-power is -0.5, out of range [0, 10]",
             "bad.orogen:6:30: error: erode:stream-power input 2 ('uplift_history') must be a series of heightmaps, "
             "but 'base' is a heightmap",
             "bad.orogen:8:5: error: erode:stream-power: input 2 (uplift_history) records no frames: give its node "
             "timelapse_every=K (e.g. tectonics:plates(..., timelapse_every=50)) so that it hands on its heights over "
             "time",
             "bad.orogen:10:53: error: erode:stream-power: give uplift_layer or an uplift_history input, not both",
             "bad.orogen:11:51: error: erode:stream-power: uplift_history_years spreads an uplift history; give one as "
             "input 2, e.g. plates.timelapse",
         })
        EXPECT_NE(r.err.find(want), std::string::npos) << "missing: " << want << "\n" << r.err;
}

TEST(LandscapeCli, RockAndGlacierParametersAreCheckedBeforeTheRun) {
    TempDir dir;
    const auto spec =
        dir.write("rock.orogen",
                  "orogen 1\n"
                  "grid 65 cell=30\n"
                  "base = generate:shape(kind=pyramid, height=300)\n"
                  "a = erode:stream-power(base, bed_dip=20)\n"
                  "b = erode:stream-power(base, bed_thickness=50, bed_angle_spread=10)\n"
                  "c = erode:stream-power(base, landslide_angle=30, bed_thickness=50, bed_angle_spread=28)\n"
                  "d = erode:stream-power(base, ela=2000)\n"
                  "e = erode:stream-power(base, glaciers=true, deposition=1)\n"
                  "f = erode:stream-power(base, landslide_angle=85)\n"
                  "g = erode:stream-power(base, bed_fold_amplitude=200)\n"
                  "h = erode:stream-power(base, bed_thickness=50, bed_fold_amplitude=200, bed_fold_wavelength=50)\n"
                  "i = erode:stream-power(base, bed_thickness=50, bed_fault_spacing=2000)\n"
                  "j = erode:stream-power(base, bed_thickness=50, bed_fault_spacing=50, bed_fault_throw=100)\n"
                  "k = erode:stream-power(base, bed_thickness=50, bed_thickness_spread=1)\n"
                  "l = erode:stream-power(base, landslide_block_spread=0.5)\n"
                  "m = erode:stream-power(base, bed_thickness=50, bed_facies_length=40)\n"
                  "n = erode:stream-power(base, bed_thickness=50, bed_facies_share=0.3)\n"
                  "o = erode:stream-power(base, bank_floor_slope=2)\n"
                  "p = erode:stream-power(base, bank_erosion=11)\n"
                  "q = erode:stream-power(base, bank_wide_area=1e5)\n"
                  "r = erode:stream-power(base, bank_erosion=4, bank_wider_area=1e6)\n"
                  "s = erode:stream-power(base, bank_erosion=4, bank_wide_area=1e6, bank_wider_area=1e5)\n"
                  "t = erode:stream-power(base, bank_erosion=4, bank_wide_area=1e5, bank_wider_area=1e6, "
                  "bank_widest_floor=10)\n"
                  "u = erode:stream-power(base, bank_erosion=4, bank_wide_area=1e5, bank_widest_floor=11)\n"
                  "v = erode:stream-power(base, floodplain_exponent=0.3)\n");
    const RunResult r = run_orogen("check " + q(spec));
    EXPECT_EQ(r.exit_code, 2);
    for (const char* want : {
             "rock.orogen:4:38: error: erode:stream-power: bed_dip describes the rock's beds; give bed_thickness (m) "
             "as well",
             "rock.orogen:5:65: error: erode:stream-power: bed_angle_spread spreads the landslide angle; give "
             "landslide_angle as well",
             "rock.orogen:6:85: error: erode:stream-power: the beds' landslide angles run landslide_angle ± "
             "bed_angle_spread, which must stay within 5-80°; give a smaller spread",
             "rock.orogen:7:34: error: erode:stream-power: ela describes glaciers; give glaciers=true as well",
             "rock.orogen:8:39: error: erode:stream-power: glaciers erode detachment-limited for now; give "
             "deposition=0 or glaciers=false",
             "rock.orogen:9:46: error: 'landslide_angle' of erode:stream-power is 85, out of range [0, 80] °",
             "rock.orogen:10:49: error: erode:stream-power: bed_fold_amplitude describes the rock's beds; give "
             "bed_thickness (m) as well",
             "rock.orogen:11:92: error: 'bed_fold_wavelength' of erode:stream-power is 50, out of range [100, "
             "1000000] m",
             "rock.orogen:12:66: error: erode:stream-power: faults need both a spacing and a throw; give "
             "bed_fault_spacing (m) and bed_fault_throw (m)",
             "rock.orogen:13:66: error: erode:stream-power: faults closer than 100 m apart would shatter the rock "
             "cell by cell; give bed_fault_spacing >= 100 (m), or 0 for no faults",
             "rock.orogen:14:69: error: 'bed_thickness_spread' of erode:stream-power is 1, out of range [0, 0.95]",
             "rock.orogen:15:53: error: erode:stream-power: landslide_block_spread roughens the landslide slopes; "
             "give landslide_angle as well",
             "rock.orogen:16:66: error: erode:stream-power: facies changing within less than 100 m would speckle the "
             "beds cell by cell; give bed_facies_length >= 100 (m), or 0 for beds of one strength each",
             "rock.orogen:17:65: error: erode:stream-power: bed_facies_share sets how much the facies change a bed's "
             "strength; give bed_facies_length (m) as well",
             "rock.orogen:18:47: error: erode:stream-power: bank_floor_slope shapes the rivers' bank erosion; give "
             "bank_erosion > 0 as well",
             "rock.orogen:19:43: error: 'bank_erosion' of erode:stream-power is 11, out of range [0, 10]",
             "rock.orogen:20:45: error: erode:stream-power: bank_wide_area shapes the rivers' bank erosion; give "
             "bank_erosion > 0 as well",
             "rock.orogen:21:62: error: erode:stream-power: bank_wider_area widens the floors bank_wide_area "
             "makes; give bank_wide_area as well",
             "rock.orogen:22:82: error: erode:stream-power: bank_wider_area is smaller than bank_wide_area",
             "rock.orogen:23:105: error: erode:stream-power: bank_widest_floor is 10: floors are an odd number of "
             "cells wide",
             "rock.orogen:24:84: error: erode:stream-power: bank_widest_floor widens the floors past seven cells "
             "each time the drainage area grows by bank_wider_area / bank_wide_area; give bank_wider_area > "
             "bank_wide_area > 0",
             "rock.orogen:25:50: error: erode:stream-power: floodplain_exponent shapes the rivers' floodplains; "
             "give floodplain_area (m²) as well",
         })
        EXPECT_NE(r.err.find(want), std::string::npos) << "missing: " << want << "\n" << r.err;
}

TEST(LandscapeCli, AProcessTurnedOffOnPurposeKeepsItsShapingParametersUnused) {
    // `make demo`'s spec shapes its floodplains, banks, beds, faults and landslides; turning one off from the
    // command line (its switch given as 0) must check and run, its shaping parameters then unused, where
    // the same parameters without their switch at all are errors (the test above).
    // The terrain part of the spec only, up to its first output: the render and video plugins it ends with
    // are not built in every configuration (the ThreadSanitizer build leaves them out).
    TempDir dir;
    const std::string demo = slurp(std::string(OROGEN_SOURCE_DIR) + "/pipelines/default.orogen");
    const std::size_t outputs = demo.find("\nexport:");
    ASSERT_NE(outputs, std::string::npos);
    ASSERT_NE(demo.find("    floodplains("), std::string::npos);  // still the spec that shapes them all
    const std::string spec =
        q(dir.write("demo.orogen", demo.substr(0, outputs + 1) + "export:raw(soil, path=\"t.r32\")\n"));
    // Its range is a loop of processes (docs/processes.md): each switch is a process's parameter.
    for (const char* off :
         {"range.floodplains.area=0", "range.banks.erosion=0", "range.rock.thickness=0", "range.rock.fault_throw=0",
          "range.rock.fault_spacing=0", "range.rock.angle=0", "range.rock.facies_length=0"}) {
        const RunResult r = run_orogen("check " + spec + " --set " + off);
        EXPECT_EQ(r.exit_code, 0) << off << "\n" << r.err;
    }
    const auto switched = dir.write("off.orogen",
                                    "orogen 1\n"
                                    "grid 65 cell=30\n"
                                    "base = generate:shape(kind=pyramid, height=300)\n"
                                    "a = erode:stream-power(base, glaciers=false, ela=2000)\n"
                                    "b = erode:stream-power(base, rain=uniform, wind_from=200)\n"
                                    "c = erode:stream-power(base, routing=d8, mfd_exponent=2)\n"
                                    "d = erode:stream-power(base, bed_thickness=50, bed_facies_length=0, "
                                    "bed_facies_share=0.3)\n");
    const RunResult checked = run_orogen("check " + q(switched));
    EXPECT_EQ(checked.exit_code, 0) << checked.err;
    // ... and the run is the one without the process: floodplains off on a small spec that shapes them.
    const auto small = dir.write("fp.orogen",
                                 "orogen 1\n"
                                 "grid 129 cell=30\n"
                                 "base = generate:diamond-square(roughness=0.5, amplitude=300)\n"
                                 "a = erode:stream-power(base, years=1e5, dt=2e4, floodplain_area=1e5, "
                                 "floodplain_width=60, floodplain_max_slope=10)\n"
                                 "b = erode:stream-power(base, years=1e5, dt=2e4)\n"
                                 "export:raw(a, path=\"a.r32\")\n"
                                 "export:raw(b, path=\"b.r32\")\n");
    const RunResult with = run_orogen("run " + q(small) + " --out " + q(dir / "with"));
    ASSERT_EQ(with.exit_code, 0) << with.err;
    const RunResult without = run_orogen("run " + q(small) + " --set a.floodplain_area=0 --out " + q(dir / "without"));
    ASSERT_EQ(without.exit_code, 0) << without.err;
    EXPECT_NE(slurp(dir / "with" / "a.r32"), slurp(dir / "with" / "b.r32"));  // floodplains change it
    EXPECT_EQ(slurp(dir / "without" / "a.r32"), slurp(dir / "without" / "b.r32"));  // and off, nothing
}

TEST(LandscapeCli, RainAndUpliftTaperParametersAreCheckedBeforeTheRun) {
    TempDir dir;
    const auto spec = dir.write("rain.orogen",
                                "orogen 1\n"
                                "grid 65 cell=30\n"
                                "base = generate:shape(kind=pyramid, height=300)\n"
                                "a = erode:stream-power(base, wind_from=200)\n"
                                "b = erode:stream-power(base, rain=orographic, rain_background=0)\n"
                                "c = erode:stream-power(base, rain=monsoon)\n"
                                "d = erode:stream-power(base, open=none, uplift_edge_taper=500)\n");
    const RunResult r = run_orogen("check " + q(spec));
    EXPECT_EQ(r.exit_code, 2);
    for (const char* want : {
             "rain.orogen:4:40: error: erode:stream-power: wind_from describes orographic rain; give "
             "rain=\"orographic\" as well",
             "rain.orogen:5:63: error: 'rain_background' of erode:stream-power is 0, out of range (0, 20] m/yr",
             "rain.orogen:6:35: error: 'rain' of erode:stream-power is 'monsoon', which is not one of uniform, "
             "orographic",
             "rain.orogen:7:59: error: erode:stream-power: uplift_edge_taper tapers the uplift towards the open "
             "sides, and open=none opens none; open some sides or give uplift_edge_taper=0",
         })
        EXPECT_NE(r.err.find(want), std::string::npos) << "missing: " << want << "\n" << r.err;
    // A choice that is not one of the choices stops there: no internal message about the missing value.
    EXPECT_EQ(r.err.find("map::at"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("4 errors"), std::string::npos) << r.err;
}

TEST(LandscapeCli, OrographicRainAddsItsLayerAndGivesTheSameBytesOnOneAndTwoThreads) {
    TempDir dir;
    const auto spec = dir.write("wet.orogen",
                                "orogen 1\n"
                                "seed 5\n"
                                "grid 129 cell=60\n"
                                "base = generate:diamond-square(roughness=0.5, amplitude=600)\n"
                                "a = erode:stream-power(base, years=2e5, dt=2e4, rain=orographic, wind_from=300, "
                                "rain_background=0.7)\n"
                                "export:raw(a, path=\"a.r32\")\n"
                                "export:png(a, path=\"rain.png\", layer=\"rain\", bits=16)\n");
    const OneAndTwoThreads runs = run_on_one_and_two_threads(dir, spec, " --no-cache");
    std::string bytes[2];
    for (int t = 0; t < 2; ++t) {
        ASSERT_EQ(runs.run[t].exit_code, 0) << runs.run[t].err;
        ASSERT_TRUE(std::filesystem::exists(std::filesystem::path(runs.out[t]) / "rain.png"));
        bytes[t] = slurp(runs.out[t] + "/a.r32");
    }
    EXPECT_FALSE(bytes[0].empty());
    EXPECT_EQ(bytes[0], bytes[1]);
}

TEST(LandscapeCli, UpliftFromThePlatesHistoryWithDepositionGivesTheSameBytesOnOneAndTwoThreads) {
    TempDir dir;
    const auto spec = dir.write("h.orogen",
                                "orogen 1\n"
                                "seed 3\n"
                                "grid 129 cell=60\n"
                                "crust = generate:diamond-square(roughness=0.6, amplitude=40)\n"
                                "p = tectonics:plates(crust, plates=6, steps=200, timelapse_every=25)\n"
                                "a = erode:stream-power(p, p.timelapse, years=4e5, dt=2e4, uplift=0.2, "
                                "uplift_history_years=2e5, uplift_smoothing=500, deposition=1)\n"
                                "export:raw(a, path=\"a.r32\")\n"
                                "export:raw(p, path=\"p.r32\")\n");
    const OneAndTwoThreads runs = run_on_one_and_two_threads(dir, spec);
    std::string bytes[2];
    for (int t = 0; t < 2; ++t) {
        const RunResult& r = runs.run[t];
        const std::string& out = runs.out[t];
        ASSERT_EQ(r.exit_code, 0) << r.err;
        EXPECT_NE(r.err.find("km³ of sediment left by the outlets"), std::string::npos) << r.err;
        bytes[t] = slurp(out + "/a.r32");
        ASSERT_EQ(bytes[t].size(), std::size_t(129 * 129 * 4));
        EXPECT_NE(bytes[t], slurp(out + "/p.r32"));
    }
    EXPECT_EQ(bytes[0], bytes[1]);
}

#ifdef OROGEN_FAKE_PLUGIN_DIR
TEST(LandscapeCli, TimelapseRecordsEveryKStepsOnAClockOfYears) {
    // export:test-series (tests/kernel/fake_plugins) writes "time sample0" per entry.
    TempDir dir;
    dir.write("s.orogen",
              "orogen 1\ngrid 33 cell=30\n"
              "b = generate:shape(kind=cone, height=300)\n"
              "t = erode:stream-power(b, years=1e5, dt=1e4, uplift=2, timelapse_every=4)\n"
              "d = erode:diffusion(t, years=3e4, dt=1e4, timelapse_every=2)\n"
              "export:test-series(t.timelapse, path=\"t.txt\")\n"
              "export:test-series(d.timelapse, path=\"d.txt\")\n"
              "export:raw(t, path=\"t.r32\")\n");
    const RunResult r = run_orogen("run s.orogen --out out --quiet",
                                   std::string("OROGEN_PLUGIN_PATH=") + OROGEN_FAKE_PLUGIN_DIR, dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    auto read = [&](const char* name) {
        std::istringstream in(slurp(dir / "out" / name));
        std::vector<std::pair<double, float>> v;
        double t;
        float h;
        while (in >> t >> h) v.emplace_back(t, h);
        return v;
    };
    const double year = 31557600.0;
    const auto t = read("t.txt");
    ASSERT_EQ(t.size(), 4u);  // the input, steps 4 and 8, the last (10)
    const double want[] = {0.0, 4e4, 8e4, 1e5};
    for (int i = 0; i < 4; ++i)  // the writer prints 6 significant digits
        EXPECT_NEAR(t[std::size_t(i)].first, want[i] * year, 1e-5 * want[i] * year + 1.0) << i;
    const std::string bytes = slurp(dir / "out/t.r32");
    float last;
    std::memcpy(&last, bytes.data(), 4);
    EXPECT_EQ(t.back().second, last);  // the last entry is the output
    EXPECT_EQ(read("d.txt").size(), 3u);  // the input, step 2, the last (3)
}
#endif

}  // namespace
