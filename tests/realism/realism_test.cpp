// The default pipeline's terrain against real mountain ranges (docs/realism.md).
//
// `make demo` at 30 m, on its own seed and on five others, measured with
// orogen::analysis (the figures of `orogen analyze`), must lie inside the band
// the four 27–30 m reference DEMs of ../shared/realism span on every figure
// that tells real terrain from generated terrain apart: the slope
// distribution, the hypsometric integral, the spectral exponent, pits and the
// channel concavity. The bands are the references' figures as
// `orogen analyze` measures them (docs/realism.md's table; the DEMs' sources
// and licences are in ../shared/realism/README.md). Terrain that drifts out of
// a band (a default changed, a process that roughens or steepens) fails here.
#include <orogen/analysis/figures.hpp>

#include <gtest/gtest.h>

#include "orogen_test.hpp"

#include <cstring>
#include <string>
#include <vector>

using namespace orogen::test;
using orogen::analysis::FigureId;
namespace fs = std::filesystem;

namespace {

struct Band {
    FigureId figure;
    double low, high;  ///< min and max over Baspa (Himalaya), Rif, Kahurangi and Raukumara, 27–30 m
};

// `orogen analyze` on the four 27–30 m DEMs of ../shared/realism/dems (docs/realism.md).
const Band kBands[] = {
    {FigureId::slope_median, 19.2, 31.7},           // °
    {FigureId::slope_p90, 29.2, 46.9},              // °
    {FigureId::steeper_40, 0.2, 24.0},              // % of the area
    {FigureId::hypsometric_integral, 0.367, 0.540},
    {FigureId::spectral_exponent, 4.27, 4.73},
    {FigureId::pits, 0.02, 0.14},                   // % of the interior samples
    {FigureId::concavity, 0.49, 1.07},
};

class DefaultPipeline : public testing::TestWithParam<int> {};

TEST_P(DefaultPipeline, LiesInsideRealRangesFiguresAtThirtyMetres) {
    const int seed = GetParam();
    TempDir dir;
    const fs::path spec = fs::path(OROGEN_SOURCE_DIR) / "pipelines" / "default.orogen";
    // The terrain exactly as `make demo` makes it; only the pictures are made smaller.
    const RunResult r = run_orogen("run " + q(spec) + " --quiet --seed " + std::to_string(seed) + " --out " +
                                   q(dir.path()) +
                                   " --set beauty.width=160 --set beauty.height=90 --set beauty.samples=1"
                                   " --set spin.frames=2 --set spin.width=64 --set spin.height=36");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string raw = slurp(dir / "terrain.r32");
    const int n = 1025;
    ASSERT_EQ(raw.size(), std::size_t(n) * n * sizeof(float));
    std::vector<float> h(std::size_t(n) * n);
    std::memcpy(h.data(), raw.data(), raw.size());
    const auto figures = orogen::analysis::measure({h.data(), n, n, 30.0});
    for (const Band& b : kBands) {
        const auto& info = orogen::analysis::info(b.figure);
        const double v = figures[b.figure].value;
        RecordProperty(std::string(info.key), std::to_string(v));
        EXPECT_GE(v, b.low) << info.key << " (seed " << seed << ")";
        EXPECT_LE(v, b.high) << info.key << " (seed " << seed << ")";
    }
}

INSTANTIATE_TEST_SUITE_P(Seeds, DefaultPipeline, testing::Values(42, 1, 2, 3, 4, 5),
                         [](const auto& info) { return "seed" + std::to_string(info.param); });

}  // namespace
