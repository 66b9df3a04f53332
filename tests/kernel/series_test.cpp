// Series values end to end: a node that outputs a series, the kernel mapping
// a one-value node over it lazily, nodes that take a series or either, the
// checker's words for a mismatch, and an eroder's time-lapse side value.
#include <gtest/gtest.h>

#include "orogen_test.hpp"

#include <cstring>
#include <sstream>
#include <vector>

using namespace orogen::test;
namespace fs = std::filesystem;

namespace {

const std::string fake_plugins = OROGEN_FAKE_PLUGIN_DIR;

RunResult run_spec(const TempDir& dir, const std::string& body, const std::string& command = "run") {
    dir.write("s.orogen", "orogen 1\ngrid 5\n" + body);
    return run_orogen(command + " s.orogen" + (command == "run" ? " --out out --quiet" : ""),
                      "OROGEN_PLUGIN_PATH=" + fake_plugins, dir.path());
}

}  // namespace

TEST(Series, AOneValueNodeIsMappedOverASeriesEntryByEntryOnDemand) {
    TempDir dir;
    const RunResult r = run_spec(dir,
                                 "f = generate:test-frames(frames=4)\n"
                                 "g = generate:test-add(f, amount=10)\n"
                                 "export:test-series(g, path=\"g.txt\")\n");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    // Entry j of the mapped series is test-add run on entry j; the times are the source's.
    // The exporter pulls one entry at a time: at most the source entry and its
    // mapped result are alive together, never all four.
    EXPECT_EQ(slurp(dir / "out/g.txt"), "0 10\n0.5 11\n1 12\n1.5 13\nmost alive 2\n");
}

TEST(Series, MappingChainsThroughSeveralNodes) {
    TempDir dir;
    const RunResult r = run_spec(dir,
                                 "f = generate:test-frames(frames=3)\n"
                                 "g = generate:test-add(f, amount=10)\n"
                                 "h = generate:test-add(g, amount=100)\n"
                                 "export:test-series(h, path=\"h.txt\")\n");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(slurp(dir / "out/h.txt"), "0 110\n0.5 111\n1 112\nmost alive 2\n");
}

TEST(Series, AnEitherInputTakesOneValueOrASeries) {
    TempDir dir;
    const RunResult r = run_spec(dir,
                                 "f = generate:test-frames(frames=5)\n"
                                 "one = generate:fault(iterations=1)\n"
                                 "a = generate:test-either(f)\n"
                                 "b = generate:test-either(one)\n"
                                 "export:png(a, path=\"a.png\")\nexport:png(b, path=\"b.png\")\n");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const RunResult check = run_spec(dir,
                                     "f = generate:test-frames(frames=5)\nx = generate:test-either(f)\n"
                                     "export:test-series(x, path=\"x.txt\")\n",
                                     "check");
    // test-either is not mapped (it takes the series itself), so its output is one heightmap.
    EXPECT_EQ(check.exit_code, 2);
    EXPECT_NE(check.err.find("s.orogen:5:20: error: export:test-series input 1 ('series') must be a series of "
                             "heightmaps, but 'x' is a heightmap"),
              std::string::npos)
        << check.err;
}

TEST(Series, TheCheckerSaysWhenASeriesIsGivenWhereItCannotGo) {
    TempDir dir;
    const RunResult r = run_spec(dir,
                                 "f = generate:test-frames(frames=2)\n"
                                 "export:raw(f, path=\"f.r32\")\n"
                                 "b = generate:fault(iterations=1)\n"
                                 "export:test-series(b, path=\"b.txt\")\n",
                                 "check");
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("s.orogen:4:12: error: export:raw input 1 ('terrain') must be a heightmap, but 'f' is a "
                         "series of heightmaps (a node that only writes files is not mapped over a series)"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("s.orogen:6:20: error: export:test-series input 1 ('series') must be a series of heightmaps, "
                         "but 'b' is a heightmap"),
              std::string::npos)
        << r.err;
}

TEST(Series, AnErrorInAMappedEntryNamesTheEntryAndTheMappedNode) {
    TempDir dir;
    const RunResult r = run_spec(dir,
                                 "f = generate:test-frames(frames=3)\n"
                                 "g = generate:test-add(f, amount=98)\n"
                                 "h = generate:test-add(g, amount=0)\n"
                                 "export:test-series(h, path=\"h.txt\")\n");
    // Entry 1 of g is 99: h refuses it when the exporter pulls it.
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("node 'export:test-series' (export:test-series) failed: entry 1 of 'h' "
                         "(generate:test-add, line 5): height 99 is not allowed here"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(dir / "out/h.txt"));
}

TEST(Series, AnEroderRecordsATimelapseEveryKStepsAndTheLastOne) {
    TempDir dir;
    dir.write("s.orogen",
              "orogen 1\ngrid 33 cell=10\n"
              "b = generate:fault(iterations=50, displacement=20)\n"
              "t = erode:thermal(b, iterations=10, timelapse_every=4, talus=10)\n"
              "export:test-series(t.timelapse, path=\"t.txt\")\n"
              "export:raw(t, path=\"t.r32\")\nexport:raw(b, path=\"b.r32\")\n");
    const RunResult r = run_orogen("run s.orogen --out out --quiet", "OROGEN_PLUGIN_PATH=" + fake_plugins, dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    // thermal reports every 4 steps (one sweep): snapshots at 0 (the input), 4, 8 and the last, 10.
    const std::string text = slurp(dir / "out/t.txt");
    std::istringstream in(text);
    std::vector<double> times;
    std::vector<float> first;
    double t;
    float h;
    while (in >> t >> h) {
        times.push_back(t);
        first.push_back(h);
    }
    ASSERT_EQ(times, (std::vector<double>{0, 4, 8, 10})) << text;
    // The first snapshot is the input and the last the output (sample 0 of each raw file).
    auto sample0 = [&](const char* f) {
        const std::string bytes = slurp(dir / "out" / f);
        float v;
        std::memcpy(&v, bytes.data(), 4);
        return v;
    };
    EXPECT_EQ(first.front(), sample0("b.r32"));
    EXPECT_EQ(first.back(), sample0("t.r32"));
}

TEST(Series, ATimelapseThatWouldNotFitInMemoryIsRefusedAtCheckTime) {
    TempDir dir;
    dir.write("s.orogen",
              "orogen 1\ngrid 4097\nb = generate:fault(iterations=1)\n"
              "t = erode:thermal(b, iterations=10000000, timelapse_every=1)\nexport:png(t, path=\"t.png\")\n");
    const RunResult r = run_orogen("check s.orogen", "", dir.path());
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("error: erode:thermal: a time-lapse of 10000001 snapshots of 4097×4097 needs"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("; record less often"), std::string::npos) << r.err;
}

TEST(Series, ThePlatesTimelapseShowsTheReliefGrowingAndEndsOnTheOutput) {
    TempDir dir;
    dir.write("s.orogen",
              "orogen 1\nseed 3\ngrid 97 cell=100\n"
              "b = generate:fault(iterations=20, displacement=5)\n"
              "p = tectonics:plates(b, plates=6, steps=240, timelapse_every=80)\n"
              "export:test-series(p.timelapse, path=\"p.txt\", sums=true)\n"
              "export:raw(p, path=\"p.r32\")\nexport:raw(b, path=\"b.r32\")\n");
    const RunResult r = run_orogen("run s.orogen --out out --quiet", "OROGEN_PLUGIN_PATH=" + fake_plugins, dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    auto sum_of = [&](const char* f) {
        const std::string bytes = slurp(dir / "out" / f);
        std::vector<float> v(bytes.size() / 4);
        std::memcpy(v.data(), bytes.data(), bytes.size());
        double s = 0.0;
        for (float x : v) s += x;
        return s;
    };
    std::istringstream in(slurp(dir / "out/p.txt"));
    std::vector<double> times, sums;
    double t, s;
    float h;
    while (in >> t >> h >> s) {
        times.push_back(t);
        sums.push_back(s);
    }
    ASSERT_EQ(times, (std::vector<double>{0, 8, 16, 24}));  // steps 0, 80, 160, 240 of dt 0.1 s
    EXPECT_EQ(sums.front(), sum_of("b.r32"));
    EXPECT_EQ(sums.back(), sum_of("p.r32"));
    // The middle snapshots carry the relief of the boundaries met so far: not the input, not yet the end.
    EXPECT_NE(sums[1], sums[0]);
    EXPECT_NE(sums[2], sums[3]);
}
