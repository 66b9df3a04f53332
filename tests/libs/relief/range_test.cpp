// raise_range: the band of cells between two points.
#include <orogen/relief/range.hpp>
#include <orogen/relief/voronoi.hpp>

#include <orogen/error.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <vector>

using namespace orogen;
using namespace orogen::relief;

namespace {

struct Grid {
    int w, h;
    std::vector<float> data;
    Grid(int w_, int h_) : w(w_), h(h_), data(std::size_t(w_) * h_, 0.0f) {}
    GridView view() { return {data.data(), w, h, 1.0}; }
};

// Number of 8-connected components of the vertices where mask is true.
int components(const std::vector<bool>& mask, int w, int h) {
    std::vector<int> comp(mask.size(), -1);
    int n = 0;
    for (std::size_t start = 0; start < mask.size(); ++start) {
        if (!mask[start] || comp[start] >= 0) continue;
        std::vector<std::size_t> stack{start};
        comp[start] = n;
        while (!stack.empty()) {
            const std::size_t i = stack.back();
            stack.pop_back();
            const int x = int(i % w), y = int(i / w);
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int nx = x + dx, ny = y + dy;
                    if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
                    const std::size_t j = std::size_t(ny) * w + nx;
                    if (mask[j] && comp[j] < 0) {
                        comp[j] = n;
                        stack.push_back(j);
                    }
                }
        }
        ++n;
    }
    return n;
}

}  // namespace

TEST(RmpRange, RaisesAConnectedBandOfWholeCellsContainingTheSegment) {
    for (std::uint64_t seed = 1; seed <= 12; ++seed) {
        Grid g(129, 97);
        const Point2 a{10.3, 20.7}, b{115.2, 80.1};
        RangeParams p;
        p.cones = 150;
        p.height = 2.5;
        const int raised = raise_range(g.view(), a, b, p, seed);
        ASSERT_GT(raised, 0);

        const auto sites = random_sites(p.cones, g.w, g.h, seed);
        const SiteIndex index(sites, g.w, g.h);
        const auto labels = label_grid(index);
        std::set<int> cells;
        std::vector<bool> mask(g.data.size());
        for (std::size_t i = 0; i < g.data.size(); ++i) {
            // jitter 0: exactly `height` or nothing, and whole cells only.
            ASSERT_TRUE(g.data[i] == 0.0f || g.data[i] == 2.5f) << g.data[i];
            mask[i] = g.data[i] > 0;
            if (mask[i]) cells.insert(labels[i]);
        }
        EXPECT_EQ(int(cells.size()), raised);
        for (std::size_t i = 0; i < g.data.size(); ++i) EXPECT_EQ(mask[i], cells.count(labels[i]) == 1);
        // The continuous segment: every point of it lies in a raised cell.
        for (int k = 0; k <= 4000; ++k) {
            const double t = k / 4000.0;
            const int s = index.nearest(a.x + t * (b.x - a.x), a.y + t * (b.y - a.y));
            ASSERT_TRUE(cells.count(s)) << "seed " << seed << " t " << t;
        }
        // The raster line: every Bresenham vertex raised.
        EXPECT_GT(g.data[std::size_t(21) * g.w + 10], 0.0f);
        EXPECT_GT(g.data[std::size_t(80) * g.w + 115], 0.0f);
        EXPECT_EQ(components(mask, g.w, g.h), 1) << "seed " << seed;
        // A proper subset of the map (the thesis's read-back bug raised everything).
        EXPECT_LT(std::count(mask.begin(), mask.end(), true), long(mask.size()));
    }
}

TEST(RmpRange, UpliftGetsTheSameAmountsAndJitterVariesCells) {
    Grid g(100, 80), u(100, 80), again(100, 80);
    RangeParams p;
    p.cones = 60;
    p.height = 3.0;
    p.jitter = 0.5;
    GridView uv = u.view();
    const int n = raise_range(g.view(), {5, 5}, {90, 70}, p, 77, &uv);
    EXPECT_EQ(g.data, u.data);
    EXPECT_EQ(raise_range(again.view(), {5, 5}, {90, 70}, p, 77), n);
    EXPECT_EQ(g.data, again.data);  // same seed, same bytes
    std::set<float> amounts;
    for (float v : g.data)
        if (v != 0) {
            amounts.insert(v);
            EXPECT_GE(v, 1.5f);
            EXPECT_LT(v, 4.5f);
        }
    EXPECT_GT(amounts.size(), 2u);
}

TEST(RmpRange, EndpointsAreClampedAndOnePointRaisesOneCell) {
    Grid g(50, 50);
    RangeParams p;
    p.cones = 30;
    EXPECT_EQ(raise_range(g.view(), {25, 25}, {25, 25}, p, 5), 1);
    Grid h(50, 50);
    EXPECT_GT(raise_range(h.view(), {-100, 25}, {500, 25}, p, 5), 1);
    EXPECT_GT(h.data[25 * 50 + 0], 0.0f);
    EXPECT_GT(h.data[25 * 50 + 49], 0.0f);
}

TEST(RmpRange, RejectsZeroCones) {
    Grid g(10, 10);
    RangeParams p;
    p.cones = 0;
    try {
        raise_range(g.view(), {1, 1}, {5, 5}, p, 1);
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(e.kind(), Error::Kind::bad_input);
        EXPECT_STREQ(e.what(), "range: cones must be at least 1 (got 0)");
    }
}
