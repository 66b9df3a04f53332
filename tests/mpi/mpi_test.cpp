// Tiled runs under mpirun: the real `orogen` binary on 1-4 ranks against the
// same spec run as one process. Seam tests compare the output files byte for
// byte: a tile that stopped eroding at its edge, a halo one vertex short or a
// cut in the wrong place changes bytes near the seams.
#include "orogen_test.hpp"

#include <gtest/gtest.h>

#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkXMLImageDataReader.h>
#include <vtkXMLPImageDataReader.h>

#include <algorithm>
#include <map>
#include <string>
#include <vector>

namespace {

using namespace orogen::test;

/// `mpirun -n RANKS orogen ARGS`, one machine, ranks allowed to outnumber cores and to run as root (CI).
RunResult run_mpi(int ranks, const std::string& args) {
    const std::string launcher =
        std::string(OROGEN_MPIEXEC) + " --oversubscribe --allow-run-as-root -n " + std::to_string(ranks) + " ";
    // run_orogen puts the binary after the environment: mpirun starts it from there.
    return run_orogen(args, "OMPI_MCA_rmaps_base_oversubscribe=1 " + launcher);
}

/// Fault, then thermal (height-aware, then hardness from a layer, with a last
/// sweep shorter than the others), each written whole: RAW heights and a VTK
/// image with every layer (eroded, hardness).
const char* kTiledSpec = R"(orogen 1
seed 7
grid 97x61 cell=2

f  = generate:fault(iterations=300, displacement=0.5)
t1 = erode:thermal(f, talus=20, rate=0.5, iterations=37, hardness=height)
t2 = erode:thermal(t1, talus=15, rate=0.3, iterations=9, hardness="hardness", neighbourhood=von-neumann)
export:raw(f, path="f.r32")
export:raw(t2, path="t.r32")
export:vtk(t2, path="t.vti")
)";

/// A node that is not tiled (generate:shape runs on rank 0) before tiled ones: its value is cut into tiles and
/// sent (Diamond-Square adds its tile of the fractal to it).
const char* kScatterSpec = R"(orogen 1
seed 3
grid 65 cell=1

s = generate:shape(kind=pyramid, height=40)
d = generate:diamond-square(s, amplitude=10)
t = erode:thermal(d, talus=25, iterations=12, neighbourhood=moore)
export:raw(t, path="t.r32")
)";

struct Case {
    int ranks;
    std::string tiles;  // "" automatic
    friend void PrintTo(const Case& c, std::ostream* os) {
        *os << c.ranks << " ranks, tiles " << (c.tiles.empty() ? "automatic" : c.tiles);
    }
};

class Seam : public ::testing::TestWithParam<Case> {};

void expect_same_outputs(const std::string& spec_text, const std::vector<std::string>& files, const Case& c) {
    TempDir dir;
    const auto spec = dir.write("s.orogen", spec_text);
    const RunResult one = run_orogen("run " + q(spec) + " --out " + q(dir / "one") + " -q");
    ASSERT_EQ(one.exit_code, 0) << one.err;
    const RunResult many = run_mpi(
        c.ranks, "run " + q(spec) + " --out " + q(dir / "many") + (c.tiles.empty() ? "" : " --tiles " + c.tiles));
    ASSERT_EQ(many.exit_code, 0) << many.err;
    EXPECT_NE(many.out.find("tiled run: " + std::to_string(c.ranks) + " rank"), std::string::npos) << many.out;
    for (const auto& f : files) {
        const std::string a = slurp(dir / "one" / f), b = slurp(dir / "many" / f);
        ASSERT_FALSE(a.empty()) << f;
        EXPECT_TRUE(a == b) << f << " differs between one process and " << c.ranks << " ranks"
                            << (c.tiles.empty() ? "" : " (--tiles " + c.tiles + ")");
    }
}

TEST_P(Seam, FaultAndThermalEqualOneProcess) {
    expect_same_outputs(kTiledSpec, {"f.r32", "t.r32", "t.vti"}, GetParam());
}

INSTANTIATE_TEST_SUITE_P(Ranks, Seam,
                         ::testing::Values(Case{1, ""}, Case{2, ""}, Case{3, ""}, Case{4, ""}, Case{2, "2x1"},
                                           Case{3, "3x1"}, Case{4, "1x4"}),
                         [](const auto& info) {
                             std::string t = info.param.tiles.empty() ? "auto" : info.param.tiles;
                             return std::to_string(info.param.ranks) + "_ranks_" + t;
                         });

/// Pipe erosion twice (closed walls with the sediment fix-up and a rain mask
/// from a layer, then open edges continuing from the first's water, sediment
/// and fluxes): every layer it writes goes into the .vti.
const char* kPipeSpec = R"(orogen 1
seed 11
grid 97x61 cell=2

f = generate:fault(iterations=300, displacement=0.5)
t = erode:thermal(f, talus=20, iterations=5, hardness=height)
p = erode:pipe(t, steps=30, dt=0.5, rain=0.01, creep=0.2, rain_mask="hardness")
q = erode:pipe(p, steps=7, dt=0.3, rain=0.002, boundary=open)
export:raw(q, path="q.r32")
export:vtk(p, path="p.vti")
export:vtk(q, path="q.vti")
)";

/// Olsen's hydraulic automaton in its three hardness modes (steepness, a
/// layer, constant), with sweeps shorter than the others at the end.
const char* kHydraulicSpec = R"(orogen 1
seed 13
grid 97x61 cell=2

f = generate:fault(iterations=300, displacement=0.5)
t = erode:thermal(f, talus=20, iterations=5, hardness=height)
h1 = erode:hydraulic(t, iterations=23, rain=0.02)
h2 = erode:hydraulic(h1, iterations=6, hardness="hardness", evaporation=0.3)
h3 = erode:hydraulic(h2, iterations=5, hardness=constant)
export:raw(h3, path="h.r32")
export:vtk(h1, path="h1.vti")
export:vtk(h3, path="h3.vti")
)";

const auto kErosionCases = ::testing::Values(Case{1, ""}, Case{2, ""}, Case{3, ""}, Case{4, ""}, Case{2, "2x1"},
                                             Case{3, "3x1"}, Case{3, "1x3"}, Case{4, "2x2"});
const auto kCaseName = [](const auto& info) {
    std::string t = info.param.tiles.empty() ? "auto" : info.param.tiles;
    return std::to_string(info.param.ranks) + "_ranks_" + t;
};

/// Diamond-Square on its own and added to a tiled base: each rank makes its tile from the coarser levels near it.
const char* kDiamondSquareSpec = R"(orogen 1
seed 5
grid 97x61 cell=2

d = generate:diamond-square(amplitude=40, roughness=0.6)
f = generate:fault(iterations=50, displacement=0.5)
e = generate:diamond-square(f, amplitude=3)
export:raw(d, path="d.r32")
export:raw(e, path="e.r32")
)";

class DiamondSquareSeam : public ::testing::TestWithParam<Case> {};
TEST_P(DiamondSquareSeam, DiamondSquareEqualsOneProcess) {
    expect_same_outputs(kDiamondSquareSpec, {"d.r32", "e.r32"}, GetParam());
}
INSTANTIATE_TEST_SUITE_P(Ranks, DiamondSquareSeam, kErosionCases, kCaseName);

class PipeSeam : public ::testing::TestWithParam<Case> {};
TEST_P(PipeSeam, PipeEqualsOneProcess) { expect_same_outputs(kPipeSpec, {"q.r32", "p.vti", "q.vti"}, GetParam()); }
INSTANTIATE_TEST_SUITE_P(Ranks, PipeSeam, kErosionCases, kCaseName);

class HydraulicSeam : public ::testing::TestWithParam<Case> {};
TEST_P(HydraulicSeam, HydraulicEqualsOneProcess) {
    expect_same_outputs(kHydraulicSpec, {"h.r32", "h1.vti", "h3.vti"}, GetParam());
}
INSTANTIATE_TEST_SUITE_P(Ranks, HydraulicSeam, kErosionCases, kCaseName);

/// Hillslope diffusion in each of its solvers: backward Euler with every side
/// closed, Peaceman-Rachford with two sides fixed (its explicit half reads the
/// neighbours' edge rows and columns), and critical-slope diffusion with the
/// other two fixed (link factors across the seams); the last step of each is
/// shorter than dt. Each sweep's recurrences run across every tile of a row or
/// column, so a value carried one tile short or in the wrong order changes
/// every vertex downstream of the seam, not just those next to it.
const char* kDiffusionSpec = R"(orogen 1
seed 17
grid 97x61 cell=2

f = generate:fault(iterations=300, displacement=2)
a = erode:diffusion(f, diffusivity=0.05, years=2500, dt=300)
b = erode:diffusion(a, diffusivity=0.2, years=900, dt=200, scheme=adi, fixed="nw")
c = erode:diffusion(b, diffusivity=0.1, years=1000, dt=150, critical_angle=35, fixed="es")
export:raw(a, path="a.r32")
export:raw(b, path="b.r32")
export:vtk(c, path="c.vti")
)";

class DiffusionSeam : public ::testing::TestWithParam<Case> {};
TEST_P(DiffusionSeam, DiffusionEqualsOneProcess) {
    expect_same_outputs(kDiffusionSpec, {"a.r32", "b.r32", "c.vti"}, GetParam());
}
INSTANTIATE_TEST_SUITE_P(Ranks, DiffusionSeam, kErosionCases, kCaseName);

/// Stream-power landscape evolution, whose rivers cross the tiles: fault
/// relief full of pits (filled, then routed across with n = 1.5), uplift from
/// a layer spread across the seams, hillslope diffusion, chi, every side
/// closed with the lowest cell of the whole grid as the one outlet, and a
/// time-lapse; then routing=mfd (not tiled: on rank 0) and (s13) floodplains reaching across the seams;
/// rough diamond-square relief with a hundred lakes a step, most of them
/// settled on their own tile (closed basins) and the rest by rank 0; and
/// uplift from the plates' time-lapse (a series on rank 0, each interval's
/// frames cut into tiles, smoothed across them), steps spanning frames;
/// landslides in tilted beds of varying strength (the limit's sweeps meet
/// at the seams until no tile changes); and sub-steps (creep, incision,
/// landslides and the history's uplift, split inside steps that span its
/// frames, three times a step on one routing), with rivers lowering their
/// banks (a bank across a seam pushed by the neighbour's river). A
/// basin labelled wrongly, a lake filled to another level, a pass reversed
/// one tile short or an exit's drainage area lost at a seam changes the
/// heights or the layers (drainage, flow_direction, chi) downstream of it.
const char* kStreamPowerSpec = R"(orogen 1
seed 7
grid 97x61 cell=30

f  = generate:fault(iterations=300, displacement=20)
t  = erode:thermal(f, talus=30, iterations=3, hardness=height)
s1 = erode:stream-power(t, years=2e5, dt=1e4, diffusivity=0.01, chi=true, uplift_layer="hardness", uplift_smoothing=200, timelapse_every=4)
s2 = erode:stream-power(s1, years=1e5, dt=2e4, n=1.5, depressions=route, open="ns", diffusivity=0)
s3 = erode:stream-power(s2, years=6e4, dt=2e4, open="none", uplift=2, base_level="0")
s4 = erode:stream-power(s3, years=4e4, dt=2e4, routing=mfd)
d  = generate:diamond-square(roughness=0.7, amplitude=300)
s5 = erode:stream-power(d, years=3e4, dt=1e4, diffusivity=0.01, channel_area=2e4)
s6 = erode:stream-power(d, years=2e4, dt=1e4, depressions=route, open="we", n=1.5, uplift_edge_taper=600)
p  = tectonics:plates(d, plates=4, steps=120, cones=30, height=60, timelapse_every=30)
s7 = erode:stream-power(p, p.timelapse, years=5e4, dt=1.5e4, uplift_history_years=4e4, uplift_smoothing=60, diffusivity=0.01, uplift_edge_taper=400)
s8 = erode:stream-power(d, years=6e4, dt=1e4, uplift=3, diffusivity=0.01, landslide_angle=28, bed_thickness=30, bed_dip=25, bed_dip_toward=60, bed_angle_spread=8, bed_erodibility_contrast=4, bed_fold_amplitude=60, bed_fold_wavelength=900, bed_thickness_spread=0.7, bed_fault_spacing=600, bed_fault_throw=50, landslide_block_spread=0.6, bed_facies_length=400, bed_facies_share=0.7)
s9 = erode:stream-power(p, p.timelapse, years=5e4, dt=2.5e4, uplift_history_years=4e4, substeps=3, uplift=1, diffusivity=0.05, channel_area=2e4, landslide_angle=30, bank_erosion=4, bank_area=1e4)
s10 = erode:stream-power(d, years=6e4, dt=1e4, uplift=2, diffusivity=0.01, channel_area=1e4, bank_erosion=6, bank_area=1e4, bank_wide_area=3e4, bank_wider_area=6e4, bank_widest_floor=11, open="we")
s11 = erode:stream-power(d, years=4e4, dt=1e4, uplift=2, diffusivity=0.01, rain=orographic, wind_from=290, rain_resolution=150, open="ns")
s12 = erode:stream-power(d, years=2e4, dt=1e4, uplift=2, rain=orographic, wind_from=60, rain_resolution=30, channel_area=1e4)
s13 = erode:stream-power(d, years=2e4, dt=1e4, uplift=2, channel_area=1e4, floodplain_area=5e4, floodplain_width=90, floodplain_max_slope=20)
r = render:terrain(s1.timelapse, width=194, height=122, exaggeration=2)
export:video(r, path="s1.mpg", fps=25, quality=0)
export:vtk(s1, path="s1.vti")
export:vtk(s2, path="s2.vti")
export:vtk(s3, path="s3.vti")
export:raw(s4, path="s4.r32")
export:vtk(s5, path="s5.vti")
export:vtk(s6, path="s6.vti")
export:vtk(s7, path="s7.vti")
export:vtk(s8, path="s8.vti")
export:vtk(s9, path="s9.vti")
export:vtk(s10, path="s10.vti")
export:vtk(s11, path="s11.vti")
export:vtk(s12, path="s12.vti")
export:vtk(s13, path="s13.vti")
)";

class StreamPowerSeam : public ::testing::TestWithParam<Case> {};
TEST_P(StreamPowerSeam, StreamPowerEqualsOneProcess) {
    expect_same_outputs(kStreamPowerSpec,
                        {"s1.mpg", "s1.vti", "s2.vti", "s3.vti", "s4.r32", "s5.vti", "s6.vti", "s7.vti", "s8.vti",
                         "s9.vti", "s10.vti", "s11.vti", "s12.vti", "s13.vti"},
                        GetParam());
}
INSTANTIATE_TEST_SUITE_P(Ranks, StreamPowerSeam, kErosionCases, kCaseName);

/// `spec_text` run on 2 ranks (its outputs in a folder removed on return).
RunResult run_on_two_ranks(const char* spec_text) {
    TempDir dir;
    const auto spec = dir.write("s.orogen", spec_text);
    return run_mpi(2, "run " + q(spec) + " --out " + q(dir / "out"));
}

TEST(Mpi, StreamPowerSettingsThatDoNotTileRunOnRankZeroAndSaySo) {
    const RunResult r = run_on_two_ranks(kStreamPowerSpec);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("'s4' (erode:stream-power) ran on rank 0 over the whole grid: routing=mfd is not tiled yet"),
              std::string::npos)
        << r.out;
    // The tiled ones say how many rounds their solves took down rivers that cross tiles (rank 0 speaks for
    // the run: the other ranks' progress and information lines are quiet).
    EXPECT_NE(r.err.find("rank 0 of 2, up to "), std::string::npos) << r.err;
    EXPECT_EQ(r.out.find("'s1' (erode:stream-power) ran on rank 0"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("'s7' (erode:stream-power) ran on rank 0"), std::string::npos)
        << r.out;  // uplift_history tiles
    EXPECT_EQ(r.out.find("'s13' (erode:stream-power) ran on rank 0"), std::string::npos) << r.out;  // floodplains tile
}

/// The lines "NODE: suspended sediment X m, ..." of a run's output, in order.
std::vector<std::string> suspended_lines(const RunResult& r) {
    std::vector<std::string> lines;
    for (const std::string* text : {&r.out, &r.err})
        for (std::size_t at = text->find("suspended sediment"); at != std::string::npos;
             at = text->find("suspended sediment", at + 1)) {
            const std::size_t start = text->rfind('\n', at) == std::string::npos ? 0 : text->rfind('\n', at) + 1;
            lines.push_back(text->substr(start, text->find('\n', at) - start));
        }
    std::sort(lines.begin(), lines.end());
    return lines;
}

TEST(Mpi, PipeSedimentTotalsAreTheSingleProcesssToTheLastBit) {
    // The closed-wall fix-up's total (a double over every cell) is carried through the tiles in the single
    // process's order; its 17 digits are printed once per node.
    TempDir dir;
    const auto spec = dir.write("s.orogen", kPipeSpec);
    const RunResult one = run_orogen("run " + q(spec) + " --out " + q(dir / "one"));
    ASSERT_EQ(one.exit_code, 0) << one.err;
    const auto expected = suspended_lines(one);
    ASSERT_EQ(expected.size(), 2u) << one.out << one.err;
    for (const auto& [ranks, tiles] : {std::pair{4, "2x2"}, std::pair{3, "1x3"}}) {
        const RunResult many = run_mpi(ranks, "run " + q(spec) + " --out " + q(dir / tiles) + " --tiles " + tiles);
        ASSERT_EQ(many.exit_code, 0) << many.err;
        EXPECT_EQ(suspended_lines(many), expected) << tiles;
    }
}

TEST(Mpi, TilesNarrowerThanPipeOrHydraulicHalosAreRefusedAtTheNode) {
    TempDir dir;
    // 20 columns in 1x4: tiles 5 wide. Pipe needs 3 (fine), hydraulic 12 (refused); 1x8: tiles 2 wide, both refused.
    const auto spec = dir.write("s.orogen",
                                "orogen 1\ngrid 20x16\nf = generate:fault()\np = erode:pipe(f, steps=2)\n"
                                "h = erode:hydraulic(p, iterations=3)\nexport:raw(h, path=\"h.r32\")\n");
    const RunResult r = run_mpi(4, "run " + q(spec) + " --out " + q(dir / "o") + " --tiles 1x4");
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("s.orogen:5:5: error: 'h' (erode:hydraulic) exchanges a halo of 12 vertices with each "
                         "neighbouring tile, so tiles must be at least 12 vertices wide, but --tiles 1x4 cuts the "
                         "20x16 grid into tiles 5 wide; use fewer columns (--tiles), fewer ranks or a larger grid"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(r.err.find("'p' (erode:pipe)"), std::string::npos) << r.err;
    const RunResult narrow = run_mpi(8, "run " + q(spec) + " --out " + q(dir / "o") + " --tiles 8x1");
    EXPECT_EQ(narrow.exit_code, 2);
    EXPECT_NE(narrow.err.find("s.orogen:4:5: error: 'p' (erode:pipe) exchanges a halo of 3 vertices with each "
                              "neighbouring tile, so tiles must be at least 3 vertices high, but --tiles 8x1 cuts the "
                              "20x16 grid into tiles 2 high; use fewer rows (--tiles), fewer ranks or a larger grid"),
              std::string::npos)
        << narrow.err;
    EXPECT_FALSE(fs::exists(dir / "o" / "h.r32"));
}

TEST(Mpi, ASpecErrorIsSaidOnceByRankZeroBeforeAnyRankLeaves) {
    // Every rank reaches the same verdict; rank 0 alone says why, and the ranks meet before leaving, so
    // mpirun does not end rank 0 before its message is out (it once did under load: exit 2, no message).
    TempDir dir;
    const auto count = [](const std::string& text, const std::string& what) {
        std::size_t n = 0;
        for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
        return n;
    };
    const auto broken = dir.write("broken.orogen", "orogen 1\ngrid 33\nf = generate:fault(\n");
    const RunResult syntax = run_mpi(3, "check " + q(broken));
    EXPECT_EQ(syntax.exit_code, 2);
    EXPECT_EQ(count(syntax.err, "broken.orogen:3:19: error: this '(' of the call to generate:fault is never closed"),
              1u)
        << syntax.err;
    const RunResult missing = run_mpi(3, "run " + q(dir / "missing.orogen") + " --out " + q(dir / "o"));
    EXPECT_EQ(missing.exit_code, 2);
    EXPECT_EQ(count(missing.err, "missing.orogen: no such file"), 1u) << missing.err;
    for (int i = 0; i < 4; ++i) {  // a check error found by every rank, said once each time
        const RunResult r = run_mpi(4, "check " + q(broken));
        EXPECT_EQ(count(r.err, "1 error in"), 1u) << r.err;
    }
    EXPECT_FALSE(fs::exists(dir / "o"));
}

TEST(Mpi, TimelapseOfATiledNodeThatDoesNotGatherItIsRefused) {
    // A plugin's tiled node without tiled_timelapse (every node of orogen's own gathers its frames).
    TempDir dir;
    const auto spec = dir.write("s.orogen",
                                "orogen 1\ngrid 33\nf = generate:fault()\n"
                                "p = erode:test-tiled-no-lapse(f, timelapse_every=2)\n"
                                "export:raw(p, path=\"p.r32\")\n");
    const std::string launcher =
        std::string(OROGEN_MPIEXEC) + " --oversubscribe --allow-run-as-root -x OROGEN_PLUGIN_PATH -n 2 ";
    const RunResult r = run_orogen("run " + q(spec) + " --out " + q(dir / "o"),
                                   "OROGEN_PLUGIN_PATH=" + std::string(OROGEN_FAKE_PLUGIN_DIR) + " " + launcher);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find("s.orogen:4:5: error: 'p' (erode:test-tiled-no-lapse): time-lapses are not recorded in a "
                         "tiled run yet; set timelapse_every=0 or run without mpirun"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(dir / "o" / "p.r32"));
}

/// The plates' time-lapse in a tiled run: every rank replays rank 0's Box2D
/// outcome into its tile up to each frame's step (peaks, rifts and
/// subduction in the relief's fields, the thesis's Voronoi cells straight
/// onto the terrain) and rank 0 gathers the frames: a stamp drawn a frame
/// early or late, or a tile's relief applied over the wrong rectangle,
/// changes the video's bytes.
const char* kPlatesTimelapseSpec = R"(orogen 1
seed 23
grid 97x61 cell=50

c = generate:fault(iterations=100, displacement=0.5)
p = tectonics:plates(c, plates=6, steps=120, oceanic_fraction=0.5, rift_threshold=2000, cones=40, timelapse_every=2)
q = tectonics:plates(p, plates=5, steps=80, ranges=cells, cones=30, drive=thesis, timelapse_every=2)
rp = render:terrain(p.timelapse, width=96, height=60, exaggeration=2)
rq = render:terrain(q.timelapse, width=96, height=60, exaggeration=2)
export:video(rp, path="p.mpg", fps=25, quality=0)
export:video(rq, path="q.mpg", fps=25, quality=0)
)";

class PlatesTimelapseSeam : public ::testing::TestWithParam<Case> {};
TEST_P(PlatesTimelapseSeam, PlatesTimelapseEqualsOneProcess) {
    expect_same_outputs(kPlatesTimelapseSpec, {"p.mpg", "q.mpg"}, GetParam());
}
INSTANTIATE_TEST_SUITE_P(Ranks, PlatesTimelapseSeam, ::testing::Values(Case{2, ""}, Case{3, "1x3"}, Case{4, "2x2"}),
                         kCaseName);

/// The time-lapses of the tiled eroders (rank 0 gathers each frame from the
/// tiles): thermal at the ends of its sweeps, hydraulic and pipe after their
/// steps (the first frame with the water run() makes), diffusion after every
/// step, each rendered and encoded near-losslessly (MPEG-2 at quantiser 1, 2
/// pixels a vertex, the relief exaggerated): a frame missing, taken at
/// another step or a row off in one tile changes the video's bytes.
const char* kTimelapseSpec = R"(orogen 1
seed 19
grid 97x61 cell=2

f = generate:fault(iterations=300, displacement=0.5)
t = erode:thermal(f, talus=20, rate=0.5, iterations=11, timelapse_every=4)
h = erode:hydraulic(t, iterations=9, rain=0.02, timelapse_every=3)
p = erode:pipe(h, steps=7, dt=0.5, rain=0.01, timelapse_every=2)
d = erode:diffusion(p, diffusivity=0.05, years=1000, dt=300, timelapse_every=1)
rt = render:terrain(t.timelapse, width=194, height=122, exaggeration=4)
rh = render:terrain(h.timelapse, width=194, height=122, exaggeration=4)
rp = render:terrain(p.timelapse, width=194, height=122, exaggeration=4)
rd = render:terrain(d.timelapse, width=194, height=122, exaggeration=4)
export:video(rt, path="t.mpg", fps=25, quality=0)
export:video(rh, path="h.mpg", fps=25, quality=0)
export:video(rp, path="p.mpg", fps=25, quality=0)
export:video(rd, path="d.mpg", fps=25, quality=0)
)";

class TimelapseSeam : public ::testing::TestWithParam<Case> {};
TEST_P(TimelapseSeam, TiledTimelapsesEqualOneProcesss) {
    expect_same_outputs(kTimelapseSpec, {"t.mpg", "h.mpg", "p.mpg", "d.mpg"}, GetParam());
}
INSTANTIATE_TEST_SUITE_P(Ranks, TimelapseSeam, ::testing::Values(Case{2, ""}, Case{3, "1x3"}, Case{4, "2x2"}),
                         kCaseName);

TEST(Mpi, WholeValueFromRankZeroIsCutIntoTiles) { expect_same_outputs(kScatterSpec, {"t.r32"}, {3, "3x1"}); }

TEST(Mpi, MoreRanksThanTilesIsRefused) {
    TempDir dir;
    const auto spec = dir.write("s.orogen", kScatterSpec);
    const RunResult r = run_mpi(3, "run " + q(spec) + " --out " + q(dir / "o") + " --tiles 2x1");
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--tiles 2x1 makes 2 tiles for 3 ranks (more ranks than tiles)"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "o" / "t.r32"));
}

TEST(Mpi, TilesNarrowerThanTheHaloAreRefusedAtTheNode) {
    TempDir dir;
    const auto spec = dir.write("s.orogen",
                                "orogen 1\ngrid 28x20\nf = generate:fault()\nt = erode:thermal(f)\n"
                                "export:raw(t, path=\"t.r32\")\n");
    const RunResult r = run_mpi(4, "run " + q(spec) + " --out " + q(dir / "o") + " --tiles 1x4");
    EXPECT_EQ(r.exit_code, 2);
    // Once (rank 0 speaks), at the thermal node's line, naming the halo, the tile width and what to change.
    EXPECT_NE(r.err.find("s.orogen:4:5: error: 't' (erode:thermal) exchanges a halo of 8 vertices"), std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("--tiles 1x4 cuts the 28x20 grid into tiles 7 wide"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("error: 't'"), r.err.rfind("error: 't'")) << r.err;
    const RunResult ok = run_mpi(2, "run " + q(spec) + " --out " + q(dir / "o") + " --tiles 1x2");
    EXPECT_EQ(ok.exit_code, 0) << ok.err;  // tiles 14 wide: fine
}

TEST(Mpi, TilesWithoutMpirunIsAUsageError) {
    const RunResult r = run_orogen("run nothing.orogen --tiles 2x2");
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("this orogen was not started by mpirun"), std::string::npos) << r.err;
}

/// A .r32 (and sidecar) of width × height with heights 0, but ±3e38 on two
/// neighbouring vertices at the east edge: their drop overflows to infinity
/// and thermal erosion turns it into NaN there, in the east tile only at first.
fs::path write_poisoned_raw(const TempDir& dir, int width, int height) {
    std::vector<float> h(std::size_t(width) * std::size_t(height), 0.0f);
    h[std::size_t(height / 2) * std::size_t(width) + std::size_t(width - 1)] = 3e38f;
    h[std::size_t(height / 2) * std::size_t(width) + std::size_t(width - 2)] = -3e38f;
    dir.write("p.r32", std::string(reinterpret_cast<const char*>(h.data()), h.size() * sizeof(float)));
    dir.write("p.r32.json",
              "{\"format\": \"r32\", \"sample_type\": \"float32\", \"byte_order\": \"little-endian\", "
              "\"width\": " +
                  std::to_string(width) + ", \"height\": " + std::to_string(height) +
                  ", \"cell_size\": 1, \"height_min\": -3e38, \"height_max\": 3e38, \"units\": \"m\", "
                  "\"layout\": \"rows north to south, samples west to east, no header\"}");
    return dir / "p.r32";
}

TEST(Mpi, ARankThatFailsEndsEveryRankWithOneErrorAndNoOutputs) {
    TempDir dir;
    write_poisoned_raw(dir, 400, 16);
    // Staged before the failure: export:raw of the input. The NaN shows at the check after step 64, when it
    // has spread ~128 vertices: only in the east tile of 1x2, so rank 1 fails while rank 0 goes on.
    const auto spec = dir.write("s.orogen",
                                "orogen 1\ngrid 400x16\np = import:raw(path=\"p.r32\")\n"
                                "export:raw(p, path=\"before.r32\")\n"
                                "t = erode:thermal(p, iterations=100)\nexport:raw(t, path=\"t.r32\")\n");
    const RunResult one = run_orogen("run " + q(spec) + " --out " + q(dir / "one"));
    ASSERT_EQ(one.exit_code, 1) << one.err;
    const RunResult r = run_mpi(2, "run " + q(spec) + " --out " + q(dir / "many") + " --tiles 1x2");
    EXPECT_EQ(r.exit_code, 1) << r.err;
    // One report, the same as one process gives (the node, its line, the step).
    const auto line = [](const std::string& err) {
        const auto at = err.find("error: node 't'");
        return at == std::string::npos ? std::string() : err.substr(at, err.find('\n', at) - at);
    };
    EXPECT_NE(line(one.err).find("failed: non-finite height"), std::string::npos) << one.err;
    EXPECT_NE(line(one.err).find("after step 64"), std::string::npos) << one.err;
    EXPECT_EQ(line(r.err), line(one.err)) << r.err;
    EXPECT_EQ(r.err.find("error:"), r.err.rfind("error:")) << r.err;  // once, not once per rank
    // Nothing in --out on any rank: no outputs, no manifest, no staging folder left behind.
    std::vector<std::string> left;
    for (const auto& e : fs::directory_iterator(dir / "many")) left.push_back(e.path().filename().string());
    EXPECT_TRUE(left.empty()) << left.size() << " entries left, first " << (left.empty() ? "" : left[0]);
}

TEST(Mpi, APipeRankWithABadRainMaskEndsEveryRankWithOneError) {
    TempDir dir;
    write_poisoned_raw(dir, 400, 16);  // as a rain mask: a negative factor in the east tile only
    const auto spec = dir.write("s.orogen",
                                "orogen 1\ngrid 400x16\nf = generate:fault()\nm = import:raw(path=\"p.r32\")\n"
                                "export:raw(f, path=\"f.r32\")\n"
                                "p = erode:pipe(f, m, steps=4)\nexport:raw(p, path=\"p.r32\")\n");
    const RunResult one = run_orogen("run " + q(spec) + " --out " + q(dir / "one"));
    ASSERT_EQ(one.exit_code, 2) << one.err;
    // Rank 1 fails before the solver's first collective; rank 0 meets its failure there.
    const RunResult r = run_mpi(2, "run " + q(spec) + " --out " + q(dir / "many") + " --tiles 1x2");
    EXPECT_EQ(r.exit_code, 2) << r.err;
    const auto line = [](const std::string& err) {
        const auto at = err.find("error: node 'p'");
        return at == std::string::npos ? std::string() : err.substr(at, err.find('\n', at) - at);
    };
    EXPECT_NE(line(one.err).find("rain_mask: the mask holds a negative or NaN value"), std::string::npos) << one.err;
    EXPECT_EQ(line(r.err), line(one.err)) << r.err;
    EXPECT_EQ(r.err.find("error:"), r.err.rfind("error:")) << r.err;
    EXPECT_TRUE(fs::is_empty(dir / "many"));
}

TEST(Mpi, AFailedWriteOnRankZeroEndsEveryRank) {
    TempDir dir;
    const auto spec = dir.write("s.orogen",
                                "orogen 1\ngrid 33\nf = generate:fault()\nt = erode:thermal(f, iterations=4)\n"
                                "export:raw(f, path=\"f.r32\")\nexport:raw(t, path=\"t.r32\")\n");
    fs::create_directories(dir / "o" / "t.r32");  // a folder where the file should go
    const RunResult r = run_mpi(2, "run " + q(spec) + " --out " + q(dir / "o"));
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_NE(r.err.find("a folder has that name"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "o" / "f.r32"));
    EXPECT_FALSE(fs::exists(dir / "o" / "manifest.json"));
}

/// The default pipeline (`make demo`), shortened with --set, on 3 ranks in
/// a row of tiles and on 2x2: every node that computes terrain is tiled
/// (diamond-square, plates, the range, stream power, thermal, diffusion), the renders,
/// the video and the whole-file exports run on rank 0 over gathered grids.
/// Every file the run writes, the manifest's digests included, must be one
/// process's bytes.
TEST(Mpi, DefaultPipelineEqualsOneProcess) {
    const std::string spec = std::string(OROGEN_SOURCE_DIR) + "/pipelines/default.orogen";
    const std::string shorter =
        " --set plates.steps=200 --set range.years=2e5 --set beauty.width=320"
        " --set beauty.height=180 --set beauty.samples=1 --set spin.frames=4 --set spin.width=160 --set spin.height=90";
    TempDir dir;
    const RunResult one = run_orogen("run " + q(spec) + " --out " + q(dir / "one") + " -q" + shorter);
    ASSERT_EQ(one.exit_code, 0) << one.err;
    auto files_of = [](const fs::path& root) {
        std::vector<std::string> names;
        for (const auto& e : fs::recursive_directory_iterator(root))
            if (e.is_regular_file()) names.push_back(fs::relative(e.path(), root).string());
        std::sort(names.begin(), names.end());
        return names;
    };
    const std::vector<std::string> want = files_of(dir / "one");
    ASSERT_GT(want.size(), 20u);
    for (const std::string tiles : {"1x3", "2x2"}) {
        const int ranks = tiles == "1x3" ? 3 : 4;
        const RunResult many =
            run_mpi(ranks, "run " + q(spec) + " --out " + q(dir / tiles) + " --tiles " + tiles + shorter);
        ASSERT_EQ(many.exit_code, 0) << many.err;
        EXPECT_EQ(many.out.find("ran on rank 0 over the whole grid"), std::string::npos) << many.out;
        // The plates' counts come from rank 0's simulation, once (the other ranks only draw its outcome).
        const std::string all = many.out + many.err;
        const std::size_t first = all.find("plates at the end");
        EXPECT_NE(first, std::string::npos) << all;
        EXPECT_EQ(all.find("plates at the end", first + 1), std::string::npos) << all;
        ASSERT_EQ(files_of(dir / tiles), want) << tiles;
        for (const std::string& f : want)
            EXPECT_TRUE(slurp(dir / "one" / f) == slurp(dir / tiles / f)) << f << " differs on " << tiles;
    }
}

/// Repeated Magnification and Probing and a range between two points: every
/// rank draws each iteration's diagram (Voronoi cells, or the faces of random
/// cuts) over the whole grid and raises its tile's part of the chosen
/// regions; on a flat start and on a base, with jitter and the range's
/// uplift layer; method=cones (OSMesa over the whole grid) runs on rank 0 and
/// says so. A cell clipped to the wrong rectangle, a span a row off or a
/// graph face's vertex raised twice at a seam changes the bytes.
const char* kRmpSpec = R"(orogen 1
seed 29
grid 97x61 cell=10

m = generate:rmp(peaks=[(0.3, 0.4), (0.7, 0.6)], iterations=40, cones=30, height=6, decay=0.98, jitter=0.3)
g = generate:rmp(m, method=graph, peaks=[(0.5, 0.5), (0.52, 0.5)], iterations=30, cuts=6, regions=3, height=4, jitter=0.2)
r = generate:range(g, from=(0.1, 0.2), to=(0.9, 0.8), iterations=20, cones=60, height=3, jitter=0.5, uplift=true)
c = generate:rmp(r, method=cones, iterations=5, cones=20)
t = erode:thermal(c, talus=30, iterations=4)
export:vtk(r, path="r.vti")
export:raw(t, path="t.r32")
)";

class RmpSeam : public ::testing::TestWithParam<Case> {};
TEST_P(RmpSeam, RmpEqualsOneProcess) { expect_same_outputs(kRmpSpec, {"r.vti", "t.r32"}, GetParam()); }
INSTANTIATE_TEST_SUITE_P(Ranks, RmpSeam, kErosionCases, kCaseName);

TEST(Mpi, RmpConesRunOnRankZeroAndSaySo) {
    const RunResult r = run_on_two_ranks(kRmpSpec);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("'c' (generate:rmp) ran on rank 0 over the whole grid: method=cones draws the whole grid "
                         "through OSMesa"),
              std::string::npos)
        << r.out;
    EXPECT_EQ(r.out.find("'m' (generate:rmp) ran on rank 0"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("'r' (generate:range) ran on rank 0"), std::string::npos) << r.out;
}

/// The plates, twice (peaks with subduction and rifts, then the thesis's Voronoi cells): rank 0 runs Box2D,
/// every rank draws the outcome into its tile; the heights, the uplift, boundary and plate layers and the
/// plates' history (a whole value, from rank 0) are the single process's, and a tiled eroder follows.
const char* kPlatesSpec = R"(orogen 1
seed 21
grid 97x61 cell=50

c = generate:fault(iterations=100, displacement=0.5)
p = tectonics:plates(c, plates=8, steps=400, oceanic_fraction=0.5, rift_threshold=2000, cones=40)
q = tectonics:plates(p, plates=6, steps=200, ranges=cells, cones=30, drive=thesis)
t = erode:thermal(q, talus=30, iterations=6)
export:raw(q, path="q.r32")
export:vtk(q, path="q.vti")
export:raw(t, path="t.r32")
export:vtk-plates(p.plates, path="plates/p.pvd")
)";

class PlatesSeam : public ::testing::TestWithParam<Case> {};
TEST_P(PlatesSeam, PlatesEqualOneProcess) {
    expect_same_outputs(
        kPlatesSpec,
        {"q.r32", "q.vti", "t.r32", "plates/p.pvd", "plates/p_plates_000040.vtp", "plates/p_collisions_000040.vtp"},
        GetParam());
}
INSTANTIATE_TEST_SUITE_P(Ranks, PlatesSeam,
                         ::testing::Values(Case{1, ""}, Case{2, ""}, Case{3, "3x1"}, Case{3, "1x3"}, Case{4, "2x2"}),
                         kCaseName);

/// Engine tiles (export:tiles), each written by the rank holding its middle sample: 16-bit PNG and
/// float RAW with their VRTs, in tiles that straddle the ranks' tiles (17 samples every 16 columns and rows,
/// against cuts at columns 24, 48, 72 or 48 and rows 20, 40 or 30), and 16-bit RAW tiles of 65 samples, which
/// have their middles at columns 32 and 80 only and so leave some ranks none to write (an empty fetch);
/// and the glTF level-of-detail pyramid, whose coarse chunks fetch lattices spread over several ranks.
const char* kEngineTilesSpec = R"(orogen 1
seed 9
grid 97x61 cell=2

f = generate:fault(iterations=300, displacement=0.5)
t = erode:thermal(f, talus=20, iterations=9, hardness=height)
export:tiles(t, path="png/t.json", tile_size=17)
export:tiles(t, path="r32/t.json", tile_size=17, format=r32)
export:tiles(t, path="big/t.json", tile_size=65, format=r16, low=-5, high=4)
export:tiles(t, path="glb/t.json", tile_size=17, format=glb, texture=16)
)";

class EngineTilesSeam : public ::testing::TestWithParam<Case> {};
TEST_P(EngineTilesSeam, EveryRanksEngineTilesEqualOneProcesss) {
    TempDir dir;
    const auto spec = dir.write("s.orogen", kEngineTilesSpec);
    const RunResult one = run_orogen("run " + q(spec) + " --out " + q(dir / "one") + " -q");
    ASSERT_EQ(one.exit_code, 0) << one.err;
    const RunResult many = run_mpi(GetParam().ranks,
                                   "run " + q(spec) + " --out " + q(dir / "many") +
                                       (GetParam().tiles.empty() ? "" : " --tiles " + GetParam().tiles));
    ASSERT_EQ(many.exit_code, 0) << many.err;
    // Every file one process wrote, the same bytes, and no other: png/ 6 × 4 tiles, r32/ 6 × 4 tiles and a
    // VRT each, big/ 2 × 1 tiles and a VRT each, and in each folder the index and the mosaic VRT.
    std::vector<std::string> a, b;
    for (const auto& e : fs::recursive_directory_iterator(dir / "one"))
        if (e.is_regular_file() && e.path().filename() != "manifest.json")
            a.push_back(fs::relative(e.path(), dir / "one").string());
    for (const auto& e : fs::recursive_directory_iterator(dir / "many"))
        if (e.is_regular_file() && e.path().filename() != "manifest.json")
            b.push_back(fs::relative(e.path(), dir / "many").string());
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    // glb/: the level-of-detail pyramid, 6 × 4 + 3 × 2 + 2 × 1 + 1 chunks and the tileset.
    EXPECT_EQ(a.size(), (24u + 2u) + (48u + 2u) + (4u + 2u) + (33u + 1u));
    ASSERT_EQ(a, b);
    for (const auto& f : a)
        EXPECT_TRUE(slurp(dir / "one" / f) == slurp(dir / "many" / f))
            << f << " differs on " << GetParam().ranks << " ranks";
    // The manifest of the tiled run lists every file with its SHA-256 (the other ranks' tiles with the
    // digests they took while writing, which rank 0 adopts: a digest sent for the wrong file shows here).
    const std::string manifest = slurp(dir / "many" / "manifest.json");
    for (const auto& f : b) {
        const auto at = manifest.find("\"path\": \"" + f + "\"");
        ASSERT_NE(at, std::string::npos) << f;
        const auto hash = manifest.find("\"sha256\": \"", at);
        ASSERT_NE(hash, std::string::npos) << f;
        EXPECT_EQ(manifest.substr(hash + 11, 64), orogen::sha256_file(dir / "many" / f)) << f;
    }
}
INSTANTIATE_TEST_SUITE_P(Ranks, EngineTilesSeam,
                         ::testing::Values(Case{2, ""}, Case{3, "3x1"}, Case{4, "1x4"}, Case{4, "2x2"}), kCaseName);

/// Every point array of `image` by name, as floats.
std::map<std::string, std::vector<float>> arrays_of(vtkImageData* image) {
    std::map<std::string, std::vector<float>> out;
    vtkPointData* pd = image->GetPointData();
    for (int i = 0; i < pd->GetNumberOfArrays(); ++i) {
        vtkDataArray* a = pd->GetArray(i);
        auto& v = out[a->GetName()];
        for (vtkIdType k = 0; k < a->GetNumberOfTuples(); ++k) v.push_back(float(a->GetComponent(k, 0)));
    }
    return out;
}

TEST(Mpi, PvtiPiecesFromEveryRankReadBackAsTheSingleVti) {
    TempDir dir;
    const auto spec = dir.write("s.orogen", R"(orogen 1
seed 5
grid 50x37 cell=3

f = generate:fault(iterations=200, displacement=0.5)
t = erode:thermal(f, iterations=10, hardness=height)
export:vtk(t, path="t.vti")
export:vtk-tiles(t, path="tiles/t.pvti")
export:vtk(t, path="y/t.vti", up="y")
export:vtk-tiles(t, path="ytiles/t.pvti", up="y")
)");
    const RunResult one = run_orogen("run " + q(spec) + " --out " + q(dir / "one") + " -q");
    ASSERT_EQ(one.exit_code, 0) << one.err;
    const RunResult many = run_mpi(4, "run " + q(spec) + " --out " + q(dir / "many") + " --tiles 2x2");
    ASSERT_EQ(many.exit_code, 0) << many.err;

    // Z-up (the default: X east, Y north, rows counted from the south) and Y-up (X east, Z south).
    for (const bool z_up : {true, false}) {
        SCOPED_TRACE(z_up ? "up=z" : "up=y");
        const fs::path vti = dir / "one" / (z_up ? "t.vti" : "y/t.vti");
        const fs::path tiles = dir / "many" / (z_up ? "tiles" : "ytiles");
        vtkNew<vtkXMLImageDataReader> single;
        single->SetFileName(vti.c_str());
        single->Update();
        vtkNew<vtkXMLPImageDataReader> parallel;
        parallel->SetFileName((tiles / "t.pvti").c_str());
        parallel->Update();
        vtkImageData* a = single->GetOutput();
        vtkImageData* b = parallel->GetOutput();
        int ea[6], eb[6];
        a->GetExtent(ea);
        b->GetExtent(eb);
        for (int i = 0; i < 6; ++i) EXPECT_EQ(ea[i], eb[i]) << "extent " << i;
        EXPECT_EQ(ea[1], 49);
        EXPECT_EQ(z_up ? ea[3] : ea[5], 36);
        double sa[3], sb[3], oa[3], ob[3];
        a->GetSpacing(sa);
        b->GetSpacing(sb);
        a->GetOrigin(oa);
        b->GetOrigin(ob);
        for (int i = 0; i < 3; ++i) {
            EXPECT_EQ(sa[i], sb[i]);
            EXPECT_EQ(oa[i], ob[i]);
        }
        const auto va = arrays_of(a), vb = arrays_of(b);
        ASSERT_EQ(va.size(), 3u);  // height, eroded, hardness
        ASSERT_EQ(vb.size(), va.size());
        for (const auto& [name, values] : va) {
            ASSERT_TRUE(vb.count(name)) << name;
            EXPECT_TRUE(values == vb.at(name)) << name << " differs between the .vti and the .pvti";
        }
        // Each rank wrote its own piece; pieces 0 and 1 (west, east) share a column, bit for bit.
        vtkNew<vtkXMLImageDataReader> west, east;
        west->SetFileName((tiles / "t_0.vti").c_str());
        east->SetFileName((tiles / "t_1.vti").c_str());
        west->Update();
        east->Update();
        int ew[6], ee[6];
        west->GetOutput()->GetExtent(ew);
        east->GetOutput()->GetExtent(ee);
        EXPECT_EQ(ew[1], ee[0]);  // the seam column belongs to both
        EXPECT_GT(ee[0], 0);
        const int rows = z_up ? ew[3] - ew[2] + 1 : ew[5] - ew[4] + 1;
        EXPECT_EQ(rows, z_up ? ee[3] - ee[2] + 1 : ee[5] - ee[4] + 1);
        EXPECT_GT(rows, 1);
        const auto hw = arrays_of(west->GetOutput()).at("height"), he = arrays_of(east->GetOutput()).at("height");
        const int ww = ew[1] - ew[0] + 1, we = ee[1] - ee[0] + 1;
        for (int y = 0; y < rows; ++y)
            EXPECT_EQ(hw[std::size_t(y * ww + ww - 1)], he[std::size_t(y * we)]) << "row " << y;
        // The manifest (rank 0) lists every piece with its hash.
        const std::string manifest = slurp(dir / "many" / "manifest.json");
        for (int r = 0; r < 4; ++r) {
            const std::string piece = std::string(z_up ? "tiles" : "ytiles") + "/t_" + std::to_string(r) + ".vti";
            const auto at = manifest.find("\"" + piece + "\"");
            ASSERT_NE(at, std::string::npos) << piece;
            EXPECT_NE(manifest.find(orogen::sha256_file(dir / "many" / piece), at), std::string::npos) << piece;
        }
    }
}

}  // namespace
