// export:paraview-state — the script's choices, and the node run through the CLI.
// (tests/plugins/export/paraview/pvbatch_test.cpp runs the script in ParaView itself.)
#include "paraview_state.hpp"

#include "orogen_test.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <regex>

using namespace orogen;
using namespace orogen::test;
namespace pv = orogen::paraview;

TEST(ParaviewState, PercentilesAreByNearestRankOverFiniteValues) {
    std::vector<float> v(101);
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = float(100 - i);  // 100 .. 0, unsorted for nth_element
    v.push_back(std::numeric_limits<float>::quiet_NaN());
    EXPECT_DOUBLE_EQ(pv::percentile(v, 0.02), 2.0);
    EXPECT_DOUBLE_EQ(pv::percentile(v, 0.5), 50.0);
    EXPECT_DOUBLE_EQ(pv::percentile(v, 0.98), 98.0);
    EXPECT_DOUBLE_EQ(pv::percentile(std::vector<float>{}, 0.5), 0.0);
}

// Erosion and deposition (both signs over 2–98 % of the map): 0, no change, is the landmark.
TEST(ParaviewState, ErodedWithBothSignsIsDivergingAndSymmetricAboutZero) {
    std::vector<float> v(1000);
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = float(i % 10) - 7.0f;  // −7 .. 2
    v[3] = -500.0f;  // one deep gully
    const pv::Colours c = pv::colours_for("eroded", v);
    EXPECT_EQ(c.kind, pv::Colours::diverging);
    EXPECT_EQ(c.array, "eroded");
    EXPECT_DOUBLE_EQ(c.shift, 0.0);
    EXPECT_DOUBLE_EQ(c.low, -c.high);
    EXPECT_DOUBLE_EQ(c.high, 7.0);  // the 2nd percentile's magnitude, not the one outlier
    EXPECT_DOUBLE_EQ(c.data_low, -7.0);
    EXPECT_DOUBLE_EQ(c.data_high, 2.0);
    ASSERT_EQ(c.ramp.size() % 2, 1u);
    const auto& middle = c.ramp[c.ramp.size() / 2];  // white-ish at zero
    EXPECT_GT(middle[0] + middle[1] + middle[2], 2.7);
    EXPECT_EQ(c.title, "eroded (m; − cut, + deposited)");
}

// The default pipeline's case (issue 52): 3 Myr of uplift and erosion took 2.4 to 3.4 km off every
// cell. Drawn about 0 it is one flat brown; relative to its median, the valleys cut deeper stand out.
TEST(ParaviewState, OneSignedErodedIsShownRelativeToItsMedian) {
    std::vector<float> v(1001);
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = -3400.0f + float(i);  // −3400 .. −2400, median −2900
    const pv::Colours c = pv::colours_for("eroded", v);
    EXPECT_EQ(c.kind, pv::Colours::diverging);
    EXPECT_EQ(c.array, "eroded_vs_median");
    EXPECT_DOUBLE_EQ(c.shift, -2900.0);
    EXPECT_DOUBLE_EQ(c.data_low, -480.0);  // the 2nd and 98th percentiles, less the median
    EXPECT_DOUBLE_EQ(c.data_high, 480.0);
    EXPECT_DOUBLE_EQ(c.low, -480.0);
    EXPECT_DOUBLE_EQ(c.high, 480.0);
    EXPECT_EQ(c.title, "eroded − median (m); median −2900 m");
}

TEST(ParaviewState, PlateIdsAreCategoriesWithDistinctColoursAndNames) {
    std::vector<float> v = {3, 3, 1, 7, 1, 7, 7, -1};
    const pv::Colours c = pv::colours_for("plate", v);
    EXPECT_EQ(c.kind, pv::Colours::categorical);
    ASSERT_EQ(c.categories.size(), 4u);
    EXPECT_EQ(c.categories[0].value, -1);
    EXPECT_EQ(c.categories[0].name, "no plate");
    EXPECT_EQ(c.categories[3].name, "plate 7");
    for (std::size_t i = 0; i < c.categories.size(); ++i)
        for (std::size_t j = i + 1; j < c.categories.size(); ++j) EXPECT_NE(c.categories[i].rgb, c.categories[j].rgb);
    const pv::Colours b = pv::colours_for("boundary", std::vector<float>{0, 1, 2, 3});
    ASSERT_EQ(b.categories.size(), 4u);
    EXPECT_EQ(b.categories[1].name, "convergent");
    EXPECT_EQ(b.categories[3].name, "transform");
}

TEST(ParaviewState, HeightAndOtherLayersAreSequentialOverTheirRange) {
    const pv::Colours h = pv::colours_for("height", std::vector<float>{-20, 0, 100, 880});
    EXPECT_EQ(h.kind, pv::Colours::sequential);  // sea floor and mountains: one ramp, not diverging
    EXPECT_DOUBLE_EQ(h.low, -20.0);
    EXPECT_DOUBLE_EQ(h.high, 880.0);
    const pv::Colours w = pv::colours_for("water", std::vector<float>(100, 0.5f));
    EXPECT_EQ(w.kind, pv::Colours::sequential);
    EXPECT_GT(w.high, w.low);  // a constant layer still has a usable range
    EXPECT_EQ(pv::colours_for("flow", std::vector<float>{0, 1}).title, "flow (m/s)");
    EXPECT_EQ(pv::colours_for("uplift", std::vector<float>{-3, 5}).kind, pv::Colours::diverging);
    EXPECT_EQ(pv::colours_for("chi", std::vector<float>{0, 5}).title, "chi");  // no unit invented
    // One sign: sequential over the 2–98 % range, not diverging about a zero the data never reach.
    std::vector<float> uplifted(1001);
    for (std::size_t i = 0; i < uplifted.size(); ++i) uplifted[i] = 3000.0f + float(i);
    const pv::Colours u = pv::colours_for("uplifted", uplifted);
    EXPECT_EQ(u.kind, pv::Colours::sequential);
    EXPECT_DOUBLE_EQ(u.low, 3020.0);
    EXPECT_DOUBLE_EQ(u.high, 3980.0);
}

TEST(ParaviewState, DrainageIsOnALogScale) {
    std::vector<float> area(1000, 900.0f);  // most cells: one cell's area
    for (std::size_t i = 0; i < 200; ++i) area[i] = 900.0f * float(1 << (i % 20));
    const pv::Colours c = pv::colours_for("drainage", area);
    EXPECT_EQ(c.kind, pv::Colours::sequential);
    EXPECT_TRUE(c.log);
    EXPECT_GT(c.low, 0.0);
    EXPECT_GT(c.high, 100 * c.low);
    EXPECT_EQ(c.title, "drainage (m²)");
}

TEST(ParaviewState, PlateOutlinesAreClippedToTheMapAndDensified) {
    // A square half off the map's east side: clipped at x = 100.
    const auto clipped = pv::clip_polygon({{50, 10}, {150, 10}, {150, 90}, {50, 90}}, 0, 0, 100, 100);
    ASSERT_EQ(clipped.size(), 4u);
    for (const auto& p : clipped) EXPECT_LE(p[0], 100.0);
    EXPECT_TRUE(pv::clip_polygon({{150, 10}, {250, 10}, {200, 90}}, 0, 0, 100, 100).empty());  // off the map
    const auto dense = pv::densify(clipped, 10.0, true);  // perimeter 50 + 80 + 50 + 80 = 260: 26 points
    EXPECT_EQ(dense.size(), 26u);
    for (std::size_t i = 0; i < dense.size(); ++i) {
        const auto& a = dense[i];
        const auto& b = dense[(i + 1) % dense.size()];
        EXPECT_LE(std::hypot(b[0] - a[0], b[1] - a[1]), 10.0 + 1e-9);
    }
    pv::XY a = {-50, 50}, b = {50, 50};
    ASSERT_TRUE(pv::clip_segment(a, b, 0, 0, 100, 100));
    EXPECT_DOUBLE_EQ(a[0], 0.0);
    EXPECT_DOUBLE_EQ(b[0], 50.0);
    pv::XY c = {-50, -1}, d = {50, -1};
    EXPECT_FALSE(pv::clip_segment(c, d, 0, 0, 100, 100));
    EXPECT_EQ(pv::densify({{0, 0}, {0, 25}}, 10.0, false).size(), 4u);  // 0, 8.3, 16.7, 25
}

TEST(ParaviewState, AutoExaggerationMakesTheReliefAFifthOfTheSide) {
    EXPECT_DOUBLE_EQ(pv::auto_exaggeration(300.0, 15000.0), 10.0);  // 3000 / 300
    EXPECT_DOUBLE_EQ(pv::auto_exaggeration(2400.0, 15000.0), 1.3);  // 1.25 → two digits
    EXPECT_DOUBLE_EQ(pv::auto_exaggeration(9000.0, 15000.0), 1.0);  // never flattened
    EXPECT_DOUBLE_EQ(pv::auto_exaggeration(1.0, 15000.0), 20.0);  // at most 20
    EXPECT_DOUBLE_EQ(pv::auto_exaggeration(0.0, 15000.0), 1.0);  // flat
}

TEST(ParaviewState, PythonStringsAreEscaped) {
    EXPECT_EQ(pv::python_string("a\"b\\c"), R"("a\"b\\c")");
    EXPECT_EQ(pv::python_string("x\ny"), R"("x\x0ay")");
    EXPECT_EQ(pv::python_string("höhe"), "\"höhe\"");
}

TEST(ParaviewState, ScriptNamesItsFilesRelativelyAndIsDeterministic) {
    pv::StateScript s;
    s.script_name = "run.py";
    s.terrain = "run.vti";
    s.plates = "run-plates.pvd";
    s.collisions = "run-collisions.pvd";
    s.layer = "eroded";
    s.colours = pv::colours_for("eroded", std::vector<float>{-1, 1});
    ASSERT_EQ(s.colours.array, "eroded");
    s.plates_colours = pv::plate_colours({2, 1});
    s.exaggeration = 2.5;
    s.height_max = 100;
    s.size_x = s.size_y = 1000;
    const std::string text = pv::state_script(s);
    EXPECT_EQ(text, pv::state_script(s));
    EXPECT_NE(text.find("\"terrain\": \"run.vti\""), std::string::npos);
    EXPECT_NE(text.find("\"particles\": None"), std::string::npos);
    EXPECT_NE(text.find("\"exaggeration\": 2.5,"), std::string::npos);
    EXPECT_NE(text.find("os.path.join(HERE, name)"), std::string::npos);  // found beside the script
    EXPECT_NE(text.find("\"array\": \"eroded\","), std::string::npos);
    EXPECT_NE(text.find("\"data_range\": [-1.0, 1.0],"), std::string::npos);
    EXPECT_EQ(text.find('/' + std::string("tmp")), std::string::npos);  // no absolute path of this machine
}

// ------------------------------------------------------------------- the node

namespace {

const char* kSpec =
    "orogen 1\nseed 1\ngrid 17 cell=10\n"
    "hill = generate:shape(kind=pyramid, height=40)\n";

}  // namespace

TEST(ParaviewStateNode, WritesTheScriptAndItsZUpTerrainBesideIt) {
    TempDir dir;
    const auto spec = dir.write("s.orogen", std::string(kSpec) + "export:paraview-state(hill, path=\"pv/run.py\")\n");
    const RunResult r = run_orogen("run " + q(spec) + " --quiet --out " + q(dir / "out"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string script = slurp(dir / "out" / "pv" / "run.py");
    EXPECT_NE(script.find("\"terrain\": \"run.vti\""), std::string::npos);
    EXPECT_NE(script.find("\"plates\": None"), std::string::npos);
    // Relief 40 m on a 160 m side: exaggerated to 0.2 · 160 / 40 = 0.8 → at least 1.
    EXPECT_NE(script.find("\"exaggeration\": 1.0,"), std::string::npos) << script.substr(0, 2000);
    const std::string vti = slurp(dir / "out" / "pv" / "run.vti");
    EXPECT_NE(vti.find("WholeExtent=\"0 16 0 16 0 0\""), std::string::npos);  // the XY plane
    const std::string manifest = slurp(dir / "out" / "manifest.json");
    EXPECT_NE(manifest.find("pv/run.py"), std::string::npos);
    EXPECT_NE(manifest.find("pv/run.vti"), std::string::npos);
}

TEST(ParaviewStateNode, AnUnknownLayerIsACheckErrorNamingTheLayersThereAre) {
    TempDir dir;
    const auto spec =
        dir.write("s.orogen", std::string(kSpec) + "export:paraview-state(hill, path=\"run.py\", layer=\"eroded\")\n");
    const RunResult r = run_orogen("check " + q(spec));
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("s.orogen:5:"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("no layer 'eroded'"), std::string::npos) << r.err;
}

TEST(ParaviewStateNode, AnotherHeightmapAsSecondInputIsACheckError) {
    TempDir dir;
    const auto spec =
        dir.write("s.orogen", std::string(kSpec) + "export:paraview-state(hill, hill, path=\"run.py\")\n");
    const RunResult r = run_orogen("check " + q(spec));
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("must be a plate history (e.g. plates.plates) or particle frames"), std::string::npos)
        << r.err;
}

TEST(ParaviewStateNode, APathOutsideTheOutputFolderIsRefused) {
    TempDir dir;
    const auto spec = dir.write("s.orogen", std::string(kSpec) + "export:paraview-state(hill, path=\"../run.py\")\n");
    const RunResult r = run_orogen("run " + q(spec) + " --quiet --out " + q(dir / "out"));
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_FALSE(fs::exists(dir / "run.py"));
    EXPECT_FALSE(fs::exists(dir / "run.vti"));
}

// export:vtk's `up` from a spec: z (the default) lays the image in the XY plane, y in the XZ plane.
TEST(ParaviewStateNode, ExportVtkTakesUpZOrYFromTheSpec) {
    TempDir dir;
    const auto spec = dir.write("s.orogen",
                                std::string(kSpec) +
                                    "export:vtk(hill, path=\"z.vti\")\n"
                                    "export:vtk(hill, path=\"y.vti\", up=y)\n"
                                    "export:vtk-particles(hill, path=\"p.pvd\", up=x)\n");
    RunResult r = run_orogen("check " + q(spec));
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("s.orogen:7:"), std::string::npos) << r.err;  // the bad `up` (and the type) on line 7
    dir.write("s.orogen",
              std::string(kSpec) +
                  "export:vtk(hill, path=\"z.vti\")\n"
                  "export:vtk(hill, path=\"y.vti\", up=y)\n");
    r = run_orogen("run " + q(spec) + " --quiet --out " + q(dir / "out"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(slurp(dir / "out" / "z.vti").find("WholeExtent=\"0 16 0 16 0 0\""), std::string::npos);
    EXPECT_NE(slurp(dir / "out" / "y.vti").find("WholeExtent=\"0 16 0 0 0 16\""), std::string::npos);
}
