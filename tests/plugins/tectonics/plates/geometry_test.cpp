// Convex splitting: the fixed Listing 3.2, area conservation, the 8-vertex
// limit, and the random cuts that make the start plates.
#include "plates.hpp"
#include "polygon.hpp"

#include <orogen/random.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

using namespace orogen;
using namespace orogen::plates;

namespace {

Polygon regular(int n, double r, Point2 c = {0, 0}) {
    Polygon p;
    for (int i = 0; i < n; ++i) {
        const double a = 2.0 * std::numbers::pi * i / n;
        p.push_back({c.x + r * std::cos(a), c.y + r * std::sin(a)});
    }
    return p;
}

}  // namespace

TEST(PlatesGeometry, AreaAndCentroidOfASquare) {
    const Polygon sq = {{0, 0}, {2, 0}, {2, 2}, {0, 2}};
    EXPECT_DOUBLE_EQ(signed_area(sq), 4.0);
    EXPECT_DOUBLE_EQ(centroid(sq).x, 1.0);
    EXPECT_DOUBLE_EQ(centroid(sq).y, 1.0);
    EXPECT_TRUE(is_convex_ccw(sq));
    const Polygon cw = {{0, 0}, {0, 2}, {2, 2}, {2, 0}};
    EXPECT_FALSE(is_convex_ccw(cw));
    const Polygon dent = {{0, 0}, {2, 0}, {1, 0.5}, {2, 2}, {0, 2}};
    EXPECT_FALSE(is_convex_ccw(dent));
}

// Listing 3.2 took atan of a slope, which cannot tell a vertex at angle θ from
// one at θ + π: for a cut whose direction lies in the second quadrant its
// sort puts opposite vertices together. The cross-product side test does not.
TEST(PlatesGeometry, SplitSortsVerticesByTheCrossProductInEveryQuadrant) {
    const Polygon oct = regular(8, 5.0);
    for (int k = 0; k < 16; ++k) {
        const double a = 2.0 * std::numbers::pi * (k + 0.37) / 16;
        const Point2 d{std::cos(a), std::sin(a)};
        const Point2 p{0.3, -0.2};
        auto parts = split_convex(oct, p, d, 1e-3);
        ASSERT_TRUE(parts) << k;
        for (const Point2& v : parts->first) EXPECT_GE(side_of(p, d, v), -1e-9) << "left part, cut " << k;
        for (const Point2& v : parts->second) EXPECT_LE(side_of(p, d, v), 1e-9) << "right part, cut " << k;
        EXPECT_TRUE(is_convex_ccw(parts->first));
        EXPECT_TRUE(is_convex_ccw(parts->second));
    }
}

TEST(PlatesGeometry, EntryAndExitLieOnTheBoundaryInRayOrder) {
    const Polygon sq = {{0, 0}, {4, 0}, {4, 4}, {0, 4}};
    auto hits = line_entry_exit(sq, {2, 1}, {-1, 0});
    ASSERT_TRUE(hits);
    EXPECT_NEAR(hits->first.x, 4.0, 1e-12);  // entering from the east, moving west
    EXPECT_NEAR(hits->second.x, 0.0, 1e-12);
    EXPECT_FALSE(line_entry_exit(sq, {10, 10}, {1, 0}));
}

TEST(PlatesGeometry, SplitConservesAreaToOnePartInAMillion) {
    std::uint64_t seed = 7;
    int splits = 0;
    for (std::uint64_t i = 0; i < 2000; ++i) {
        const int n = 3 + int(random::below(6, seed, 1, i));
        Polygon poly = regular(n, random::uniform_in(0.5, 20.0, seed, 2, i),
                               {random::uniform_in(-50, 50, seed, 3, i), random::uniform_in(-50, 50, seed, 4, i)});
        const Point2 c = centroid(poly);
        const double a = random::uniform_in(0, 2 * std::numbers::pi, seed, 5, i);
        const Point2 p{c.x + random::uniform_in(-0.3, 0.3, seed, 6, i),
                       c.y + random::uniform_in(-0.3, 0.3, seed, 7, i)};
        auto parts = split_convex(poly, p, {std::cos(a), std::sin(a)}, 1e-6);
        if (!parts) continue;
        ++splits;
        const double whole = signed_area(poly);
        const double sum = signed_area(parts->first) + signed_area(parts->second);
        EXPECT_NEAR(sum, whole, 1e-6 * whole);
        EXPECT_TRUE(is_convex_ccw(parts->first));
        EXPECT_TRUE(is_convex_ccw(parts->second));
        EXPECT_LE(parts->first.size() + parts->second.size(), poly.size() + 4);
    }
    EXPECT_GT(splits, 1900);
}

TEST(PlatesGeometry, CutTooCloseToAVertexIsRefused) {
    const Polygon sq = {{0, 0}, {4, 0}, {4, 4}, {0, 4}};
    EXPECT_FALSE(split_convex(sq, {0, 0}, {1, 1}, 0.05));  // through two corners
    EXPECT_FALSE(split_convex(sq, {0.01, 0}, {1, 1}, 0.05));  // grazing a corner
    EXPECT_FALSE(split_convex(sq, {10, 10}, {1, 0}, 0.05));  // misses
    EXPECT_TRUE(split_convex(sq, {2, 2}, {1, 0.3}, 0.05));
}

TEST(PlatesGeometry, RandomPlatesTileTheAreaWithConvexPlatesOfAtMostEightVertices) {
    const Point2 size = area_size(257, 129);
    EXPECT_DOUBLE_EQ(size.x, 36.0);
    EXPECT_DOUBLE_EQ(size.y, 18.0);
    for (int count : {2, 3, 5, 12, 40, 128}) {
        for (std::uint64_t seed : {1ull, 2ull, 99ull}) {
            const auto plates = random_plates(size, count, 0.5, 1.0, seed);
            ASSERT_EQ(int(plates.size()), count);
            double total = 0.0;
            for (const PlateSpec& p : plates) {
                EXPECT_TRUE(is_convex_ccw(p.polygon));
                EXPECT_LE(p.polygon.size(), 8u);
                EXPECT_GE(p.polygon.size(), 3u);
                EXPECT_LE(std::hypot(p.velocity.x, p.velocity.y), 1.0);
                EXPECT_TRUE(p.density == std::clamp(p.density, oceanic_density - 0.02, oceanic_density + 0.02) ||
                            p.density == std::clamp(p.density, continental_density - 0.02, continental_density + 0.02));
                total += signed_area(p.polygon);
            }
            EXPECT_NEAR(total, size.x * size.y, 1e-9 * size.x * size.y) << count << " plates, seed " << seed;
        }
    }
}

TEST(PlatesGeometry, RandomPlatesAreAFunctionOfTheSeed) {
    const auto a = random_plates({36, 36}, 12, 0.5, 1.0, 5);
    const auto b = random_plates({36, 36}, 12, 0.5, 1.0, 5);
    const auto c = random_plates({36, 36}, 12, 0.5, 1.0, 6);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a[i].polygon, b[i].polygon);
        EXPECT_EQ(a[i].density, b[i].density);
    }
    EXPECT_NE(a[0].polygon, c[0].polygon);
}

TEST(PlatesGeometry, MaxPlatesLeavesEachPlateSixteenBySixteenSamples) {
    EXPECT_EQ(max_plates(65, 65), 16);
    EXPECT_EQ(max_plates(17, 17), 1);
    EXPECT_EQ(max_plates(1025, 1025), 256);
}

TEST(PlatesGeometry, ConvexFillCoversExactlyTheInside) {
    std::vector<float> data(20 * 20, 0.0f);
    GridView g{data.data(), 20, 20, 1.0};
    const Polygon tri = {{2, 2}, {17, 2}, {2, 17}};
    fill_polygon(g, tri, 5.0f);
    for (int y = 0; y < 20; ++y)
        for (int x = 0; x < 20; ++x) {
            const bool inside = x >= 2 && y >= 2 && x + y <= 19;
            EXPECT_EQ(g.at(x, y), inside ? 5.0f : 0.0f) << x << "," << y;
        }
}
