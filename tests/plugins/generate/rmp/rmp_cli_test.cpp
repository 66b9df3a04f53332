// generate:rmp, generate:range and generate:shape through the real orogen binary.
#include "orogen_test.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <vector>

using namespace orogen::test;

namespace {

std::vector<float> read_r32(const fs::path& p) {
    const std::string bytes = slurp(p);
    std::vector<float> v(bytes.size() / 4);
    std::memcpy(v.data(), bytes.data(), v.size() * 4);
    return v;
}

const char* kHeader = "orogen 1\nseed 11\ngrid 65 cell=10\n";

}  // namespace

TEST(RmpCli, AllMethodsRunAndAreTheSameBytesOnOneAndTwoThreads) {
    TempDir dir;
    const auto spec =
        dir.write("m.orogen",
                  std::string(kHeader) +
                      "v = generate:rmp(cones=40, iterations=30, jitter=0.5, peaks=[(0.3, 0.3), (0.7, 0.6)])\n"
                      "c = generate:rmp(method=cones, cones=40, iterations=30)\n"
                      "g = generate:rmp(method=graph, cuts=6, regions=3, iterations=30)\n"
                      "r = generate:range(from=(0.1, 0.9), to=(0.9, 0.2), cones=80, iterations=10, uplift=true)\n"
                      "s = generate:shape(kind=hemisphere, height=50)\n"
                      "export:raw(v, path=\"v.r32\")\nexport:raw(c, path=\"c.r32\")\nexport:raw(g, path=\"g.r32\")\n"
                      "export:raw(r, path=\"r.r32\")\nexport:raw(s, path=\"s.r32\")\n");
    const auto one = run_orogen("run " + q(spec) + " --quiet --threads 1 --out " + q(dir / "one"));
    ASSERT_EQ(one.exit_code, 0) << one.err;
    const auto two = run_orogen("run " + q(spec) + " --quiet --threads 2 --out " + q(dir / "two"));
    ASSERT_EQ(two.exit_code, 0) << two.err;
    for (const char* f : {"v.r32", "c.r32", "g.r32", "r.r32", "s.r32"}) {
        const auto a = slurp(dir / "one" / f), b = slurp(dir / "two" / f);
        ASSERT_EQ(a.size(), 65u * 65u * 4u) << f;
        EXPECT_EQ(a, b) << f << " differs between 1 and 2 threads";
    }
    // Each terrain is a proper mountain: highest at (one of) its peaks, not raised everywhere.
    const auto c = read_r32(dir / "one" / "c.r32");
    EXPECT_EQ(c[32 * 65 + 32], *std::max_element(c.begin(), c.end()));
    EXPECT_FLOAT_EQ(c[32 * 65 + 32], 150.0f);  // 30 iterations × 5 m
    EXPECT_LT(*std::min_element(c.begin(), c.end()), 150.0f);
    const auto s = read_r32(dir / "one" / "s.r32");
    EXPECT_FLOAT_EQ(s[32 * 65 + 32], 50.0f);
    EXPECT_FLOAT_EQ(s[0], 0.0f);
}

TEST(RmpCli, ConesAndVoronoiGiveTheSameMountainForTheSameSeed) {
    // --set changes a node's parameters, not its label (its seed): two runs of one node.
    TempDir dir;
    const auto spec =
        dir.write("m.orogen",
                  std::string(kHeader) +
                      "m = generate:rmp(cones=50, iterations=40, jitter=0.3)\nexport:raw(m, path=\"m.r32\")\n");
    const auto v = run_orogen("run " + q(spec) + " --quiet --out " + q(dir / "v"));
    ASSERT_EQ(v.exit_code, 0) << v.err;
    const auto c = run_orogen("run " + q(spec) + " --quiet --set m.method=cones --out " + q(dir / "c"));
    ASSERT_EQ(c.exit_code, 0) << c.err;
    const auto a = read_r32(dir / "v" / "m.r32"), b = read_r32(dir / "c" / "m.r32");
    ASSERT_EQ(a.size(), b.size());
    std::size_t same = 0;
    for (std::size_t i = 0; i < a.size(); ++i) same += a[i] == b[i];
    EXPECT_GE(double(same) / double(a.size()), 0.995);
}

struct BadCase {
    const char* name;
    const char* statement;
    int exit_code;
    const char* message;
};

class RmpCliBadInput : public ::testing::TestWithParam<BadCase> {};

TEST_P(RmpCliBadInput, IsAClearError) {
    const BadCase& c = GetParam();
    TempDir dir;
    const auto spec = dir.write("bad.orogen", std::string(kHeader) + c.statement + "\n");
    const auto r = run_orogen("run " + q(spec) + " --quiet --out " + q(dir / "out"));
    EXPECT_EQ(r.exit_code, c.exit_code) << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << "stderr was:\n" << r.err;
}

INSTANTIATE_TEST_SUITE_P(
    Rmp, RmpCliBadInput,
    ::testing::Values(
        BadCase{"peak_outside", "m = generate:rmp(peaks=[(0.5, 0.5), (1.2, 0.5)])", 2, "out of range [0, 1]"},
        BadCase{"zero_cones", "m = generate:rmp(cones=0)", 2, "out of range [1, 10000000]"},
        BadCase{"negative_iterations", "m = generate:rmp(iterations=-3)", 2, "out of range [1, 1000000]"},
        BadCase{"zero_cuts", "m = generate:rmp(method=graph, cuts=0)", 2, "out of range [1, 5000]"},
        BadCase{"regions_beyond_lazy_caterer", "m = generate:rmp(method=graph, cuts=3, regions=8)", 2,
                "generate:rmp: regions=8 is more than the 7 polygons 3 cuts can make at most (n(n+1)/2 + 1); "
                "lower regions or raise cuts"},
        BadCase{"regions_beyond_this_arrangement", "m = generate:rmp(method=graph, cuts=3, regions=7, iterations=200)",
                2, "fewer than regions=7; set regions to at most cuts+1 = 4"},
        BadCase{"cuts_without_graph", "m = generate:rmp(cuts=4)", 2,
                "generate:rmp: cuts and regions apply to method=graph only; this node uses method=voronoi"},
        BadCase{"same_range_ends", "r = generate:range(from=(0.4, 0.5), to=(0.4, 0.5))", 2,
                "generate:range: the range's two end points are the same point (0.4, 0.5); give `from` and `to` "
                "different points"},
        BadCase{"slope_on_a_pyramid", "s = generate:shape(kind=pyramid, slope=20)", 2,
                "generate:shape: slope applies to kind=plane only; this shape is kind=pyramid"},
        BadCase{"unknown_shape", "s = generate:shape(kind=sphere)", 2, "is 'sphere', which is not one of"}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(RmpCli, OsmesaContextFailureIsAClearRunError) {
    // Mesa refuses the shared 4.5 core context (orogen/gl_context.hpp) when told to offer OpenGL 3.0 only.
    TempDir dir;
    const auto spec = dir.write("c.orogen",
                                std::string(kHeader) +
                                    "m = generate:rmp(method=cones)\n"
                                    "export:raw(m, path=\"m.r32\")\n");
    const auto r = run_orogen("run " + q(spec) + " --quiet --out " + q(dir / "out"), "MESA_GL_VERSION_OVERRIDE=3.0");
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_NE(r.err.find("cones: OSMesa could not create an OpenGL 4.5 core context"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("use method=voronoi"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out" / "m.r32"));
}

// Golden hashes of the shipped pipelines' outputs (seed fixed in each spec).
// A change here means the terrain changed: update on purpose, never silently.
TEST(RmpCli, ShippedPipelinesKeepTheirGoldenOutputs) {
    struct Golden {
        const char* spec;
        const char* file;
        const char* sha256;
    };
    const Golden goldens[] = {
        {"rmp-jitter.orogen", "rmp-jitter-static.png",
         "6f673d41826d26a831ea59e223008938a2d3df4a74cfcdd913eb7a2154ef11e2"},
        {"rmp-jitter.orogen", "rmp-jitter-dynamic.png",
         "c3f71af9634d08446826f6ce381943618b53187ab85013eccd51f55ae0b3f60a"},
        {"rmp-mountains.orogen", "rmp-mountains.png",
         "e872a179f0457851111330655367808545d705f373e9e539854c404b00ffead1"},
    };
    for (const Golden& g : goldens) {
        TempDir dir;
        const fs::path spec = fs::path(OROGEN_SOURCE_DIR) / "pipelines" / g.spec;
        const auto r = run_orogen("run " + q(spec) + " --quiet --out " + q(dir.path()));
        ASSERT_EQ(r.exit_code, 0) << g.spec << ": " << r.err;
        EXPECT_EQ(orogen::sha256_file(dir / g.file), g.sha256) << g.spec << " → " << g.file;
    }
    // The timing pipeline is too slow for the suite (about 20 s); it must still check.
    const auto c = run_orogen("check " + q(fs::path(OROGEN_SOURCE_DIR) / "pipelines" / "rmp-timings.orogen"));
    EXPECT_EQ(c.exit_code, 0) << c.err;
}

TEST(RmpCli, ConesOnAGridTooLargeForOsmesaIsRefusedAtCheckTime) {
    TempDir dir;
    const auto spec = dir.write("big.orogen", "orogen 1\ngrid 20000x2\nm = generate:rmp(method=cones)\n");
    const auto r = run_orogen("check " + q(spec));
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("generate:rmp: method=cones draws one pixel per vertex and OSMesa draws at most 16384 × "
                         "16384; this grid is 20000 × 2: use method=voronoi (the same diagram)"),
              std::string::npos)
        << r.err;
}
