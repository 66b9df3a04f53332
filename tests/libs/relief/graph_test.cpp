// Line arrangements: face counts against the arrangement formula, simple
// convex faces, degenerate line sets (parallel, nearly parallel, concurrent).
#include <orogen/relief/graph.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

using namespace orogen;
using namespace orogen::relief;

namespace {

// Faces of lines that all cross the open rectangle: 1 + n + Σ over interior
// crossing points of (lines through it − 1). Brute force, points merged at 1e-6.
int expected_faces(const std::vector<Line>& lines, double w, double h) {
    std::vector<std::pair<Point2, std::set<int>>> points;
    for (std::size_t i = 0; i < lines.size(); ++i)
        for (std::size_t j = i + 1; j < lines.size(); ++j) {
            const Point2 d = lines[i].direction, e = lines[j].direction;
            const double den = d.x * e.y - d.y * e.x;
            if (std::abs(den) < 1e-14) continue;
            const Point2 c{lines[j].point.x - lines[i].point.x, lines[j].point.y - lines[i].point.y};
            const double u = (c.x * e.y - c.y * e.x) / den;
            const Point2 p{lines[i].point.x + u * d.x, lines[i].point.y + u * d.y};
            if (!(p.x > 1e-9 && p.x < w - 1e-9 && p.y > 1e-9 && p.y < h - 1e-9)) continue;
            bool merged = false;
            for (auto& [q, set] : points)
                if (std::hypot(q.x - p.x, q.y - p.y) < 1e-6) {
                    set.insert(int(i));
                    set.insert(int(j));
                    merged = true;
                }
            if (!merged) points.push_back({p, {int(i), int(j)}});
        }
    int faces = 1 + int(lines.size());
    for (const auto& [p, set] : points) faces += int(set.size()) - 1;
    return faces;
}

void expect_proper(const Arrangement& g, double w, double h) {
    double total = 0;
    for (std::size_t f = 0; f < g.faces.size(); ++f) {
        const auto& face = g.faces[f];
        ASSERT_GE(face.size(), 3u);
        std::set<int> distinct(face.begin(), face.end());
        EXPECT_EQ(distinct.size(), face.size()) << "face " << f << " is not simple";
        const auto poly = g.polygon(int(f));
        double area = 0;
        for (std::size_t k = 0; k < poly.size(); ++k) {
            const Point2 &p = poly[k], &q = poly[(k + 1) % poly.size()], &r = poly[(k + 2) % poly.size()];
            area += p.x * q.y - q.x * p.y;
            EXPECT_GE((q.x - p.x) * (r.y - q.y) - (q.y - p.y) * (r.x - q.x), -1e-9) << "face " << f << " not convex";
        }
        EXPECT_GT(area, 0);
        total += area / 2;
    }
    EXPECT_NEAR(total, w * h, 1e-6 * w * h);
    // Euler for a connected plane graph: V − E + (bounded faces + 1) = 2.
    EXPECT_EQ(int(g.vertices.size()) - int(g.edges.size()) + int(g.faces.size()) + 1, 2);
}

Line through(Point2 a, Point2 b) { return {a, {b.x - a.x, b.y - a.y}}; }

}  // namespace

TEST(RmpGraph, NoCutsIsTheRectangle) {
    const Arrangement g = build_arrangement({}, 10, 6);
    ASSERT_EQ(g.faces.size(), 1u);
    EXPECT_EQ(g.faces[0].size(), 4u);
    expect_proper(g, 10, 6);
}

TEST(RmpGraph, GeneralPositionMeetsTheLazyCatererBound) {
    // 3, 4 and 5 lines, every pair crossing inside: the thesis's 7, 11, 16 polygons.
    // Tangents to a circle of radius 1 about the centre, normals 36° apart:
    // no two parallel, no three through a point, every crossing inside.
    std::vector<Line> lines;
    for (int i = 0; i < 5; ++i) {
        const double a = i * 0.2 * 3.141592653589793;
        lines.push_back({{5 + std::cos(a), 5 + std::sin(a)}, {-std::sin(a), std::cos(a)}});
    }
    const int lazy[] = {0, 2, 4, 7, 11, 16};
    for (int n = 1; n <= 5; ++n) {
        std::vector<Line> some(lines.begin(), lines.begin() + n);
        const Arrangement g = build_arrangement(some, 10, 10);
        EXPECT_EQ(int(g.faces.size()), expected_faces(some, 10, 10));
        EXPECT_EQ(int(g.faces.size()), lazy[n]) << n << " lines";
        expect_proper(g, 10, 10);
    }
}

TEST(RmpGraph, ParallelLines) {
    std::vector<Line> lines{through({2.5, 0}, {2.5, 1}), through({5, 0}, {5, 1}), through({7.5, 3}, {7.5, 4})};
    Arrangement g = build_arrangement(lines, 10, 10);
    EXPECT_EQ(g.faces.size(), 4u);
    expect_proper(g, 10, 10);
    lines.push_back(through({0, 5}, {1, 5}));
    g = build_arrangement(lines, 10, 10);
    EXPECT_EQ(g.faces.size(), 8u);
    expect_proper(g, 10, 10);
}

TEST(RmpGraph, NearlyParallelLines) {
    // Crossing inside at a small angle: 4 faces, two of them slivers.
    std::vector<Line> lines{{{5, 5}, {1, 0}}, {{5, 5}, {1, 1e-5}}};
    Arrangement g = build_arrangement(lines, 10, 10);
    EXPECT_EQ(g.faces.size(), 4u);
    expect_proper(g, 10, 10);
    // At 1e-10 the slivers are thinner than the merge distance (1e-7 of the
    // map): both lines become one, 2 faces, still a proper graph.
    lines = {{{5, 5}, {1, 0}}, {{5, 5}, {1, 1e-10}}};
    g = build_arrangement(lines, 10, 10);
    EXPECT_EQ(g.faces.size(), 2u);
    expect_proper(g, 10, 10);
    // Crossing far outside: 3 faces.
    lines = {{{5, 5}, {1, 0}}, {{5, 5.001}, {1, 1e-10}}};
    g = build_arrangement(lines, 10, 10);
    EXPECT_EQ(g.faces.size(), 3u);
    expect_proper(g, 10, 10);
    // Almost the same line.
    lines = {{{5, 5}, {1, 0}}, {{5, 5 + 1e-12}, {1, 1e-15}}};
    g = build_arrangement(lines, 10, 10);
    EXPECT_EQ(g.faces.size(), 2u);
    expect_proper(g, 10, 10);
}

TEST(RmpGraph, LinesThroughOnePointAndThroughCorners) {
    std::vector<Line> lines{through({0, 0}, {10, 10}), through({10, 0}, {0, 10}), through({5, 0}, {5, 10})};
    Arrangement g = build_arrangement(lines, 10, 10);
    EXPECT_EQ(g.faces.size(), 6u);
    EXPECT_EQ(int(g.faces.size()), expected_faces(lines, 10, 10));
    expect_proper(g, 10, 10);
    lines.push_back(through({0, 5}, {10, 5}));
    lines.push_back(through({0, 2}, {10, 8}));  // also through the centre
    g = build_arrangement(lines, 10, 10);
    EXPECT_EQ(g.faces.size(), 10u);
    expect_proper(g, 10, 10);
    // A line through a border vertex made by another line.
    lines.push_back(through({5, 0}, {0, 3}));
    g = build_arrangement(lines, 10, 10);
    EXPECT_EQ(int(g.faces.size()), expected_faces(lines, 10, 10));
    expect_proper(g, 10, 10);
}

TEST(RmpGraph, RandomCutsGiveTheArrangementCount) {
    for (int n : {3, 4, 5, 50}) {
        for (std::uint64_t seed = 1; seed <= 5; ++seed) {
            const auto lines = random_cuts(n, 128, 96, seed);
            const Arrangement g = build_arrangement(lines, 128, 96);
            EXPECT_EQ(int(g.faces.size()), expected_faces(lines, 128, 96)) << n << " cuts, seed " << seed;
            EXPECT_LE(int(g.faces.size()), (n * n + n + 2) / 2);
            expect_proper(g, 128, 96);
        }
    }
}

TEST(RmpGraph, ScanlineFillAgreesWithPnpolyAndCoversTheGrid) {
    const int w = 97, h = 65;
    const auto lines = random_cuts(12, w - 1, h - 1, 11);
    const Arrangement g = build_arrangement(lines, w - 1, h - 1);
    std::vector<int> count(std::size_t(w) * h, 0);
    std::vector<RowSpan> spans;
    for (std::size_t f = 0; f < g.faces.size(); ++f) {
        const auto poly = g.polygon(int(f));
        convex_row_spans(poly, w, h, spans);
        std::set<std::pair<int, int>> filled;
        for (const auto& s : spans)
            for (int x = s.x0; x <= s.x1; ++x) {
                ++count[std::size_t(s.y) * w + x];
                filled.insert({x, s.y});
            }
        // Strictly inside by PNPOLY → filled (boundary vertices may go either way in PNPOLY).
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                if (pnpoly(poly, {double(x), double(y)})) EXPECT_TRUE(filled.count({x, y}));
    }
    for (int c : count) EXPECT_GE(c, 1);  // every vertex in some face
}

TEST(RmpGraph, DepthFirstOrderVisitsEveryFaceOnceThroughNeighbours) {
    const auto lines = random_cuts(8, 100, 100, 3);
    const Arrangement g = build_arrangement(lines, 100, 100);
    const int start = face_containing(g, {50, 50});
    ASSERT_GE(start, 0);
    EXPECT_TRUE(pnpoly(g.polygon(start), {50, 50}));
    const auto order = depth_first_order(g, start);
    ASSERT_EQ(order.size(), g.faces.size());
    EXPECT_EQ(order[0], start);
    std::set<int> seen{order[0]};
    for (std::size_t i = 1; i < order.size(); ++i) {
        EXPECT_TRUE(seen.insert(order[i]).second);
        // Depth first: adjacent to some face visited before it.
        bool linked = false;
        for (int s : seen)
            for (int n : g.adjacency[std::size_t(order[i])]) linked |= (n == s && s != order[i]);
        EXPECT_TRUE(linked);
    }
    // Corners of the map lie in a face too (PNPOLY's half-open rule on the far border).
    EXPECT_GE(face_containing(g, {100, 100}), 0);
    EXPECT_GE(face_containing(g, {0, 0}), 0);
}
