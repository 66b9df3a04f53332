// The plate simulation: scripted collisions (head-on, pull-apart, dense
// under light), rifting, containment, where the uplift lands, determinism and
// bad input.
#include "plates.hpp"
#include "polygon.hpp"

#include <orogen/error.hpp>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

using namespace orogen;
using namespace orogen::plates;

namespace {

struct Grid {
    int n;
    double cell;
    std::vector<float> height, uplift, boundary, plate;
    explicit Grid(int size, double cell_m = 10.0)
        : n(size), cell(cell_m), height(std::size_t(size) * size, 0.0f), uplift(height.size(), 0.0f),
          boundary(height.size(), 0.0f), plate(height.size(), 0.0f) {}
    GridView view(std::vector<float>& v) { return {v.data(), n, n, cell}; }
    Layers layers() { return {view(height), view(uplift), view(boundary), view(plate)}; }
    double spu() const { return samples_per_unit(n, n); }
};

Polygon rect(double x0, double y0, double x1, double y1) { return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}; }

PlateSpec plate(Polygon p, Point2 v, double density = continental_density) {
    PlateSpec s;
    s.polygon = std::move(p);
    s.velocity = v;
    s.density = density;
    return s;
}

PlateSpec plate_at(Polygon p) { return plate(std::move(p), {0, 0}); }

Params scripted(int steps) {
    Params p;
    p.drive = Drive::still;
    p.steps = steps;
    p.dt = 0.1;
    p.record_every = 1;
    return p;
}

// Uplift-weighted mean and variance of x and y over cells where `keep(u)`.
struct Moments {
    double weight = 0, mx = 0, my = 0, vx = 0, vy = 0;
};
template <typename Keep>
Moments moments(const Grid& g, Keep keep) {
    Moments m;
    for (int y = 0; y < g.n; ++y)
        for (int x = 0; x < g.n; ++x) {
            const double u = g.uplift[std::size_t(y) * g.n + x];
            if (!keep(u)) continue;
            const double w = std::abs(u);
            m.weight += w, m.mx += w * x, m.my += w * y;
        }
    m.mx /= m.weight, m.my /= m.weight;
    for (int y = 0; y < g.n; ++y)
        for (int x = 0; x < g.n; ++x) {
            const double u = g.uplift[std::size_t(y) * g.n + x];
            if (!keep(u)) continue;
            const double w = std::abs(u);
            m.vx += w * (x - m.mx) * (x - m.mx), m.vy += w * (y - m.my) * (y - m.my);
        }
    m.vx /= m.weight, m.vy /= m.weight;
    return m;
}

double distance_to_segment(Point2 p, Point2 a, Point2 b) {
    const double dx = b.x - a.x, dy = b.y - a.y;
    const double len2 = dx * dx + dy * dy;
    double t = len2 > 0 ? ((p.x - a.x) * dx + (p.y - a.y) * dy) / len2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    return std::hypot(p.x - (a.x + t * dx), p.y - (a.y + t * dy));
}

}  // namespace

// Two plates driven head-on along x meet between them: one range, running
// north–south (perpendicular to the motion), raised only between them.
TEST(PlatesSimulation, HeadOnCollisionRaisesOneRangePerpendicularToTheMotion) {
    Grid g(129);
    const std::vector<PlateSpec> plates = {plate(rect(6, 6, 16, 30), {2, 0}), plate(rect(20, 6, 30, 30), {-2, 0})};
    const Result r = simulate(plates, scripted(60), 11, g.layers());
    EXPECT_GE(r.stats.events[int(BoundaryKind::convergent)], 1);
    EXPECT_EQ(r.stats.events[int(BoundaryKind::divergent)], 0);
    EXPECT_EQ(r.stats.subductions, 0);
    for (const CollisionEvent& e : r.history.collisions) {
        EXPECT_EQ(e.kind, BoundaryKind::convergent);
        EXPECT_NEAR(e.a.x, e.b.x, 1e-3 * g.spu() * g.cell);  // the contact runs north–south
        EXPECT_GT(e.impulse, 0.0);
    }
    for (float u : g.uplift) EXPECT_GE(u, 0.0f);  // a range only raises
    const Moments m = moments(g, [](double u) { return u > 0; });
    ASSERT_GT(m.weight, 0.0);
    const double meet = 18.0 * g.spu();  // the plates meet at x = 18 u
    EXPECT_NEAR(m.mx, meet, 4.0);
    EXPECT_NEAR(m.my, 18.0 * g.spu(), 8.0);
    EXPECT_GT(m.vy, 4.0 * m.vx) << "the range should run north–south";
    // Between the plates: nothing raised west of the west plate's start or east of the east plate's.
    for (int y = 0; y < g.n; ++y)
        for (int x = 0; x < g.n; ++x)
            if (x < 6.0 * g.spu() - 1 || x > 30.0 * g.spu() + 1) EXPECT_EQ(g.uplift[std::size_t(y) * g.n + x], 0.0f);
    // The boundary layer marks the contact as convergent.
    EXPECT_EQ(g.boundary[std::size_t(std::lround(18 * g.spu())) * g.n + std::size_t(std::lround(meet))], 1.0f);
    // And the height carries the same change as the uplift layer.
    for (std::size_t i = 0; i < g.height.size(); ++i) ASSERT_EQ(g.height[i], g.uplift[i]);
}

// Two touching plates pulled apart: a rift valley (lower) with a ridge on its axis.
// 25 cones: relief widths of a Voronoi cell of 26 samples, so the floor and
// the ridge are several samples wide.
TEST(PlatesSimulation, PullApartCutsARiftWithARidge) {
    Grid g(129);
    const std::vector<PlateSpec> plates = {plate(rect(6, 6, 18, 30), {-1, 0}), plate(rect(18, 6, 30, 30), {1, 0})};
    Params p = scripted(30);
    p.cones = 25;
    const Result r = simulate(plates, p, 11, g.layers());
    EXPECT_EQ(r.stats.events[int(BoundaryKind::divergent)], 1);
    EXPECT_EQ(r.stats.events[int(BoundaryKind::convergent)], 0);
    for (float u : g.uplift) EXPECT_LE(u, 0.0f);  // a rift only lowers
    const int axis = int(std::lround(18 * g.spu()));
    const int row = int(std::lround(18 * g.spu()));
    const float* u = &g.uplift[std::size_t(row) * g.n];
    const float floor_w = *std::min_element(u + axis - 12, u + axis - 2);
    const float floor_e = *std::min_element(u + axis + 3, u + axis + 13);
    EXPECT_LT(floor_w, -10.0f);
    EXPECT_LT(floor_e, -10.0f);
    EXPECT_GT(u[axis], floor_w + 4.0f) << "a ridge should stand on the rift's axis";
    EXPECT_GT(u[axis], floor_e + 4.0f);
    EXPECT_EQ(g.boundary[std::size_t(row) * g.n + axis], 2.0f);
    const Moments m = moments(g, [](double v) { return v < 0; });
    EXPECT_NEAR(m.mx, axis, 2.0);
    EXPECT_GT(m.vy, 4.0 * m.vx);
}

// A dense (oceanic) plate driven into a light (continental) one: a trench on
// the dense plate's side, a volcanic arc on the light one's. The arc is a
// chain of separate volcanoes, so the profile across is taken as each
// column's lowest and highest sample over the plates' rows.
TEST(PlatesSimulation, DensePlateUnderLightGivesTrenchAndArc) {
    for (bool dense_west : {true, false}) {
        Grid g(129);
        const double west = dense_west ? oceanic_density : continental_density;
        const double east = dense_west ? continental_density : oceanic_density;
        const std::vector<PlateSpec> plates = {plate(rect(6, 6, 16, 30), {2, 0}, west),
                                               plate(rect(20, 6, 30, 30), {-2, 0}, east)};
        Params p = scripted(60);
        p.cones = 25;
        const Result r = simulate(plates, p, 11, g.layers());
        EXPECT_GE(r.stats.subductions, 1);
        std::vector<float> lowest(std::size_t(g.n), 0.0f), highest(std::size_t(g.n), 0.0f);
        for (int y = int(8 * g.spu()); y <= int(28 * g.spu()); ++y)
            for (int x = 0; x < g.n; ++x) {
                const float v = g.uplift[std::size_t(y) * g.n + x];
                lowest[std::size_t(x)] = std::min(lowest[std::size_t(x)], v);
                highest[std::size_t(x)] = std::max(highest[std::size_t(x)], v);
            }
        const int lo = int(std::min_element(lowest.begin(), lowest.end()) - lowest.begin());
        const int hi = int(std::max_element(highest.begin(), highest.end()) - highest.begin());
        const double meet = 18.0 * g.spu();
        EXPECT_LT(lowest[std::size_t(lo)], -0.8 * p.trench_depth);
        EXPECT_GT(highest[std::size_t(hi)], 0.5 * p.arc_height);
        if (dense_west) {
            EXPECT_LT(lo, meet) << "trench on the dense (west) side";
            EXPECT_GT(hi, meet) << "arc on the light (east) side";
            for (int x = 0; x < int(meet) - 1; ++x)
                EXPECT_LE(highest[std::size_t(x)], 0.0f) << "no arc on the dense side";
        } else {
            EXPECT_GT(lo, meet);
            EXPECT_LT(hi, meet);
            for (int x = int(meet) + 2; x < g.n; ++x)
                EXPECT_LE(highest[std::size_t(x)], 0.0f) << "no arc on the dense side";
        }
        EXPECT_GT(std::abs(hi - meet), std::abs(lo - meet)) << "the arc stands farther inland than the trench";
    }
}

// Two plates sliding past each other along their shared edge: a transform
// boundary, recorded, with the height left as it was.
TEST(PlatesSimulation, TransformBoundaryLeavesTheHeightUnchanged) {
    Grid g(129);
    for (std::size_t i = 0; i < g.height.size(); ++i) g.height[i] = float(i % 13);
    const std::vector<float> before = g.height;
    const std::vector<PlateSpec> plates = {plate(rect(6, 6, 18, 30), {0, -1}), plate(rect(18, 6, 30, 30), {0, 1})};
    const Result r = simulate(plates, scripted(30), 11, g.layers());
    EXPECT_EQ(r.stats.events[int(BoundaryKind::transform)], 1);
    EXPECT_EQ(r.stats.events[int(BoundaryKind::convergent)] + r.stats.events[int(BoundaryKind::divergent)], 0);
    EXPECT_EQ(g.height, before);
    for (float u : g.uplift) EXPECT_EQ(u, 0.0f);
    ASSERT_EQ(r.history.collisions.size(), 1u);
    EXPECT_EQ(r.history.collisions[0].kind, BoundaryKind::transform);
    const int axis = int(std::lround(18 * g.spu()));
    EXPECT_EQ(g.boundary[std::size_t(axis) * g.n + axis], 3.0f);
}

TEST(PlatesSimulation, RiftingKeepsPlatesConvexWithAtMostEightVerticesAndConservesArea) {
    Grid g(129);
    const auto start = random_plates(area_size(g.n, g.n), 8, 0.5, 1.0, 3);
    Params p;
    p.steps = 800;
    p.record_every = 1;
    p.rift_threshold = 100.0;
    p.max_plates = max_plates(g.n, g.n);
    const Result r = simulate(start, p, 3, g.layers());
    EXPECT_GE(r.stats.rifts, 3);
    EXPECT_EQ(r.final_plates.size(), start.size() + std::size_t(r.stats.rifts));
    double area0 = 0.0;
    for (const PlateSpec& s : start) area0 += signed_area(s.polygon);
    const double m_per_u = g.spu() * g.cell;
    for (const PlateSnapshot& snap : r.history.snapshots) {
        double area = 0.0;
        for (const PlateState& s : snap.plates) {
            EXPECT_LE(s.polygon.size(), 8u) << "step " << snap.step;
            EXPECT_TRUE(is_convex_ccw(s.polygon, 1e-7)) << "plate " << s.id << " at step " << snap.step;
            area += signed_area(s.polygon) / (m_per_u * m_per_u);
        }
        EXPECT_NEAR(area, area0, 1e-4 * area0) << "step " << snap.step;  // Box2D stores floats
    }
    // Ids stay unique.
    std::vector<int> ids = r.final_ids;
    std::sort(ids.begin(), ids.end());
    EXPECT_EQ(std::adjacent_find(ids.begin(), ids.end()), ids.end());
}

// No plate leaves the area between the beams, whatever the drive, over 10,000 steps.
TEST(PlatesSimulation, NoPlateLeavesTheContainerOverTenThousandSteps) {
    for (Drive drive : {Drive::converge, Drive::rotate, Drive::shear, Drive::thesis}) {
        Grid g(33);
        const Point2 size = area_size(g.n, g.n);
        const auto start = random_plates(size, 12, 0.5, 1.0, 17);
        Params p;
        p.drive = drive;
        p.steps = 10'000;
        p.record_every = 10;
        p.cones = 50;
        p.rift_threshold = 0.0;
        const Result r = simulate(start, p, 17, g.layers());
        const double m_per_u = g.spu() * g.cell;
        const double slack = margin_units + p.stroke + 0.25;  // beams at their farthest, plus Box2D's skin
        for (const PlateSnapshot& snap : r.history.snapshots)
            for (const PlateState& s : snap.plates)
                for (const Point2& v : s.polygon) {
                    ASSERT_GE(v.x / m_per_u, -slack) << drive_names[int(drive)] << " step " << snap.step;
                    ASSERT_LE(v.x / m_per_u, size.x + slack) << drive_names[int(drive)] << " step " << snap.step;
                    ASSERT_GE(v.y / m_per_u, -slack) << drive_names[int(drive)] << " step " << snap.step;
                    ASSERT_LE(v.y / m_per_u, size.y + slack) << drive_names[int(drive)] << " step " << snap.step;
                }
    }
}

// Ranges are raised over the Voronoi cells a contact segment crosses, so
// uplift reaches about one cell size c = sqrt(area / cones) from the segment
// (a cell crossed near its edge extends up to about its diameter, ~2c, away).
// k = 1.5 c: at least 80 % of the uplift lies within k of a recorded segment.
TEST(PlatesSimulation, UpliftLiesAlongRecordedSegments) {
    Grid g(129);
    Params p;
    p.steps = 200;
    p.cones = 400;
    p.rift_threshold = 0.0;
    const auto start = random_plates(area_size(g.n, g.n), 12, 0.5, 1.0, 23);
    const Result r = simulate(start, p, 23, g.layers());
    std::vector<std::pair<Point2, Point2>> segments, mirrored;
    for (const CollisionEvent& e : r.history.collisions) {
        if (e.kind == BoundaryKind::transform) continue;
        const Point2 a{e.a.x / g.cell, e.a.y / g.cell}, b{e.b.x / g.cell, e.b.y / g.cell};
        segments.push_back({a, b});
        mirrored.push_back({{g.n - 1 - a.x, a.y}, {g.n - 1 - b.x, b.y}});  // a control: the same segments elsewhere
    }
    ASSERT_GE(segments.size(), 5u);
    const double c = std::sqrt(double(g.n) * g.n / p.cones);
    const double k = 1.5 * c;
    auto near_fraction = [&](const std::vector<std::pair<Point2, Point2>>& segs) {
        double total = 0, near = 0;
        for (int y = 0; y < g.n; ++y)
            for (int x = 0; x < g.n; ++x) {
                const double u = std::abs(g.uplift[std::size_t(y) * g.n + x]);
                if (u == 0) continue;
                total += u;
                for (const auto& [a, b] : segs)
                    if (distance_to_segment({double(x), double(y)}, a, b) <= k) {
                        near += u;
                        break;
                    }
            }
        return near / total;
    };
    const double along = near_fraction(segments);
    const double control = near_fraction(mirrored);
    EXPECT_GE(along, 0.8);
    EXPECT_LT(control, along - 0.1) << "the test would pass for segments anywhere";
    std::printf("uplift within k = %.1f samples of a segment: %.1f %% (mirrored segments: %.1f %%), %zu segments\n", k,
                100 * along, 100 * control, segments.size());
}

TEST(PlatesSimulation, SameSeedGivesIdenticalBytesOnOneAndTwoThreads) {
    auto run = [](int threads) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
        Grid g(129);
        for (int i = 0; i < g.n * g.n; ++i) g.height[std::size_t(i)] = float(i % 97) * 0.5f;
        Params p;
        p.steps = 400;
        p.rift_threshold = 200.0;
        p.max_plates = max_plates(g.n, g.n);
        const Result r = simulate(random_plates(area_size(g.n, g.n), 12, 0.5, 1.0, 99), p, 99, g.layers());
        return std::make_pair(std::move(g), r.history);
    };
    const auto [g1, h1] = run(1);
    const auto [g2, h2] = run(2);
    const auto [g3, h3] = run(2);
    for (const auto* g : {&g2, &g3}) {
        EXPECT_EQ(std::memcmp(g1.height.data(), g->height.data(), g1.height.size() * 4), 0);
        EXPECT_EQ(std::memcmp(g1.uplift.data(), g->uplift.data(), g1.uplift.size() * 4), 0);
        EXPECT_EQ(g1.boundary, g->boundary);
        EXPECT_EQ(g1.plate, g->plate);
    }
    for (const auto* h : {&h2, &h3}) {
        ASSERT_EQ(h1.collisions.size(), h->collisions.size());
        for (std::size_t i = 0; i < h1.collisions.size(); ++i) {
            EXPECT_EQ(h1.collisions[i].a, h->collisions[i].a);
            EXPECT_EQ(h1.collisions[i].impulse, h->collisions[i].impulse);
        }
        ASSERT_EQ(h1.snapshots.size(), h->snapshots.size());
        EXPECT_EQ(h1.snapshots.back().plates.back().polygon, h->snapshots.back().plates.back().polygon);
    }
    EXPECT_GT(h1.collisions.size(), 0u);
}

// What a tiled run does: the events alone (no grid), encoded and decoded as rank 0 sends them, then drawn into
// uneven windows of the grid that together cover it. Every sample of every layer gets the whole run's bits, in
// both range styles (peaks with trenches, volcanoes and rifts; the thesis's Voronoi cells).
TEST(PlatesSimulation, EventsDrawnIntoWindowsGiveTheWholeGridsBits) {
    for (const RangeStyle style : {RangeStyle::peaks, RangeStyle::cells}) {
        SCOPED_TRACE(style == RangeStyle::peaks ? "peaks" : "cells");
        const int w = 131, h = 97;
        std::vector<float> base(std::size_t(w) * h);
        for (std::size_t i = 0; i < base.size(); ++i) base[i] = float(i % 89) * 0.25f;
        Params p;
        p.steps = 400;
        p.rift_threshold = 200.0;
        p.ranges = style;
        p.max_plates = max_plates(w, h);
        const auto start = random_plates(area_size(w, h), 12, 0.5, 1.0, 7);
        std::vector<float> whole = base, uplift(base.size(), 0.0f), boundary(base.size(), 0.0f),
                           plate(base.size(), 0.0f);
        const Result r = simulate(start, p, 7,
                                  {{whole.data(), w, h, 10.0},
                                   {uplift.data(), w, h, 10.0},
                                   {boundary.data(), w, h, 10.0},
                                   {plate.data(), w, h, 10.0}});
        ASSERT_GT(r.replay.stamps.size(), 10u);
        EXPECT_EQ(std::count_if(r.replay.stamps.begin(), r.replay.stamps.end(),
                                [](const ReliefStamp& s) { return s.kind == ReliefStamp::Kind::subduction; }) > 0,
                  true);

        const Result events = simulate_events(start, p, 7, w, h, 10.0);
        const Replay replay = decode_replay(encode(events.replay));
        ASSERT_EQ(replay.stamps.size(), r.replay.stamps.size());
        EXPECT_THROW(decode_replay(encode(events.replay).substr(0, 40)), Error);
        // Cuts off the powers of two, windows narrower than the volcanoes' reach.
        const int xs[] = {0, 17, 60, 61, 131}, ys[] = {0, 40, 41, 97};
        for (int j = 0; j + 1 < 4; ++j)
            for (int i = 0; i + 1 < 5; ++i) {
                const TileRect t{xs[i], ys[j], xs[i + 1] - xs[i], ys[j + 1] - ys[j]};
                std::vector<float> th(std::size_t(t.width) * t.height), tu(th.size(), 0.0f), tb(th.size(), 0.0f),
                    tp(th.size(), 0.0f);
                for (int y = 0; y < t.height; ++y)
                    for (int x = 0; x < t.width; ++x)
                        th[std::size_t(y) * t.width + x] = base[std::size_t(t.y0 + y) * w + std::size_t(t.x0 + x)];
                draw_tile(replay, p, 7,
                          {{th.data(), t.width, t.height, 10.0},
                           {tu.data(), t.width, t.height, 10.0},
                           {tb.data(), t.width, t.height, 10.0},
                           {tp.data(), t.width, t.height, 10.0}},
                          t);
                int differ = 0;
                for (int y = 0; y < t.height; ++y)
                    for (int x = 0; x < t.width; ++x) {
                        const std::size_t g = std::size_t(t.y0 + y) * w + std::size_t(t.x0 + x),
                                          k = std::size_t(y) * t.width + x;
                        differ += std::memcmp(&th[k], &whole[g], 4) != 0 || std::memcmp(&tu[k], &uplift[g], 4) != 0 ||
                            tb[k] != boundary[g] || tp[k] != plate[g];
                    }
                EXPECT_EQ(differ, 0) << "window at (" << t.x0 << ", " << t.y0 << ")";
            }
        EXPECT_NE(whole, base);
    }
}

TEST(PlatesSimulation, PlateLayerNamesThePlateOverEachSample) {
    Grid g(65);
    const std::vector<PlateSpec> plates = {plate(rect(2, 2, 17, 34), {0, 0}), plate(rect(19, 2, 34, 34), {0, 0})};
    simulate(plates, scripted(1), 1, g.layers());
    EXPECT_EQ(g.plate[32 * 65 + 16], 0.0f);
    EXPECT_EQ(g.plate[32 * 65 + 48], 1.0f);
    EXPECT_EQ(g.plate[0], -1.0f);  // outside every plate
}

TEST(PlatesSimulation, AWideGridGetsAWideAreaCoveringItExactly) {
    const int w = 129, h = 65;
    std::vector<float> height(std::size_t(w) * h), plate(height.size());
    const Point2 size = area_size(w, h);
    EXPECT_DOUBLE_EQ(size.x, 36.0);
    EXPECT_DOUBLE_EQ(size.y, 18.0);
    const std::vector<PlateSpec> plates = {plate_at(rect(0, 0, 18, 18)), plate_at(rect(18, 0, 36, 18))};
    Layers layers;
    layers.terrain = {height.data(), w, h, 10.0};
    layers.plate = {plate.data(), w, h, 10.0};
    const Result r = simulate(plates, scripted(1), 1, layers);
    EXPECT_DOUBLE_EQ(r.history.width, 1280.0);
    EXPECT_DOUBLE_EQ(r.history.height, 640.0);
    // Samples well inside each half belong to its plate: the area maps onto the whole grid.
    for (int y = 2; y < h - 2; ++y) {
        EXPECT_EQ(plate[std::size_t(y) * w + 2], 0.0f) << y;
        EXPECT_EQ(plate[std::size_t(y) * w + 61], 0.0f) << y;
        EXPECT_EQ(plate[std::size_t(y) * w + 67], 1.0f) << y;
        EXPECT_EQ(plate[std::size_t(y) * w + w - 3], 1.0f) << y;
    }
}

TEST(PlatesSimulation, BadParametersAreRefused) {
    Grid g(33);
    const std::vector<PlateSpec> plates = {plate(rect(2, 2, 17, 34), {0, 0}), plate(rect(19, 2, 34, 34), {0, 0})};
    Params p = scripted(10);
    p.steps = 0;
    EXPECT_THROW(simulate(plates, p, 1, g.layers()), BadInput);
    p = scripted(10);
    p.dt = 0.0;
    EXPECT_THROW(simulate(plates, p, 1, g.layers()), BadInput);
    p = scripted(10);
    const std::vector<PlateSpec> clockwise = {plate({{0, 0}, {0, 5}, {5, 5}, {5, 0}}, {0, 0})};
    try {
        simulate(clockwise, p, 1, g.layers());
        FAIL();
    } catch (const BadInput& e) {
        EXPECT_STREQ(e.what(), "plate 0 must be a convex counter-clockwise polygon of 3 to 8 vertices");
    }
    const std::vector<PlateSpec> sliver = {plate({{0, 0}, {5, 0}, {5, 4.99}, {4.99, 5}, {0, 5}}, {0, 0})};
    try {
        simulate(sliver, p, 1, g.layers());
        FAIL();
    } catch (const BadInput& e) {
        EXPECT_STREQ(e.what(), "plate 0 has an edge shorter than 0.05 u, which Box2D would weld away");
    }
    EXPECT_EQ(parse_drive("converge"), Drive::converge);
    EXPECT_FALSE(parse_drive("sideways"));
}

TEST(PlatesSimulation, NonFinitePositionFailsWithTheStep) {
    Grid g(33);
    const double inf = std::numeric_limits<double>::infinity();
    const std::vector<PlateSpec> plates = {plate(rect(2, 2, 17, 34), {0, 0}), plate(rect(19, 2, 34, 34), {inf, 0})};
    try {
        simulate(plates, scripted(10), 1, g.layers());
        FAIL() << "expected an error";
    } catch (const BadInput&) {
        FAIL() << "a diverging simulation is a failed run, not bad input";
    } catch (const Error& e) {
        EXPECT_STREQ(e.what(), "plate 1 has a non-finite position at step 1 (Box2D diverged; lower dt or speed)");
    }
}
