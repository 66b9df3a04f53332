// Tests of the implicit hillslope-diffusion core: volume with closed sides,
// the error-function solution of a step, the maximum principle at huge time
// steps, fixed sides, nonlinear diffusion, determinism across thread counts.
#include <orogen/solvers/diffusion.hpp>

#include <orogen/random.hpp>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

namespace {

using namespace orogen;

std::vector<double> rough(int w, int h, std::uint64_t seed, double amplitude) {
    std::vector<double> v(std::size_t(w) * std::size_t(h));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            v[std::size_t(y) * w + x] = amplitude * random::uniform(seed, x, y) + 0.01 * amplitude * x;
    return v;
}

double sum(const std::vector<double>& v) {
    double s = 0.0;
    for (double x : v) s += x;
    return s;
}

/// Mean square difference between west–east neighbours, m².
double roughness(const std::vector<double>& v, int w) {
    double s = 0.0;
    for (std::size_t i = 0; i + 1 < v.size(); ++i)
        if ((i + 1) % std::size_t(w) != 0) s += (v[i + 1] - v[i]) * (v[i + 1] - v[i]);
    return s / double(v.size());
}

class Schemes : public ::testing::TestWithParam<solvers::diffusion::Scheme> {};

TEST_P(Schemes, ClosedSidesKeepTheVolumeToRoundOff) {
    const int w = 67, h = 45;
    auto v = rough(w, h, 3, 500.0);
    const double before = sum(v), rough_before = roughness(v, w);
    solvers::diffusion::Settings s;
    s.diffusivity = 0.05;
    s.scheme = GetParam();
    solvers::diffusion::Solver solver(w, h, 30.0, s);
    for (int i = 0; i < 40; ++i) solver.step(v.data(), 5e4);  // r = D dt / cell² ≈ 2.8 per step
    EXPECT_NEAR(sum(v), before, 1e-11 * std::abs(before));
    // It did diffuse: the cell-to-cell roughness is mostly gone.
    EXPECT_LT(roughness(v, w), 0.01 * rough_before);
}

TEST_P(Schemes, StepSpreadsAsTheErrorFunction) {
    // h(x, 0) = H for x < x0, 0 beyond; on an infinite line h(x, t) = H/2 erfc((x − x0)/(2 sqrt(D t))).
    // The grid is wide enough that the closed ends do not matter.
    const int w = 401, h = 5;
    const double cell = 10.0, D = 0.02, H = 100.0, x0 = 200.5 * cell;
    std::vector<double> v(std::size_t(w) * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) v[std::size_t(y) * w + x] = x * cell < x0 ? H : 0.0;
    solvers::diffusion::Settings s;
    s.diffusivity = D;
    s.scheme = GetParam();
    solvers::diffusion::Solver solver(w, h, cell, s);
    const double t = 2e5, dt = 2e3;  // sqrt(D t) = 63 m ≈ 6 cells; r = 0.4
    for (int i = 0; i < int(t / dt); ++i) solver.step(v.data(), dt);
    double worst = 0.0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const double exact = 0.5 * H * std::erfc((x * cell - x0) / (2.0 * std::sqrt(D * t)));
            worst = std::max(worst, std::abs(v[std::size_t(y) * w + x] - exact));
        }
    EXPECT_LT(worst, 0.01 * H) << "largest deviation from the erfc solution, m";
    // The same run with D doubled would give a wider front: the test sees D.
    EXPECT_GT(v[std::size_t(2) * w + 206], 0.5);
}

INSTANTIATE_TEST_SUITE_P(Diffusion, Schemes,
                         ::testing::Values(solvers::diffusion::Scheme::implicit, solvers::diffusion::Scheme::adi),
                         [](const auto& info) {
                             return info.param == solvers::diffusion::Scheme::implicit ? "implicit" : "adi";
                         });

TEST(Diffusion, ImplicitKeepsTheMaximumPrincipleAtHugeSteps) {
    const int w = 64, h = 64;
    auto v = rough(w, h, 11, 300.0);
    const auto [lo0, hi0] = std::minmax_element(v.begin(), v.end());
    const double lo = *lo0, hi = *hi0;
    solvers::diffusion::Settings s;
    s.diffusivity = 1.0;
    solvers::diffusion::Solver solver(w, h, 1.0, s);
    solver.step(v.data(), 1e6);  // r = 1e6
    for (double x : v) {
        ASSERT_TRUE(std::isfinite(x));
        EXPECT_GE(x, lo - 1e-9);
        EXPECT_LE(x, hi + 1e-9);
    }
    // With r this large the surface is almost flat at the mean.
    const auto [a, b] = std::minmax_element(v.begin(), v.end());
    EXPECT_LT(*b - *a, 1.0);
}

TEST(Diffusion, FixedSidesKeepTheirHeightsAndOpenTheVolume) {
    const int w = 40, h = 30;
    auto v = rough(w, h, 5, 100.0);
    for (int x = 0; x < w; ++x) v[std::size_t(x)] = -500.0;  // the north side: a low base level
    const auto before = v;
    solvers::diffusion::Settings s;
    s.diffusivity = 0.1;
    s.fixed.north = true;
    s.fixed.west = true;
    solvers::diffusion::Solver solver(w, h, 10.0, s);
    for (int i = 0; i < 20; ++i) solver.step(v.data(), 1e4);
    for (int x = 0; x < w; ++x) EXPECT_EQ(v[std::size_t(x)], before[std::size_t(x)]);
    for (int y = 0; y < h; ++y) EXPECT_EQ(v[std::size_t(y) * w], before[std::size_t(y) * w]);
    EXPECT_LT(sum(v), sum(before) - 1000.0);  // material left through the low fixed side
}

TEST(Diffusion, CriticalSlopeDiffusionConservesAndFlattensSteepSlopesFaster) {
    const int w = 60, h = 8;
    // A ridge with 45° flanks.
    std::vector<double> lin(std::size_t(w) * h), nonlin;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) lin[std::size_t(y) * w + x] = 300.0 - 10.0 * std::abs(x - 29.5);
    nonlin = lin;
    const double before = sum(lin);
    solvers::diffusion::Settings s;
    s.diffusivity = 0.01;
    solvers::diffusion::Solver a(w, h, 10.0, s);
    s.critical_slope = 1.1;  // 48°
    solvers::diffusion::Solver b(w, h, 10.0, s);
    for (int i = 0; i < 50; ++i) {
        a.step(lin.data(), 1e3);
        b.step(nonlin.data(), 1e3);
    }
    EXPECT_NEAR(sum(nonlin), before, 1e-11 * before);
    const double crest_lin = *std::max_element(lin.begin(), lin.end());
    const double crest_nonlin = *std::max_element(nonlin.begin(), nonlin.end());
    EXPECT_LT(crest_nonlin, crest_lin - 1.0) << "near the critical slope the flux must be several times the linear one";
}

TEST(Diffusion, SameBitsOnOneAndTwoThreads) {
    const int w = 301, h = 203;
    std::vector<double> results[2];
    for (int t = 0; t < 2; ++t) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(t + 1));
        auto v = rough(w, h, 9, 200.0);
        solvers::diffusion::Settings s;
        s.diffusivity = 0.03;
        s.scheme = solvers::diffusion::Scheme::adi;
        s.fixed.east = true;
        solvers::diffusion::Solver solver(w, h, 20.0, s);
        for (int i = 0; i < 5; ++i) solver.step(v.data(), 1e4);
        s.scheme = solvers::diffusion::Scheme::implicit;
        s.critical_slope = 0.8;
        solvers::diffusion::Solver nl(w, h, 20.0, s);
        for (int i = 0; i < 5; ++i) nl.step(v.data(), 1e4);
        results[t] = std::move(v);
    }
    ASSERT_EQ(results[0].size(), results[1].size());
    EXPECT_EQ(0, std::memcmp(results[0].data(), results[1].data(), results[0].size() * sizeof(double)));
}

}  // namespace
