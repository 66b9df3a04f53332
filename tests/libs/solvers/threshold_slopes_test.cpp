// Tests of the threshold-slope limit (threshold_slopes.hpp): the known surfaces
// it must give (a round cone around a fixed point, valley sides at the
// threshold whatever the valley's azimuth, a plane away from a fixed
// edge), the three properties that define it on rough relief (nothing
// steeper than S_c, nothing raised, each lowered vertex held exactly at
// the bound its neighbours give it, above a lower one, so no pit), and the
// same bits as a plain Jacobi iteration to the fixed point and on any
// thread count.
#include <orogen/solvers/threshold_slopes.hpp>

#include <orogen/random.hpp>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>
#include <vector>

namespace {

using namespace orogen;

constexpr double kSqrt2 = 1.4142135623730951;

std::vector<double> rough(int w, int h, std::uint64_t seed, double amplitude) {
    std::vector<double> v(std::size_t(w) * std::size_t(h));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) v[std::size_t(y) * w + x] = amplitude * random::uniform(seed, x, y) + 3.0 * x;
    return v;
}

/// The eight neighbours (dx, dy) and their distance in cells.
struct Neighbour {
    int dx, dy;
    double cells;
};
constexpr Neighbour kNeighbours[] = {{-1, -1, kSqrt2}, {0, -1, 1.0},    {1, -1, kSqrt2}, {-1, 0, 1.0},
                                     {1, 0, 1.0},      {-1, 1, kSqrt2}, {0, 1, 1.0},     {1, 1, kSqrt2}};

/// The bound vertex (x, y) gets from its neighbours in v (none outside the grid): the least edge_bound
/// over the eight triangles of its stencil, each a straight neighbour and a diagonal one beside it.
double bound_at(const std::vector<double>& v, int w, int h, int x, int y, double step) {
    auto at = [&](int dx, int dy) {
        const int nx = x + dx, ny = y + dy;
        return nx < 0 || ny < 0 || nx >= w || ny >= h ? std::numeric_limits<double>::infinity()
                                                      : v[std::size_t(ny) * w + nx];
    };
    double best = std::numeric_limits<double>::infinity();
    for (const auto& [sx, sy] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}})
        for (int side : {-1, 1}) {  // the diagonal beside the straight neighbour (sx, sy)
            const int dx = sx != 0 ? sx : side, dy = sy != 0 ? sy : side;
            best = std::min(best, solvers::threshold::edge_bound(at(sx, sy), at(dx, dy), step));
        }
    return best;
}

/// The definition iterated the simplest way: every vertex from the previous
/// iterate's neighbours at once, until nothing changes.
std::vector<double> jacobi(std::vector<double> v, int w, int h, double cell, const std::vector<double>& slope) {
    for (bool changed = true; changed;) {
        changed = false;
        std::vector<double> next = v;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const std::size_t i = std::size_t(y) * w + x;
                const double c = bound_at(v, w, h, x, y, slope[i] * cell);
                if (c < next[i]) next[i] = c, changed = true;
            }
        v = std::move(next);
    }
    return v;
}

TEST(ThresholdSlopes, AFixedPointOnAHighPlateauBecomesARoundCone) {
    // Heights 1000 m but the centre, held at 0: the limit is S_c times the distance to it, the same
    // in every direction. The 8-neighbour path (straight and diagonal steps only) is up to 8 % longer
    // between the axes and the diagonals: octagonal cones, whose faces all look one of eight ways.
    const int w = 61, h = 61, cx = 30, cy = 30;
    const double cell = 30.0, slope = std::tan(35.0 * M_PI / 180.0);
    std::vector<double> v(std::size_t(w) * h, 1000.0);
    std::vector<std::uint8_t> fixed(v.size(), 0);
    v[std::size_t(cy) * w + cx] = 0.0;
    fixed[std::size_t(cy) * w + cx] = 1;
    const auto r = solvers::threshold::limit_slopes(v.data(), w, h, cell, {slope}, fixed.data());
    double worst = 0.0, worst_octagon = 0.0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const int ax = std::abs(x - cx), ay = std::abs(y - cy);
            const double d = std::hypot(double(ax), double(ay));
            const double octagon = double(std::max(ax, ay) - std::min(ax, ay)) + kSqrt2 * std::min(ax, ay);
            const double got = v[std::size_t(y) * w + x], cone = slope * cell * d;
            if (cone >= 1000.0 || d < 8.0) continue;
            // Never below the true cone (nothing slides further than the threshold demands), never above
            // the octagonal one, and close to the true cone away from the apex.
            EXPECT_GE(got, cone * (1.0 - 1e-12)) << x << "," << y;
            EXPECT_LE(got, slope * cell * octagon * (1.0 + 1e-12)) << x << "," << y;
            worst = std::max(worst, got / cone - 1.0);
            worst_octagon = std::max(worst_octagon, octagon / d - 1.0);
        }
    EXPECT_LT(worst, 0.03) << "the cone is round to 3 % beyond 8 cells from its apex (2.3 % measured)";
    EXPECT_GT(worst_octagon, 0.07) << "the octagonal path it replaces is 7-8 % long there";
    EXPECT_GT(r.lowered, 0);
    EXPECT_GE(r.rounds, 2) << "the last round must be one that changed nothing";
}

TEST(ThresholdSlopes, ValleySidesAreHeldAtTheThresholdWhateverTheValleysAzimuth) {
    // A river held at 0 along a straight line at 0-45° through the grid: the valley's sides are planes
    // at the threshold, so a vertex's height is S_c times its distance to the line, to the river's own
    // steps: S_c times the distance to its nearest vertex (those within half a cell of the line), to
    // 2.5 % beyond 10 cells (1.9 % measured). The octagonal limit stood 8 % too high at 22.5°.
    const int w = 120, h = 120;
    const double cell = 30.0, slope = 0.7;
    for (double azimuth : {0.0, 10.0, 22.5, 30.0, 45.0}) {
        const double ux = std::cos(azimuth * M_PI / 180.0), uy = std::sin(azimuth * M_PI / 180.0);
        std::vector<double> v(std::size_t(w) * h, 5000.0);
        std::vector<std::uint8_t> fixed(v.size(), 0);
        auto distance = [&](int x, int y) { return std::abs(-(x - 10) * uy + (y - 10) * ux); };  // cells
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                if (distance(x, y) <= 0.5) v[std::size_t(y) * w + x] = 0.0, fixed[std::size_t(y) * w + x] = 1;
        std::vector<std::pair<int, int>> river;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                if (fixed[std::size_t(y) * w + x]) river.emplace_back(x, y);
        solvers::threshold::limit_slopes(v.data(), w, h, cell, {slope}, fixed.data());
        double worst = 0.0;
        for (int y = 30; y < h - 30; ++y)
            for (int x = 30; x < w - 30; ++x) {
                if (distance(x, y) < 10.0) continue;
                double d = 1e30;  // cells, to the nearest vertex of the river
                for (const auto& [rx, ry] : river) d = std::min(d, std::hypot(double(x - rx), double(y - ry)));
                const double expected = slope * cell * d;
                worst = std::max(worst, std::abs(v[std::size_t(y) * w + x] - expected) / expected);
            }
        EXPECT_LT(worst, 0.025) << "a valley at " << azimuth << "° from the grid's rows";
    }
}

TEST(ThresholdSlopes, AFixedRiverLeavesPlanarValleySidesAtTheThreshold) {
    // A river along the west edge held at 0: every column x stands at S_c·cell·x, up to the plateau.
    const int w = 50, h = 20;
    const double cell = 10.0, slope = 0.7;
    std::vector<double> v(std::size_t(w) * h, 200.0);
    std::vector<std::uint8_t> fixed(v.size(), 0);
    for (int y = 0; y < h; ++y) v[std::size_t(y) * w] = 0.0, fixed[std::size_t(y) * w] = 1;
    double removed_by_vertex = 0.0;
    std::vector<double> removed(v.size(), 0.0);
    const auto r = solvers::threshold::limit_slopes(v.data(), w, h, cell, {slope}, fixed.data(), removed.data());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            EXPECT_NEAR(v[std::size_t(y) * w + x], std::min(200.0, slope * cell * x), 1e-9) << x << "," << y;
            removed_by_vertex += removed[std::size_t(y) * w + x];
        }
    EXPECT_NEAR(r.removed, removed_by_vertex, 1e-9);
    // Per column 200 − 7x for x < 29 (x = 0 is the river, already at 0).
    double expected = 0.0;
    for (int x = 1; x < w; ++x) expected += std::max(0.0, 200.0 - 7.0 * x) * h;
    EXPECT_NEAR(r.removed, expected, 1e-6);
}

TEST(ThresholdSlopes, RoughReliefEndsAtTheThresholdWithoutPitsAndNothingRaised) {
    const int w = 83, h = 57;
    const double cell = 30.0;
    const auto before = rough(w, h, 3, 400.0);
    // Two rocks: a strong band of beds (45°) across a weak one (25°).
    std::vector<double> slope(before.size());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            slope[std::size_t(y) * w + x] = std::tan((((x + y) / 9) % 2 ? 45.0 : 25.0) * M_PI / 180.0);
    auto v = before;
    solvers::threshold::limit_slopes(v.data(), w, h, cell, {0.0, slope.data()});
    std::int64_t lowered = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = std::size_t(y) * w + x;
            ASSERT_LE(v[i], before[i]) << "nothing is raised";
            const double straight = slope[i] * cell, diagonal = straight * kSqrt2;
            bool lower = false;
            for (const auto& n : kNeighbours) {
                const int nx = x + n.dx, ny = y + n.dy;
                if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
                const double nb = v[std::size_t(ny) * w + nx], step = n.cells == 1.0 ? straight : diagonal;
                ASSERT_LE(v[i], nb + step) << "steeper than its rock's threshold at " << x << "," << y;
                lower = lower || nb < v[i];
            }
            ASSERT_LE(v[i], bound_at(v, w, h, x, y, straight)) << "a bound left unmet at " << x << "," << y;
            if (v[i] < before[i]) {
                ++lowered;
                EXPECT_EQ(v[i], bound_at(v, w, h, x, y, straight))
                    << "a lowered vertex stands exactly at the bound its neighbours give it";
                EXPECT_TRUE(lower) << "a lowered vertex is not a pit";
            }
        }
    EXPECT_GT(lowered, std::int64_t(v.size() / 10)) << "the rough relief was meant to be far steeper than 25-45°";
}

TEST(ThresholdSlopes, TheSameBitsAsAJacobiIterationAndOnOneAndTwoThreads) {
    // The update is monotone, so every order of updates ends at the one greatest fixed point, bit for bit:
    // the sweeps, Jacobi's all-at-once iteration, and the sweeps on any number of threads.
    // 601 columns: the vertical sweeps run in strips of 256 columns, which meet at two seams.
    // Working memory kept between calls (as a model keeps it between steps) changes no bit, though
    // it comes to each call holding the last one's grids, of another size.
    solvers::threshold::Scratch kept;
    for (const auto [w, h] : {std::pair{97, 64}, std::pair{601, 47}, std::pair{97, 64}}) {
        const double cell = 25.0;
        const auto start = rough(w, h, 11, 600.0);
        std::vector<double> slope(start.size());
        for (std::size_t i = 0; i < slope.size(); ++i) slope[i] = 0.4 + 0.6 * random::uniform(5, i);
        const auto reference = jacobi(start, w, h, cell, slope);
        for (int threads : {1, 2}) {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
            auto v = start;
            solvers::threshold::limit_slopes(v.data(), w, h, cell, {0.0, slope.data()});
            EXPECT_EQ(0, std::memcmp(v.data(), reference.data(), v.size() * sizeof(double)))
                << w << " x " << h << ", " << threads << " threads";
            auto with_kept = start;
            std::vector<double> removed(start.size(), 0.0);
            const auto result = solvers::threshold::limit_slopes(with_kept.data(), w, h, cell, {0.0, slope.data()},
                                                                 nullptr, removed.data(), &kept);
            EXPECT_EQ(0, std::memcmp(with_kept.data(), reference.data(), v.size() * sizeof(double)))
                << w << " x " << h << ", " << threads << " threads, working memory kept";
            std::int64_t lowered = 0;
            for (std::size_t i = 0; i < v.size(); ++i) {
                EXPECT_EQ(removed[i], start[i] - reference[i]);
                lowered += reference[i] < start[i];
            }
            EXPECT_EQ(result.lowered, lowered);
        }
    }
}

TEST(ThresholdSlopes, ABadSlopeOrCellIsRefused) {
    std::vector<double> v(16, 0.0);
    EXPECT_THROW(solvers::threshold::limit_slopes(v.data(), 4, 4, 30.0, {0.0}), std::invalid_argument);
    EXPECT_THROW(solvers::threshold::limit_slopes(v.data(), 4, 4, 30.0, {std::nan("")}), std::invalid_argument);
    EXPECT_THROW(solvers::threshold::limit_slopes(v.data(), 4, 4, 0.0, {0.5}), std::invalid_argument);
}

}  // namespace
