// The realism regression on the classifier (issue 50, docs/analysis.md "Telling windows apart"): the default
// pipeline's terrain, as `make demo` makes it, on two seeds, against the four 27–30 m reference DEMs shipped in
// data/dems/, cut into 3.84 km windows and told apart by orogen::analysis::discriminate (XGBoost, leaving one
// source out). Its balanced accuracy must not rise above kBound: a change that makes the terrain easier to
// tell from real ranges fails here. The bound only ever goes down, towards the 60 %.
#include <orogen/analysis/discriminate.hpp>

#include <gdal.h>
#include <gtest/gtest.h>

#include "shipped_dem.hpp"

#include "orogen_test.hpp"

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

using namespace orogen::test;
namespace fs = std::filesystem;

namespace {

/// Measured when this test was written (issue 50): seeds 42 and 1 of the default against the Baspa, the Rif, the
/// Kahurangi and the Raukumara, 3.84 km windows, 284 of them: real windows called real 86.5 %, generated called
/// generated 97.7 %. The bound leaves 4 points (about ten windows) for a change of seed-level detail. Lower both
/// when the terrain gets harder to tell apart; never raise them.
constexpr double kMeasured = 0.9210;
constexpr double kBound = kMeasured + 0.04;

struct Dem {
    std::string name;
    std::vector<float> z;
    int width = 0, height = 0;
    double cell = 0.0;
};

Dem read_dem(const std::string& name) {
    ShippedDem shipped = read_shipped_dem(name);
    return {name, std::move(shipped.z), shipped.width, shipped.height, shipped.cell};
}

TEST(Discriminate, TheDefaultPipelineIsNoEasierToTellFromRealRanges) {
    std::vector<Dem> dems;
    for (const int seed : {42, 1}) {
        TempDir dir;
        const fs::path spec = fs::path(OROGEN_SOURCE_DIR) / "pipelines" / "default.orogen";
        const RunResult r =
            run_orogen("run " + q(spec) + " --quiet --out " + q(dir.path()) + " --seed " + std::to_string(seed) +
                       " --set beauty.width=160 --set beauty.height=90 --set beauty.samples=1"
                       " --set spin.frames=2 --set spin.width=64 --set spin.height=36");
        ASSERT_EQ(r.exit_code, 0) << r.err;
        const std::string raw = slurp(dir / "terrain.r32");
        constexpr int side = 1025;
        ASSERT_EQ(raw.size(), std::size_t(side) * side * sizeof(float));
        Dem d{"default seed " + std::to_string(seed), std::vector<float>(std::size_t(side) * side), side, side, 30.0};
        std::memcpy(d.z.data(), raw.data(), raw.size());
        dems.push_back(std::move(d));
    }
    for (const char* name : {"himalaya_baspa_30m", "morocco_rif_27m", "nz_kahurangi_30m", "nz_raukumara_30m"}) {
        dems.push_back(read_dem(name));
        ASSERT_GT(dems.back().width, 0) << "data/dems/" << name << ".tif";
    }
    std::vector<orogen::analysis::Source> sources;
    for (std::size_t i = 0; i < dems.size(); ++i)
        sources.push_back({dems[i].name, {dems[i].z.data(), dems[i].width, dems[i].height, dems[i].cell}, i >= 2});
    const auto d = orogen::analysis::discriminate(sources);
    std::printf("balanced accuracy %.4f (real called real %.3f, generated called generated %.3f)\n",
                d.balanced_accuracy, d.recall_real, d.recall_generated);
    for (const auto& s : d.sources)
        std::printf("  %-20s %3zu windows, %5.1f %% called real\n", s.name.c_str(), s.windows, 100.0 * s.called_real);
    for (std::size_t i = 0; i < 5; ++i) {
        const auto& imp = d.importance[i];
        std::printf("  %-22s gain %4.1f %%  real %.3g  generated %.3g\n",
                    std::string(orogen::analysis::window_figure_table()[std::size_t(imp.figure)].key).c_str(),
                    100.0 * imp.share, imp.median_real, imp.median_generated);
    }
    testing::Test::RecordProperty("balanced_accuracy", std::to_string(d.balanced_accuracy));
    EXPECT_LE(d.balanced_accuracy, kBound) << "the default pipeline's terrain got easier to tell from real ranges";
}

}  // namespace
