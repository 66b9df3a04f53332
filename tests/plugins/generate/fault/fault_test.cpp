// Fault properties: the per-row difference array gives exactly the thesis's
// cross-product side test; heights are sums of ±displacement; the mean stays.
#include "fault.hpp"

#include <orogen/values.hpp>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>

using namespace orogen;

TEST(Fault, RowDifferencesEqualTheCrossProductTestAtEveryVertex) {
    const int w = 37, h = 23;
    std::vector<fault::Line> lines = fault::random_lines(w, h, 300, 11);
    // Awkward cases: horizontal, vertical, through vertices, diagonal through corners, nearly flat.
    lines.push_back({3, 4, 1, 0});
    lines.push_back({3, 4, -1, 0});
    lines.push_back({5, 0, 0, 1});
    lines.push_back({5, 0, 0, -1});
    lines.push_back({0, 0, 1, 1});
    lines.push_back({36, 22, -1, -1});
    lines.push_back({10, 10, 1, 1e-12});
    lines.push_back({10, 10, -1, -1e-12});
    lines.push_back({-50, 5, 1, 0.01});  // crossing outside the grid
    std::vector<std::int32_t> counts;
    fault::count_sides(counts, w, h, lines);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            int expected = 0;
            for (const auto& l : lines) expected += fault::raised(l, x, y) ? 1 : -1;
            ASSERT_EQ(counts[std::size_t(y) * w + x], expected) << "at " << x << "," << y;
        }
}

TEST(Fault, EveryVertexIsASumOfPlusMinusDisplacementSteps) {
    const int iterations = 201;
    const double d = 0.75;
    Heightmap hm(64, 48, 1.0, 10.0f);
    fault::apply(hm.view(), iterations, d, 5);
    for (float v : hm.heights()) {
        const double steps = (v - 10.0) / d;
        ASSERT_EQ(steps, std::round(steps));
        ASSERT_LE(std::fabs(steps), iterations);
        ASSERT_EQ(std::abs(int(std::lround(steps))) % 2, iterations % 2);  // odd count of ±1
    }
}

TEST(Fault, TheMeanHeightStaysWhereItStarted) {
    // Each run's mean moves by d·Σ(2·f_i − 1), f_i the share raised by line i;
    // which side rises is random, so over many runs the mean change averages out.
    const int runs = 200;
    double sum = 0, sum_sq = 0;
    for (int s = 0; s < runs; ++s) {
        Heightmap hm(48, 48, 1.0, 0.0f);
        fault::apply(hm.view(), 100, 1.0, std::uint64_t(s));
        double mean = 0;
        for (float v : hm.heights()) mean += v;
        mean /= double(hm.size());
        sum += mean;
        sum_sq += mean * mean;
    }
    const double avg = sum / runs;
    const double sd = std::sqrt(sum_sq / runs - avg * avg);
    EXPECT_GT(sd, 0.5);  // individual runs do move (≈ sqrt(100)·E|2f−1|)
    EXPECT_LT(std::fabs(avg), 4.0 * sd / std::sqrt(double(runs)));
}

TEST(Fault, GivesTheSameBytesOnOneAndTwoThreadsAndDependsOnTheSeed) {
    auto run = [](int threads, std::uint64_t seed) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
        Heightmap hm(513, 257, 1.0);
        fault::apply(hm.view(), 300, 1.0, seed);
        return hm.heights();
    };
    EXPECT_EQ(run(1, 9), run(2, 9));
    EXPECT_NE(run(2, 9), run(2, 10));
}
