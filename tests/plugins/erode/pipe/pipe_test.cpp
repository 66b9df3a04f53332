// Tests of the Mei et al. pipe model: rest, conservation, stability at any
// time step, channels, continuation, determinism across thread counts.
#include "pipe.hpp"

#include <orogen/error.hpp>
#include <orogen/random.hpp>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <vector>

namespace {

using namespace orogen;

/// Owns every state array of a w × h simulation.
struct Sim {
    int w, h;
    double cell;
    std::vector<float> height, water, sediment, fw, fe, fn, fs, speed;
    Sim(int w_, int h_, double cell_)
        : w(w_), h(h_), cell(cell_), height(std::size_t(w_) * h_), water(height.size()), sediment(height.size()),
          fw(height.size()), fe(height.size()), fn(height.size()), fs(height.size()), speed(height.size()) {}
    GridView g(std::vector<float>& v) { return {v.data(), w, h, cell}; }
    pipe::State state() { return {g(height), g(water), g(sediment), g(fw), g(fe), g(fn), g(fs), g(speed)}; }
    float& at(std::vector<float>& v, int x, int y) { return v[std::size_t(y) * w + x]; }
    /// Run `steps` steps of `dt` in one solver; returns the number of sub-steps.
    std::int64_t run(const pipe::Settings& s, int steps, double dt, const float* mask = nullptr) {
        pipe::Solver solver(state(), s, mask);
        for (int i = 1; i <= steps; ++i) solver.advance(dt, i);
        solver.finish();
        return solver.substeps();
    }
};

double total(const std::vector<float>& v) {
    double t = 0.0;
    for (float x : v) t += x;
    return t;
}

pipe::Settings closed_no_sources() {
    pipe::Settings s;
    s.rain = 0.0;
    s.evaporation = 0.0;
    return s;
}

/// A bowl whose heights are multiples of 1/1024 m, so level − height is exact.
Sim bowl(int n, float level) {
    Sim sim(n, n, 1.0);
    const float c = float(n - 1) / 2.0f;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const float r2 = (float(x) - c) * (float(x) - c) + (float(y) - c) * (float(y) - c);
            const float b = std::round(0.01f * r2 * 1024.0f) / 1024.0f;
            sim.at(sim.height, x, y) = b;
            sim.at(sim.water, x, y) = std::max(0.0f, level - b);
        }
    return sim;
}

TEST(Pipe, LakeAtRestStaysAtRest) {
    Sim sim = bowl(49, 3.0f);
    const auto water0 = sim.water;
    const auto height0 = sim.height;
    sim.run(closed_no_sources(), 2000, 0.1);
    float vmax = 0.0f;
    for (float v : sim.speed) vmax = std::max(vmax, v);
    EXPECT_LT(vmax, 1e-6f);
    EXPECT_EQ(sim.water, water0);
    EXPECT_EQ(sim.height, height0);
}

TEST(Pipe, ConservesWaterAndMaterialOver10000Steps) {
    // A sloshing lake on rough ground: water moves, erodes and deposits.
    Sim sim = bowl(41, 3.0f);
    for (int y = 0; y < sim.h; ++y)
        for (int x = 0; x < sim.w; ++x) {
            sim.at(sim.height, x, y) += 0.2f * float(random::uniform(3, x, y));
            if (sim.at(sim.water, x, y) > 0.0f) sim.at(sim.water, x, y) += 0.05f * float(x);  // tilted surface
        }
    const double water0 = total(sim.water);
    const double material0 = total(sim.height) + total(sim.sediment);
    pipe::Settings s = closed_no_sources();
    s.capacity = 0.5;
    const std::int64_t subs = sim.run(s, 10000, 0.05);
    EXPECT_GE(subs, 10000);
    EXPECT_NEAR(total(sim.water), water0, 1e-5 * water0);
    EXPECT_NEAR(total(sim.height) + total(sim.sediment), material0, 1e-5 * material0);
    // It did move material.
    EXPECT_GT(total(sim.sediment), 1e-3);
}

// The same with the node's default creep (diffusion of the terrain, pair
// terms): terrain + sediment still conserved, and the terrain does smooth.
TEST(Pipe, ConservesMaterialWithCreep) {
    Sim sim = bowl(41, 3.0f);
    for (int y = 0; y < sim.h; ++y)
        for (int x = 0; x < sim.w; ++x) sim.at(sim.height, x, y) += 0.2f * float(random::uniform(3, x, y));
    const auto height0 = sim.height;
    const double water0 = total(sim.water);
    const double material0 = total(sim.height) + total(sim.sediment);
    pipe::Settings s = closed_no_sources();
    s.capacity = 0.5;
    s.creep = 0.2;
    sim.run(s, 3000, 0.05);
    EXPECT_NEAR(total(sim.water), water0, 1e-5 * water0);
    EXPECT_NEAR(total(sim.height) + total(sim.sediment), material0, 1e-5 * material0);
    // Creep smoothed the noise: the mean |laplacian| dropped.
    auto roughness = [&](const std::vector<float>& v) {
        double r = 0.0;
        for (int y = 1; y < sim.h - 1; ++y)
            for (int x = 1; x < sim.w - 1; ++x) {
                const std::size_t i = std::size_t(y) * sim.w + x;
                r += std::fabs(4.0 * v[i] - v[i - 1] - v[i + 1] - v[i - sim.w] - v[i + sim.w]);
            }
        return r;
    };
    EXPECT_LT(roughness(sim.height), 0.5 * roughness(height0));
}

TEST(Pipe, AnyTimeStepStaysFiniteAndNonNegative) {
    for (double dt : {1e-4, 0.5, 5.0, 60.0}) {
        Sim sim(40, 33, 2.0);
        for (int y = 0; y < sim.h; ++y)
            for (int x = 0; x < sim.w; ++x)
                sim.at(sim.height, x, y) = 30.0f * float(random::uniform(5, x, y)) + 0.5f * float(x);
        pipe::Settings s;
        s.rain = 0.01;
        const std::int64_t subs = sim.run(s, 12, dt);
        if (dt >= 5.0) EXPECT_GT(subs, 12) << "a long step must be split";
        for (auto* v : {&sim.height, &sim.water, &sim.sediment, &sim.speed})
            for (float x : *v) ASSERT_TRUE(std::isfinite(x)) << "dt " << dt;
        for (float d : sim.water) ASSERT_GE(d, 0.0f);
        EXPECT_GT(total(sim.water), 0.0);
    }
}

TEST(Pipe, NonFiniteInputFailsNamingTheStep) {
    Sim sim(20, 20, 1.0);
    sim.at(sim.height, 5, 5) = std::numeric_limits<float>::quiet_NaN();
    pipe::Solver solver(sim.state(), pipe::Settings{});
    try {
        solver.advance(0.01, 7);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_STREQ(e.what(),
                     "non-finite terrain, water or sediment at step 7 (sub-step 1, dt 0.01 s); the simulation "
                     "became unstable");
    }
}

/// A plane falling south at `slope`, with a little seeded roughness.
Sim tilted_plane(int n, float slope, std::uint64_t seed) {
    Sim sim(n, n, 1.0);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
            sim.at(sim.height, x, y) = slope * float(n - 1 - y) + 0.05f * float(random::uniform(seed, x, y));
    return sim;
}

TEST(Pipe, RainOnATiltedPlaneCarvesChannelsAndDepositsAtTheFoot) {
    const int n = 81;
    Sim sim = tilted_plane(n, 0.3f, 21);
    const auto height0 = sim.height;
    pipe::Settings s;
    s.rain = 0.002;
    s.evaporation = 0.0;
    s.capacity = 0.3;
    sim.run(s, 600, 0.1);
    std::vector<double> change(sim.height.size());
    for (std::size_t i = 0; i < change.size(); ++i) change[i] = double(sim.height[i]) - height0[i];
    // A network: on a row across the upper slope, erosion varies strongly from
    // cell to cell (channels between ridges), not a uniform lowering.
    int channels = 0;
    double row_min = 0.0, row_mean = 0.0;
    const int y = n / 2;
    for (int x = 2; x < n - 2; ++x) {
        const double c = change[std::size_t(y) * n + x];
        row_min = std::min(row_min, c);
        row_mean += c / double(n - 4);
    }
    for (int x = 2; x < n - 2; ++x) {
        const double c = change[std::size_t(y) * n + x];
        const double l = change[std::size_t(y) * n + x - 1], r = change[std::size_t(y) * n + x + 1];
        if (c < l && c < r && c < 0.5 * row_min) ++channels;  // a local trough of real depth
    }
    EXPECT_GE(channels, 3) << "mean change " << row_mean << " deepest " << row_min;
    EXPECT_LT(row_min, 2.0 * row_mean);
    // Deposits at the foot (the southern rows), erosion above.
    double foot = 0.0, slope_part = 0.0;
    for (int yy = 0; yy < n; ++yy)
        for (int x = 0; x < n; ++x) (yy >= n - 6 ? foot : slope_part) += change[std::size_t(yy) * n + x];
    EXPECT_GT(foot, 0.0);
    EXPECT_LT(slope_part, 0.0);
}

TEST(Pipe, TwoRunsInARowEqualOneLongerRun) {
    Sim a = tilted_plane(37, 0.2f, 4);
    Sim b = a;
    pipe::Settings s;
    s.rain = 0.003;
    a.run(s, 50, 0.3);
    b.run(s, 20, 0.3);
    b.run(s, 30, 0.3);
    EXPECT_EQ(a.height, b.height);
    EXPECT_EQ(a.water, b.water);
    EXPECT_EQ(a.sediment, b.sediment);
    EXPECT_EQ(a.speed, b.speed);
}

TEST(Pipe, OpenBoundaryLetsWaterLeave) {
    Sim closed = tilted_plane(33, 0.3f, 2), open = closed;
    pipe::Settings s;
    s.rain = 0.005;
    s.evaporation = 0.0;
    closed.run(s, 300, 0.1);
    s.boundary = pipe::Boundary::open;
    open.run(s, 300, 0.1);
    const double rained = 0.005 * 300 * 0.1 * 33 * 33;
    EXPECT_NEAR(total(closed.water), rained, 1e-4 * rained);
    EXPECT_LT(total(open.water), 0.8 * rained);
}

TEST(Pipe, RainMaskLimitsWhereItRains) {
    Sim sim(30, 30, 1.0);  // flat, dry
    std::vector<float> mask(sim.height.size(), 0.0f);
    for (int y = 0; y < 30; ++y)
        for (int x = 0; x < 15; ++x) mask[std::size_t(y) * 30 + x] = 1.0f;
    pipe::Settings s;
    s.rain = 0.01;
    s.evaporation = 0.0;
    sim.run(s, 1, 0.01, mask.data());
    EXPECT_GT(sim.at(sim.water, 3, 3), 0.0f);
    EXPECT_EQ(sim.at(sim.water, 28, 3), 0.0f);
}

TEST(Pipe, SameBytesOnOneAndTwoThreads) {
    Sim a = tilted_plane(203, 0.25f, 9), b = a;
    pipe::Settings s;
    s.rain = 0.004;
    {
        tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        a.run(s, 40, 0.2);
    }
    {
        tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);
        b.run(s, 40, 0.2);
    }
    for (auto [x, y] : {std::pair{&a.height, &b.height},
                        {&a.water, &b.water},
                        {&a.sediment, &b.sediment},
                        {&a.fw, &b.fw},
                        {&a.speed, &b.speed}})
        EXPECT_EQ(std::memcmp(x->data(), y->data(), x->size() * sizeof(float)), 0);
}

}  // namespace
