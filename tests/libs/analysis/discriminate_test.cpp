// orogen::analysis::discriminate (docs/analysis.md, "Telling windows apart") on cases with known answers,
// over the reference DEMs shipped in data/dems/: two halves of one real DEM are not told apart, white noise
// is told apart at once, a copy smoothed over 3 cells is told apart; and the window figures on surfaces whose
// figures are known.
#include <orogen/analysis/discriminate.hpp>

#include <gdal.h>
#include <gtest/gtest.h>

#include "shipped_dem.hpp"
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <vector>

namespace {

using namespace orogen::analysis;
namespace fs = std::filesystem;

struct Dem {
    std::vector<float> z;
    int width = 0, height = 0;
    double cell = 0.0;
    Grid grid() const { return {z.data(), width, height, cell}; }
    /// The block of `w` × `h` samples whose top-left sample is (x0, y0), as its own DEM.
    Dem crop(int x0, int y0, int w, int h) const {
        Dem d{{}, w, h, cell};
        for (int y = y0; y < y0 + h; ++y)
            d.z.insert(d.z.end(), z.begin() + std::ptrdiff_t(y) * width + x0,
                       z.begin() + std::ptrdiff_t(y) * width + x0 + w);
        return d;
    }
};

Dem read_dem(const std::string& name) {
    orogen::test::ShippedDem shipped = orogen::test::read_shipped_dem(name);
    Dem dem;
    dem.z = std::move(shipped.z);
    dem.width = shipped.width, dem.height = shipped.height, dem.cell = shipped.cell;
    return dem;
}

/// A 3 × 3 box mean (edges: the samples inside).
Dem smoothed(const Dem& d) {
    Dem s = d;
    for (int y = 0; y < d.height; ++y)
        for (int x = 0; x < d.width; ++x) {
            double sum = 0.0;
            int n = 0;
            for (int v = std::max(0, y - 1); v <= std::min(d.height - 1, y + 1); ++v)
                for (int u = std::max(0, x - 1); u <= std::min(d.width - 1, x + 1); ++u)
                    sum += d.z[std::size_t(v) * std::size_t(d.width) + std::size_t(u)], ++n;
            s.z[std::size_t(y) * std::size_t(d.width) + std::size_t(x)] = float(sum / n);
        }
    return s;
}

/// Uniform white noise of ±amplitude from a fixed hash (no std distributions: the same bits everywhere).
Dem white_noise(int side, double cell, double amplitude, std::uint64_t seed) {
    Dem d{{}, side, side, cell};
    std::uint64_t state = seed;
    for (int i = 0; i < side * side; ++i) {
        state += 0x9E3779B97F4A7C15ull;  // splitmix64
        std::uint64_t z = state;
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        z ^= z >> 31;
        d.z.push_back(float(amplitude * (2.0 * double(z >> 11) / double(1ull << 53) - 1.0)));
    }
    return d;
}

class Discriminate : public testing::Test {
protected:
    void SetUp() override {
        baspa = read_dem("himalaya_baspa_30m");
        ASSERT_EQ(baspa.width, 1000) << "data/dems/himalaya_baspa_30m.tif";
    }
    Dem baspa;
    DiscriminateOptions options = [] {
        DiscriminateOptions o;
        o.window_m = 64 * 30.0;  // 64 cells: 9 windows in each 250² block, 7 × 15 in each half
        return o;
    }();
};

TEST_F(Discriminate, TwoHalvesOfOneRealDemAreNotToldApart) {
    // The Baspa's west half against its east half, each cut into eight 250² blocks, each block a source: leaving
    // one out leaves seven of its kind to learn from. (With only two sources a kind, leaving one out is biased
    // below 50 % for terrains nothing tells apart: the one left of its kind covers less of the figures' space
    // than the two of the other kind, so the held-out source is called the other kind more often. Its two
    // quarters against the other two score 28 %; docs/analysis.md.)
    std::vector<Dem> blocks;
    std::vector<Source> sources;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) blocks.push_back(baspa.crop(250 * i, 250 * j, 250, 250));
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i)
            sources.push_back(
                {"block " + std::to_string(i) + "," + std::to_string(j), blocks[std::size_t(4 * j + i)].grid(), i < 2});
    const auto d = discriminate(sources, options);
    ASSERT_EQ(d.windows.size(), 16u * 9u);
    std::printf("two halves of the Baspa: balanced accuracy %.3f\n", d.balanced_accuracy);
    EXPECT_GE(d.balanced_accuracy, 0.35);
    EXPECT_LE(d.balanced_accuracy, 0.65);
}

TEST_F(Discriminate, WhiteNoiseIsToldApartAtOnce) {
    const Dem west = baspa.crop(0, 0, 500, 1000), east = baspa.crop(500, 0, 500, 1000);
    const Dem a = white_noise(500, 30.0, 200.0, 1), b = white_noise(500, 30.0, 200.0, 2);
    const auto d = discriminate({{"west", west.grid(), true},
                                 {"east", east.grid(), true},
                                 {"noise1", a.grid(), false},
                                 {"noise2", b.grid(), false}},
                                options);
    std::printf("white noise against the Baspa: balanced accuracy %.3f\n", d.balanced_accuracy);
    EXPECT_GE(d.balanced_accuracy, 0.95);
    for (const auto& s : d.sources) EXPECT_NEAR(s.called_real, s.real ? 1.0 : 0.0, 0.1) << s.name;
}

TEST_F(Discriminate, ACopySmoothedOverThreeCellsIsToldApart) {
    const Dem west = baspa.crop(0, 0, 500, 1000), east = baspa.crop(500, 0, 500, 1000);
    const Dem west_smooth = smoothed(west), east_smooth = smoothed(east);
    const auto d = discriminate({{"west", west.grid(), true},
                                 {"east", east.grid(), true},
                                 {"west smoothed", west_smooth.grid(), false},
                                 {"east smoothed", east_smooth.grid(), false}},
                                options);
    std::printf("the Baspa against its 3x3 mean: balanced accuracy %.3f, most telling %s\n", d.balanced_accuracy,
                std::string(window_figure_table()[std::size_t(d.importance.front().figure)].key).c_str());
    EXPECT_GE(d.balanced_accuracy, 0.85);
}

TEST_F(Discriminate, IsTheSameOnOneThreadOrTwoAndReportsEveryFigure) {
    const Dem west = baspa.crop(0, 0, 500, 1000), east = baspa.crop(500, 0, 500, 1000);
    const Dem a = smoothed(west), b = smoothed(east);
    const std::vector<Source> sources = {
        {"west", west.grid(), true}, {"east", east.grid(), true}, {"a", a.grid(), false}, {"b", b.grid(), false}};
    // Once on one thread, once on two: the same bits (XGBoost runs on one thread whatever the pool).
    auto run = [&](int threads) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
        return discriminate(sources, options);
    };
    const auto one = run(1), two = run(2);
    ASSERT_EQ(one.windows.size(), two.windows.size());
    for (std::size_t k = 0; k < one.windows.size(); ++k) EXPECT_EQ(one.windows[k].p_real, two.windows[k].p_real);
    EXPECT_EQ(one.balanced_accuracy, two.balanced_accuracy);
    ASSERT_EQ(one.importance.size(), window_figure_count);
    for (std::size_t i = 1; i < one.importance.size(); ++i)
        EXPECT_GE(one.importance[i - 1].gain, one.importance[i].gain);
    EXPECT_EQ(one.window_cells, 64);
    EXPECT_EQ(one.sources.size(), 4u);
}

TEST_F(Discriminate, SkipsWindowsWithHoles) {
    // The north half of one source is nodata: only its windows wholly south of row 500 are measured (rows of
    // windows start at row 20, 64 apart: the eighth and after), 7 of 15 rows of 7.
    const Dem west = baspa.crop(0, 0, 500, 1000), east = baspa.crop(500, 0, 500, 1000);
    const Dem a = smoothed(west), b = smoothed(east);
    std::vector<std::uint8_t> valid(a.z.size(), 1);
    std::fill(valid.begin(), valid.begin() + 500 * 500, std::uint8_t(0));
    Grid holed = a.grid();
    holed.valid = valid.data();
    const auto d = discriminate(
        {{"west", west.grid(), true}, {"east", east.grid(), true}, {"a", holed, false}, {"b", b.grid(), false}},
        options);
    EXPECT_EQ(d.sources[0].windows, 105u);
    EXPECT_EQ(d.sources[2].windows, 49u);
    for (const auto& w : d.windows)
        if (w.source == 2) EXPECT_GE(w.y, 500);
}

TEST(DiscriminateChecks, SayWhatIsWrongAndHowToFixIt) {
    const Dem a = white_noise(200, 30.0, 10.0, 1), b = white_noise(200, 30.0, 10.0, 2);
    const Dem coarse = white_noise(200, 90.0, 10.0, 3), small = white_noise(100, 30.0, 10.0, 4);
    DiscriminateOptions o;
    EXPECT_EQ(check_sources(
                  {{"a", a.grid(), true}, {"b", b.grid(), true}, {"c", a.grid(), false}, {"d", b.grid(), false}}, o),
              "");
    // The 27 m Rif goes with 30 m ranges, in any order; 35 m cells do not.
    const Dem rif_like = white_noise(200, 27.0, 10.0, 5), coarser = white_noise(200, 35.0, 10.0, 6);
    EXPECT_EQ(
        check_sources(
            {{"r", rif_like.grid(), true}, {"b", b.grid(), true}, {"c", a.grid(), false}, {"d", b.grid(), false}}, o),
        "");
    EXPECT_NE(
        check_sources(
            {{"a", a.grid(), true}, {"b", b.grid(), true}, {"c", coarser.grid(), false}, {"d", b.grid(), false}}, o),
        "");
    const std::string one_real =
        check_sources({{"a", a.grid(), true}, {"c", a.grid(), false}, {"d", b.grid(), false}}, o);
    EXPECT_NE(one_real.find("at least two real"), std::string::npos) << one_real;
    const std::string cells = check_sources(
        {{"a", a.grid(), true}, {"b", b.grid(), true}, {"coarse", coarse.grid(), false}, {"d", b.grid(), false}}, o);
    EXPECT_NE(cells.find("coarse has 90 m cells and a 30 m"), std::string::npos) << cells;
    EXPECT_NE(cells.find("gdalwarp -tr 90 90"), std::string::npos) << cells;
    const std::string too_small = check_sources(
        {{"a", a.grid(), true}, {"b", b.grid(), true}, {"small", small.grid(), false}, {"d", b.grid(), false}}, o);
    EXPECT_NE(too_small.find("small (100x100 samples of 30 m) is smaller than one window"), std::string::npos)
        << too_small;
    EXPECT_NE(too_small.find("--window-m 3000 or less"), std::string::npos) << too_small;
    EXPECT_THROW(discriminate({{"a", a.grid(), true}}, o), std::invalid_argument);
}

TEST(WindowFigures, APlaneAndWhiteNoiseMeasureAsTheyShould) {
    // A plane rising 1 in 2 eastwards: every slope atan 0.5, no curvature, roughness ratio 1 (σ grows as h).
    const int n = 64;
    std::vector<float> plane(std::size_t(n) * n);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) plane[std::size_t(y) * n + x] = float(0.5 * 30.0 * x);
    const auto f = measure_window({plane.data(), n, n, 30.0});
    const double degrees = std::atan(0.5) * 180.0 / 3.14159265358979323846;
    EXPECT_NEAR(f[std::size_t(WindowFigureId::slope_p10)], degrees, 1e-6);
    EXPECT_NEAR(f[std::size_t(WindowFigureId::slope_p90)], degrees, 1e-6);
    EXPECT_NEAR(f[std::size_t(WindowFigureId::slope_spread)], 0.0, 1e-9);
    EXPECT_NEAR(f[std::size_t(WindowFigureId::curvature_spread)], 0.0, 1e-6);
    EXPECT_NEAR(f[std::size_t(WindowFigureId::roughness_ratio)], 1.0, 1e-9);
    EXPECT_NEAR(f[std::size_t(WindowFigureId::orientation_coherence)], 1.0, 1e-9);
    EXPECT_NEAR(f[std::size_t(WindowFigureId::elevation_skew)], 0.0, 1e-6);
    // White noise: σ is the same at every lag, slopes face every way, no spectral slope.
    const Dem noise = white_noise(n, 30.0, 100.0, 7);
    const auto g = measure_window(noise.grid());
    EXPECT_NEAR(g[std::size_t(WindowFigureId::roughness_ratio)], 0.0, 0.05);
    EXPECT_LT(g[std::size_t(WindowFigureId::orientation_coherence)], 0.4);
    EXPECT_NEAR(g[std::size_t(WindowFigureId::spectral_exponent)], 0.0, 0.5);
    EXPECT_NEAR(g[std::size_t(WindowFigureId::convex_share)], 50.0, 5.0);
}

}  // namespace
