// End to end: the erosion nodes' check-time errors, through the real binary.
#include "orogen_test.hpp"

#include <gtest/gtest.h>

namespace {

using namespace orogen::test;

TEST(ErosionCli, MissingLayersAreCheckTimeErrors) {
    TempDir dir;
    const auto spec = dir.write("bad.orogen",
                                "orogen 1\n"
                                "grid 65 cell=1\n"
                                "base = generate:shape(kind=pyramid)\n"
                                "a = erode:thermal(base, talus=30, hardness=rock)\n"
                                "b = erode:pipe(base, rain_mask=wet)\n"
                                "c = erode:hydraulic(a, hardness=soft)\n");
    const RunResult r = run_orogen("check " + q(spec));
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("bad.orogen:4:44: error: erode:thermal: no layer 'rock' on the input (the input has no "
                         "layers); use constant, height or the name of an existing layer"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("bad.orogen:5:32: error: erode:pipe: no layer 'wet' on the input (the input has no layers)"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("bad.orogen:6:33: error: erode:hydraulic: no layer 'soft' on the input (the input's layers "
                         "are: eroded); use steepness, constant or the name of an existing layer"),
              std::string::npos)
        << r.err;
}

TEST(ErosionCli, BadRatesAndTalusAreRangeErrors) {
    TempDir dir;
    const auto spec = dir.write("range.orogen",
                                "orogen 1\n"
                                "grid 65 cell=1\n"
                                "base = generate:shape(kind=pyramid)\n"
                                "a = erode:thermal(base, talus=90)\n"
                                "b = erode:pipe(base, rain=-1)\n"
                                "c = erode:hydraulic(base, evaporation=nan)\n");
    const RunResult r = run_orogen("check " + q(spec));
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("'talus' of erode:thermal is 90, out of range (0, 90) °"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("'rain' of erode:pipe is -1, out of range [0, inf) m/s"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("'evaporation' of erode:hydraulic must be a finite number, got nan"), std::string::npos)
        << r.err;
}

TEST(ErosionCli, LayersCarryFromNodeToNode) {
    TempDir dir;
    const auto spec = dir.write("chain.orogen",
                                "orogen 1\n"
                                "grid 65 cell=1\n"
                                "base = generate:shape(kind=pyramid, height=20)\n"
                                "a = erode:pipe(base, steps=20, dt=0.5)\n"
                                "b = erode:thermal(a, hardness=water)\n"
                                "c = erode:pipe(b, steps=10, rain_mask=water)\n"
                                "d = erode:hydraulic(c, iterations=5)\n");
    const RunResult r = run_orogen("run " + q(spec) + " --out " + q(dir / "out"));
    EXPECT_EQ(r.exit_code, 0) << r.err;
}

}  // namespace
