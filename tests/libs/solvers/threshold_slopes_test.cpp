// Tests of the threshold-slope limit (threshold_slopes.hpp): the known surfaces
// it must give (a cone around a fixed point, a plane away from a fixed
// line), the three properties that define it on rough relief (nothing
// steeper than S_c, nothing raised, each lowered vertex held up by the
// neighbour that lowered it, so no pit), and the same bits as a plain
// Jacobi iteration to the fixed point and on any thread count.
#include <orogen/solvers/threshold_slopes.hpp>

#include <orogen/random.hpp>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstring>
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
constexpr Neighbour kNeighbours[] = {{-1, -1, kSqrt2}, {0, -1, 1.0}, {1, -1, kSqrt2}, {-1, 0, 1.0},
                                     {1, 0, 1.0},      {-1, 1, kSqrt2}, {0, 1, 1.0}, {1, 1, kSqrt2}};

/// The definition iterated the simplest way: every vertex from the previous
/// iterate's neighbours at once, until nothing changes.
std::vector<double> jacobi(std::vector<double> v, int w, int h, double cell, const std::vector<double>& slope) {
    for (bool changed = true; changed;) {
        changed = false;
        std::vector<double> next = v;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const std::size_t i = std::size_t(y) * w + x;
                const double straight = slope[i] * cell, diagonal = straight * kSqrt2;
                for (const auto& n : kNeighbours) {
                    const int nx = x + n.dx, ny = y + n.dy;
                    if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
                    const double c = v[std::size_t(ny) * w + nx] + (n.cells == 1.0 ? straight : diagonal);
                    if (c < next[i]) next[i] = c, changed = true;
                }
            }
        v = std::move(next);
    }
    return v;
}

TEST(ThresholdSlopes, AFixedPointOnAHighPlateauBecomesAnOctagonalCone) {
    // Heights 1000 m but the centre, held at 0: the limit is S_c times the shortest 8-neighbour path,
    // max(|dx|,|dy|) − min(|dx|,|dy|) straight steps and min(|dx|,|dy|) diagonal ones.
    const int w = 41, h = 31, cx = 20, cy = 15;
    const double cell = 30.0, slope = std::tan(35.0 * M_PI / 180.0);
    std::vector<double> v(std::size_t(w) * h, 1000.0);
    std::vector<std::uint8_t> fixed(v.size(), 0);
    v[std::size_t(cy) * w + cx] = 0.0;
    fixed[std::size_t(cy) * w + cx] = 1;
    const auto r = threshold::limit_slopes(v.data(), w, h, cell, {slope}, fixed.data());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const int ax = std::abs(x - cx), ay = std::abs(y - cy);
            const double path = double(std::max(ax, ay) - std::min(ax, ay)) + kSqrt2 * std::min(ax, ay);
            const double expected = std::min(1000.0, slope * cell * path);
            EXPECT_NEAR(v[std::size_t(y) * w + x], expected, 1e-9 * 1000.0) << x << "," << y;
        }
    EXPECT_GT(r.lowered, 0);
    EXPECT_GE(r.rounds, 2) << "the last round must be one that changed nothing";
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
    const auto r = threshold::limit_slopes(v.data(), w, h, cell, {slope}, fixed.data(), removed.data());
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
        for (int x = 0; x < w; ++x) slope[std::size_t(y) * w + x] = std::tan((((x + y) / 9) % 2 ? 45.0 : 25.0) * M_PI / 180.0);
    auto v = before;
    threshold::limit_slopes(v.data(), w, h, cell, {0.0, slope.data()});
    std::int64_t lowered = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = std::size_t(y) * w + x;
            ASSERT_LE(v[i], before[i]) << "nothing is raised";
            const double straight = slope[i] * cell, diagonal = straight * kSqrt2;
            bool held = false, lower = false;
            for (const auto& n : kNeighbours) {
                const int nx = x + n.dx, ny = y + n.dy;
                if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
                const double nb = v[std::size_t(ny) * w + nx], step = n.cells == 1.0 ? straight : diagonal;
                ASSERT_LE(v[i], nb + step) << "steeper than its rock's threshold at " << x << "," << y;
                held = held || v[i] == nb + step;
                lower = lower || nb < v[i];
            }
            if (v[i] < before[i]) {
                ++lowered;
                EXPECT_TRUE(held) << "a lowered vertex stands exactly S_c·d above the neighbour that holds it";
                EXPECT_TRUE(lower) << "a lowered vertex is not a pit";
            }
        }
    EXPECT_GT(lowered, std::int64_t(v.size() / 10)) << "the rough relief was meant to be far steeper than 25-45°";
}

TEST(ThresholdSlopes, TheSameBitsAsAJacobiIterationAndOnOneAndTwoThreads) {
    // The update is monotone, so every order of updates ends at the one greatest fixed point, bit for bit:
    // the sweeps, Jacobi's all-at-once iteration, and the sweeps on any number of threads.
    // 601 columns: the vertical sweeps run in strips of 256 columns, which meet at two seams.
    for (const auto [w, h] : {std::pair{97, 64}, std::pair{601, 47}}) {
        const double cell = 25.0;
        const auto start = rough(w, h, 11, 600.0);
        std::vector<double> slope(start.size());
        for (std::size_t i = 0; i < slope.size(); ++i) slope[i] = 0.4 + 0.6 * random::uniform(5, i);
        const auto reference = jacobi(start, w, h, cell, slope);
        for (int threads : {1, 2}) {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
            auto v = start;
            threshold::limit_slopes(v.data(), w, h, cell, {0.0, slope.data()});
            EXPECT_EQ(0, std::memcmp(v.data(), reference.data(), v.size() * sizeof(double)))
                << w << " x " << h << ", " << threads << " threads";
        }
    }
}

TEST(ThresholdSlopes, ABadSlopeOrCellIsRefused) {
    std::vector<double> v(16, 0.0);
    EXPECT_THROW(threshold::limit_slopes(v.data(), 4, 4, 30.0, {0.0}), std::invalid_argument);
    EXPECT_THROW(threshold::limit_slopes(v.data(), 4, 4, 30.0, {std::nan("")}), std::invalid_argument);
    EXPECT_THROW(threshold::limit_slopes(v.data(), 4, 4, 0.0, {0.5}), std::invalid_argument);
}

}  // namespace
