// Diamond-Square properties: any size, determinism, seed sensitivity, what
// roughness and amplitude do.
#include "diamond_square.hpp"

#include <orogen/values.hpp>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstring>

using namespace orogen;

namespace {
Heightmap make(int w, int h, double amplitude, double roughness, std::uint64_t seed) {
    Heightmap hm(w, h, 1.0, std::nanf(""));  // NaN: any vertex left unset shows up
    diamond_square::generate(hm.view(), {amplitude, roughness}, seed);
    return hm;
}

/// Share of the variance in the finest scales: mean squared difference from the
/// 3×3 box average, over the variance.
double high_frequency_share(const Heightmap& hm) {
    double mean = 0;
    for (float v : hm.heights()) mean += v;
    mean /= double(hm.size());
    double var = 0, hf = 0;
    for (float v : hm.heights()) var += (v - mean) * (v - mean);
    const auto g = hm.view();
    for (int y = 1; y < g.height - 1; ++y)
        for (int x = 1; x < g.width - 1; ++x) {
            double box = 0;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) box += g.at(x + dx, y + dy);
            const double d = g.at(x, y) - box / 9.0;
            hf += d * d;
        }
    return hf / var;
}
}  // namespace

TEST(DiamondSquare, FillsEveryVertexOfAnyGridSize) {
    for (auto [w, h] :
         {std::pair{2, 2}, {3, 3}, {5, 5}, {65, 65}, {100, 37}, {37, 100}, {513, 257}, {2, 300}, {1, 7}}) {
        const Heightmap hm = make(w, h, 100.0, 0.5, 1);
        for (float v : hm.heights()) ASSERT_TRUE(std::isfinite(v)) << w << "x" << h;
        if (w * h > 4) {
            float lo = hm.heights()[0], hi = lo;
            for (float v : hm.heights()) lo = std::min(lo, v), hi = std::max(hi, v);
            EXPECT_GT(hi - lo, 1.0f) << w << "x" << h;
        }
    }
}

TEST(DiamondSquare, TheCentreOfThreeByThreeIsTheCornerAverageWithinOneOffset) {
    for (std::uint64_t seed = 0; seed < 50; ++seed) {
        const Heightmap hm = make(3, 3, 10.0, 0.5, seed);
        const auto g = hm.view();
        for (int c : {0, 2})
            for (int r : {0, 2}) EXPECT_LE(std::fabs(g.at(c, r)), 10.0f);
        const float avg = 0.25f * (g.at(0, 0) + g.at(2, 0) + g.at(0, 2) + g.at(2, 2));
        EXPECT_LE(std::fabs(g.at(1, 1) - avg), 5.0f);  // amplitude · roughness
    }
}

TEST(DiamondSquare, IsDeterministicAndSeedSensitive) {
    const Heightmap a = make(129, 129, 50, 0.6, 7);
    const Heightmap b = make(129, 129, 50, 0.6, 7);
    const Heightmap c = make(129, 129, 50, 0.6, 8);
    EXPECT_EQ(a.heights(), b.heights());
    std::size_t same = 0;
    for (std::size_t i = 0; i < a.size(); ++i) same += a.heights()[i] == c.heights()[i];
    EXPECT_LT(same, a.size() / 100);
}

TEST(DiamondSquare, GivesTheSameBytesOnOneAndTwoThreads) {
    std::vector<float> one, two;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        one = make(1025, 513, 100, 0.55, 3).heights();
    }
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        two = make(1025, 513, 100, 0.55, 3).heights();
    }
    EXPECT_EQ(one, two);
}

TEST(DiamondSquare, RoughnessRaisesHighFrequencyEnergy) {
    for (std::uint64_t seed = 0; seed < 5; ++seed) {
        const double smooth = high_frequency_share(make(257, 257, 100, 0.4, seed));
        const double mid = high_frequency_share(make(257, 257, 100, 0.55, seed));
        const double rough = high_frequency_share(make(257, 257, 100, 0.7, seed));
        EXPECT_LT(smooth, mid) << "seed " << seed;
        EXPECT_LT(mid, rough) << "seed " << seed;
    }
}

TEST(DiamondSquare, AmplitudeScalesTheSurfaceExactly) {
    const Heightmap a = make(65, 33, 10.0, 0.5, 4);
    const Heightmap b = make(65, 33, 20.0, 0.5, 4);
    for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(2.0f * a.heights()[i], b.heights()[i]);
}

// A tiled run's tiles (generate_tile: each rank its own, every level computed
// only near the tile) must be the whole grid's bits: any size, any cut, tiles
// down to one vertex, at the grid's edges and corners and inside.
TEST(DiamondSquare, EveryTileEqualsTheWholeGridsVertices) {
    const int sizes[][2] = {{1, 1}, {2, 3}, {5, 5}, {17, 9}, {33, 33}, {65, 40}, {97, 61}, {130, 7}};
    for (const auto& [w, h] : sizes) {
        const Heightmap whole = make(w, h, 50.0, 0.55, 9);
        // Cuts into 1, 2, 3 and 5 parts a side (as split_grid cuts: floor(k·size/parts)), and 1-vertex tiles.
        for (const int parts : {1, 2, 3, 5, 1000}) {
            const int cols = std::min(parts, w), rows = std::min(parts, h);
            for (int r = 0; r < rows; ++r)
                for (int c = 0; c < cols; ++c) {
                    const int x0 = c * w / cols, x1 = (c + 1) * w / cols, y0 = r * h / rows, y1 = (r + 1) * h / rows;
                    Heightmap tile(x1 - x0, y1 - y0, 1.0, std::nanf(""));
                    diamond_square::generate_tile(tile.view(), x0, y0, w, h, {50.0, 0.55}, 9);
                    for (int y = y0; y < y1; ++y)
                        for (int x = x0; x < x1; ++x) {
                            const float a = whole.view().at(x, y), b = tile.view().at(x - x0, y - y0);
                            ASSERT_EQ(std::memcmp(&a, &b, sizeof a), 0)
                                << w << "x" << h << ", tile at (" << x0 << ", " << y0 << "), vertex (" << x << ", " << y
                                << "): " << a << " vs " << b;
                        }
                }
        }
    }
}
