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

// erode:hydraulic writes its own `flow` (water per step) and drops a pipe's
// fluxes; the pipe model then starts afresh from water and sediment instead of
// reading that `flow` as its speed: the same bytes as a pipe run continued from
// a zero-step pipe run (whose fluxes and speed are all zero).
TEST(ErosionCli, PipeAfterHydraulicIgnoresItsFlowLayer) {
    TempDir dir;
    const std::string head =
        "orogen 1\n"
        "grid 65 cell=1\n"
        "base = generate:shape(kind=pyramid, height=20)\n"
        "wet = erode:pipe(base, steps=10, dt=0.5)\n"
        "olsen = erode:hydraulic(wet, iterations=5, rain=2, evaporation=0)\n";
    const auto direct = dir.write("direct.orogen",
                                  head +
                                      "p = erode:pipe(olsen, steps=3, dt=2)\n"
                                      "export:raw(p, path=\"p.r32\")\n"
                                      "export:vtk(olsen, path=\"olsen.vti\")\n");
    const auto fresh = dir.write("fresh.orogen",
                                 head +
                                     "z = erode:pipe(olsen, steps=0)\n"
                                     "p = erode:pipe(z, steps=3, dt=2)\n"
                                     "export:raw(p, path=\"p.r32\")\n");
    ASSERT_EQ(run_orogen("run " + q(direct) + " --out " + q(dir / "a")).exit_code, 0);
    ASSERT_EQ(run_orogen("run " + q(fresh) + " --out " + q(dir / "b")).exit_code, 0);
    EXPECT_EQ(slurp(dir / "a" / "p.r32"), slurp(dir / "b" / "p.r32"));
    // The hydraulic output carries its flow and no fluxes.
    const std::string vti = slurp(dir / "a" / "olsen.vti");
    EXPECT_NE(vti.find("Name=\"flow\""), std::string::npos);
    EXPECT_EQ(vti.find("flux_west"), std::string::npos);
}

}  // namespace
