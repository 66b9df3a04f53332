// The cone method through OSMesa against the exact Voronoi diagram.
#include "cones.hpp"
#include "rmp.hpp"
#include <orogen/relief/voronoi.hpp>

#include <orogen/error.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

using namespace orogen;
using namespace orogen::rmp;
using namespace orogen::relief;

TEST(RmpCones, ConesDrawTheExactVoronoiDiagram) {
    const int w = 129, h = 97;
    ConeRenderer renderer(w, h);
    for (int count : {7, 100, 1000}) {
        const auto sites = random_sites(count, w, h, 500 + count);
        const SiteIndex index(sites, w, h);
        const auto exact = label_grid(index);
        // As rmp_cones draws them: each cone as wide as its cell's bound; and
        // the thesis's way, every cone one radius (covering the whole map).
        auto radii = index.cell_radius_bounds();
        for (double& r : radii) r += 1.0;
        const auto ids = renderer.render(sites, radii);
        std::vector<std::int32_t> drawn(ids.size());
        for (std::size_t i = 0; i < ids.size(); ++i) drawn[i] = std::int32_t(ids[i]) - 1;
        EXPECT_EQ(drawn, renderer.labels(sites, index.covering_radius() + 1.0));
        std::size_t same = 0;
        for (std::size_t i = 0; i < exact.size(); ++i) {
            ASSERT_GE(drawn[i], 0) << "vertex " << i << " not covered by any cone";
            same += drawn[i] == exact[i];
        }
        const double agreement = double(same) / double(exact.size());
        std::printf("%d cones: cones and voronoi agree on %.4f %% of the vertices\n", count, 100.0 * agreement);
        EXPECT_GE(agreement, 0.995) << count << " cones";
        // The cell under the centre is the same one.
        EXPECT_EQ(drawn[std::size_t(48) * w + 64], exact[std::size_t(48) * w + 64]);
    }
}

TEST(RmpCones, RmpConesAgreesWithRmpVoronoi) {
    const int w = 97, h = 97;
    RmpParams p;
    p.iterations = 20;
    p.cones = 60;
    p.peaks = {{0.5, 0.5}, {0.25, 0.7}};
    p.jitter = 0.4;
    std::vector<float> a(std::size_t(w) * h, 0.0f), b = a;
    rmp_voronoi({a.data(), w, h, 1.0}, p, 123);
    rmp_cones({b.data(), w, h, 1.0}, p, 123);
    std::size_t same = 0;
    for (std::size_t i = 0; i < a.size(); ++i) same += a[i] == b[i];
    EXPECT_GE(double(same) / double(a.size()), 0.995);
    EXPECT_EQ(a[std::size_t(48) * w + 48], b[std::size_t(48) * w + 48]);
    EXPECT_GT(*std::max_element(b.begin(), b.end()), 0.0f);
}

TEST(RmpCones, GridLargerThanOsmesaCanDrawIsAClearError) {
    try {
        ConeRenderer renderer(40000, 2);
        FAIL() << "expected BadInput";
    } catch (const BadInput& e) {
        const std::string m = e.what();
        EXPECT_EQ(m.rfind("cones: the grid is 40000 × 2 vertices but OSMesa draws at most ", 0), 0u) << m;
        EXPECT_NE(m.find("; use method=voronoi for larger grids"), std::string::npos) << m;
    }
}
