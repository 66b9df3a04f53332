// The exact Voronoi index: nearest-site queries against brute force, cells
// as row spans that tile the grid, the covering radius bound.
#include <orogen/relief/voronoi.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace orogen;
using namespace orogen::relief;

namespace {

int brute_nearest(std::span<const Point2> sites, double x, double y) {
    int best = -1;
    double bd = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < sites.size(); ++i) {
        const double d = (sites[i].x - x) * (sites[i].x - x) + (sites[i].y - y) * (sites[i].y - y);
        if (d < bd) {
            bd = d;
            best = int(i);
        }
    }
    return best;
}

}  // namespace

TEST(RmpVoronoi, SitesAreDeterministicAndInsideTheGrid) {
    const auto a = random_sites(500, 65, 33, 7);
    const auto b = random_sites(500, 65, 33, 7);
    const auto c = random_sites(500, 65, 33, 8);
    ASSERT_EQ(a.size(), 500u);
    EXPECT_EQ(a, b);
    EXPECT_NE(a, c);
    for (const Point2& p : a) {
        EXPECT_GE(p.x, 0.0);
        EXPECT_LT(p.x, 64.0);
        EXPECT_GE(p.y, 0.0);
        EXPECT_LT(p.y, 32.0);
    }
}

TEST(RmpVoronoi, NearestMatchesBruteForce) {
    for (int count : {1, 2, 7, 100, 3000}) {
        const auto sites = random_sites(count, 97, 61, 100 + count);
        const SiteIndex index(sites, 97, 61);
        for (int y = 0; y < 61; y += 3)
            for (int x = 0; x < 97; x += 2) ASSERT_EQ(index.nearest(x, y), brute_nearest(sites, x, y)) << count;
    }
}

TEST(RmpVoronoi, TiesGoToTheLowestSiteIndex) {
    // Vertex column x = 3 is equidistant from both sites.
    const std::vector<Point2> sites{{4, 2}, {2, 2}, {3, 2}};
    const SiteIndex index(std::span<const Point2>(sites).first(2), 7, 5);
    for (int y = 0; y < 5; ++y) {
        EXPECT_EQ(index.nearest(3, y), 0);
        EXPECT_EQ(index.nearest(2, y), 1);
    }
    const SiteIndex swapped(std::span<const Point2>(sites).subspan(1, 1), 7, 5);
    EXPECT_EQ(swapped.nearest(3, 0), 0);
}

TEST(RmpVoronoi, CellSpansTileTheGridExactly) {
    for (int count : {1, 5, 16, 300, 2000}) {
        const int w = 129, h = 71;
        const auto sites = random_sites(count, w, h, 42 + count);
        const SiteIndex index(sites, w, h);
        const auto labels = label_grid(index);
        std::vector<int> owner(std::size_t(w) * h, -1);
        for (int s = 0; s < count; ++s) {
            int last_y = -1;
            index.for_each_span(s, [&](int y, int x0, int x1) {
                EXPECT_GT(y, last_y);
                last_y = y;
                ASSERT_LE(x0, x1);
                for (int x = x0; x <= x1; ++x) {
                    auto& o = owner[std::size_t(y) * w + x];
                    EXPECT_EQ(o, -1) << "vertex in two cells";
                    o = s;
                }
            });
        }
        for (std::size_t i = 0; i < owner.size(); ++i) {
            ASSERT_EQ(owner[i], labels[i]) << "count " << count << " vertex " << i;
            ASSERT_EQ(labels[i], brute_nearest(sites, double(i % w), double(i / w)));
        }
    }
}

TEST(RmpVoronoi, CellPolygonIsConvexAndHoldsItsSite) {
    const auto sites = random_sites(200, 101, 101, 3);
    const SiteIndex index(sites, 101, 101);
    double total = 0;
    for (int s = 0; s < 200; ++s) {
        const CellPolygon c = index.cell(s);
        ASSERT_GE(c.vertices.size(), 3u);
        ASSERT_EQ(c.vertices.size(), c.edge_site.size());
        double area = 0;
        const std::size_t n = c.vertices.size();
        for (std::size_t k = 0; k < n; ++k) {
            const Point2 &p = c.vertices[k], &q = c.vertices[(k + 1) % n], &r = c.vertices[(k + 2) % n];
            area += p.x * q.y - q.x * p.y;
            EXPECT_GE((q.x - p.x) * (r.y - q.y) - (q.y - p.y) * (r.x - q.x), -1e-9) << "not convex";
            EXPECT_GE((q.x - p.x) * (sites[s].y - p.y) - (q.y - p.y) * (sites[s].x - p.x), -1e-9);
            // An edge made by site t lies on the bisector of s and t.
            if (c.edge_site[k] >= 0) {
                const Point2& t = sites[std::size_t(c.edge_site[k])];
                const double ds = std::hypot(p.x - sites[s].x, p.y - sites[s].y);
                const double dt = std::hypot(p.x - t.x, p.y - t.y);
                EXPECT_NEAR(ds, dt, 1e-6);
            }
        }
        total += area / 2;
    }
    EXPECT_NEAR(total, 100.0 * 100.0, 1e-6);  // the cells tile the grid rectangle
}

TEST(RmpVoronoi, CoveringRadiusBoundsEveryVertex) {
    for (int count : {1, 7, 100, 5000}) {
        const int w = 90, h = 130;
        const auto sites = random_sites(count, w, h, 9 + count);
        const SiteIndex index(sites, w, h);
        const double r = index.covering_radius();
        double worst = 0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const Point2& s = sites[std::size_t(index.nearest(x, y))];
                worst = std::max(worst, std::hypot(s.x - x, s.y - y));
            }
        EXPECT_GE(r, worst);
        EXPECT_LE(r, std::hypot(w - 1, h - 1) + 1e-9);
    }
}

TEST(RmpVoronoi, CellRadiusBoundsHoldEveryCell) {
    for (int count : {1, 7, 100, 3000}) {
        const int w = 120, h = 90;
        const auto sites = random_sites(count, w, h, 31 + count);
        const SiteIndex index(sites, w, h);
        const auto bounds = index.cell_radius_bounds();
        ASSERT_EQ(bounds.size(), sites.size());
        std::vector<double> reach(sites.size(), 0.0);
        for (int s = 0; s < count; ++s)
            for (const Point2& p : index.cell(s).vertices)  // the cell's farthest point is a corner
                reach[std::size_t(s)] = std::max(reach[std::size_t(s)], std::hypot(p.x - sites[s].x, p.y - sites[s].y));
        for (int s = 0; s < count; ++s) EXPECT_GE(bounds[std::size_t(s)], reach[std::size_t(s)] - 1e-9) << s;
    }
}
