// Tests of Olsen's hydraulic automaton: the two flow cases by hand, mass
// balance, steepness hardness, continuation, determinism across threads.
#include "hydraulic.hpp"

#include <orogen/random.hpp>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstring>
#include <utility>
#include <vector>

namespace {

using namespace orogen;

struct Grid {
    int w, h;
    double cell;
    std::vector<float> height, water, sediment;
    Grid(int w_, int h_, double cell_ = 1.0)
        : w(w_), h(h_), cell(cell_), height(std::size_t(w_) * h_), water(height.size()), sediment(height.size()) {}
    hydraulic::State state() {
        return {{height.data(), w, h, cell}, {water.data(), w, h, cell}, {sediment.data(), w, h, cell}};
    }
};

double total(const std::vector<float>& v) {
    double s = 0.0;
    for (float x : v) s += x;
    return s;
}

Grid noise_terrain(int w, int h, std::uint64_t seed) {
    Grid g(w, h, 2.0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            g.height[std::size_t(y) * w + x] =
                20.0f * float(random::uniform(seed, x, y)) + 30.0f * std::sin(0.08f * float(x)) + 0.3f * float(y);
    return g;
}

hydraulic::Settings no_sources() {
    hydraulic::Settings s;
    s.rain = 0.0;
    s.solubility = 0.0;
    s.evaporation = 0.0;
    s.capacity = 1e6;
    return s;
}

TEST(Hydraulic, OlsenLevelsOutWhenWaterExceedsTheAltitudeDrop) {
    Grid g(3, 1);
    g.water = {0.0f, 3.0f, 0.0f};
    hydraulic::erode(g.state(), 1, no_sources());
    // a = (0, 3, 0): ā = 1, a − ā = 2 < water 3: move 2, one to each side.
    EXPECT_EQ(g.water, (std::vector<float>{1.0f, 1.0f, 1.0f}));
}

TEST(Hydraulic, OlsenDrainsCompletelyWhenTheDropExceedsTheWater) {
    Grid g(3, 1);
    g.height = {0.0f, 5.0f, 0.0f};
    g.water = {0.0f, 1.0f, 0.0f};
    g.sediment = {0.0f, 0.5f, 0.0f};
    hydraulic::erode(g.state(), 1, no_sources());
    // a = (0, 6, 0): a − ā = 4 > water 1: all water leaves, half each way, with its sediment.
    EXPECT_EQ(g.water, (std::vector<float>{0.5f, 0.0f, 0.5f}));
    EXPECT_EQ(g.sediment, (std::vector<float>{0.25f, 0.0f, 0.25f}));
    EXPECT_EQ(g.height, (std::vector<float>{0.0f, 5.0f, 0.0f}));
}

// The `flow` layer: what each cell sends downhill in the next step, in both
// of Olsen's cases, and nothing where there is no drop.
TEST(Hydraulic, OutflowIsTheWaterTheNextStepMoves) {
    auto outflow = [](Grid& g) {
        std::vector<float> flow(g.height.size(), -1.0f);
        hydraulic::outflow({{g.height.data(), g.w, g.h, g.cell},
                            {g.water.data(), g.w, g.h, g.cell},
                            {g.sediment.data(), g.w, g.h, g.cell}},
                           no_sources(), nullptr, GridView{flow.data(), g.w, g.h, g.cell});
        return flow;
    };
    Grid level(3, 1);
    level.water = {0.0f, 3.0f, 0.0f};  // levels out: moves a − ā = 2
    EXPECT_EQ(outflow(level), (std::vector<float>{0.0f, 2.0f, 0.0f}));
    Grid drain(3, 1);
    drain.height = {0.0f, 5.0f, 0.0f};
    drain.water = {0.0f, 1.0f, 0.0f};  // drains completely: moves all its water
    EXPECT_EQ(outflow(drain), (std::vector<float>{0.0f, 1.0f, 0.0f}));
    // A column on a 5 × 4 plain (rows of padding and edges included): only the column gives.
    Grid column(5, 4);
    column.height[std::size_t(2) * 5 + 2] = 10.0f;
    for (float& w : column.water) w = 0.5f;
    const auto flow = outflow(column);
    for (std::size_t i = 0; i < flow.size(); ++i) EXPECT_EQ(flow[i], i == 2 * 5 + 2 ? 0.5f : 0.0f) << i;
    // And it is what a step moves: on noise, the water leaving each cell (its
    // water minus what it kept, with no inflow where nothing is higher) is
    // bounded by its water, and zero exactly where no neighbour is lower.
    Grid g = noise_terrain(37, 29, 8);
    for (std::size_t i = 0; i < g.water.size(); ++i) g.water[i] = 0.01f * float(i % 7);
    const auto f = outflow(g);
    int giving = 0;
    for (int y = 0; y < g.h; ++y)
        for (int x = 0; x < g.w; ++x) {
            const std::size_t i = std::size_t(y) * g.w + x;
            const float a = g.height[i] + g.water[i];
            bool lower = false;
            for (auto [dx, dy] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
                const int nx = x + dx, ny = y + dy;
                if (nx < 0 || ny < 0 || nx >= g.w || ny >= g.h) continue;
                const std::size_t j = std::size_t(ny) * g.w + nx;
                lower = lower || g.height[j] + g.water[j] < a;
            }
            EXPECT_GE(f[i], 0.0f);
            EXPECT_LE(f[i], g.water[i] * (1.0f + 1e-6f));
            if (!lower || g.water[i] == 0.0f) EXPECT_EQ(f[i], 0.0f) << x << "," << y;
            giving += f[i] > 0.0f;
        }
    EXPECT_GT(giving, 100);
    // Chunks of rows (each with its own halo) give the same bytes as one.
    Grid big = noise_terrain(161, 300, 9);
    for (std::size_t i = 0; i < big.water.size(); ++i) big.water[i] = 0.02f * float(i % 5);
    std::vector<float> one, two;
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
        one = outflow(big);
    }
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
        two = outflow(big);
    }
    EXPECT_EQ(std::memcmp(one.data(), two.data(), one.size() * sizeof(float)), 0);
    // Every cell, across the chunks' seams, against Olsen's rule in double:
    // moved = min(water, D/(1 + n)), D the sum of the n drops to lower neighbours.
    for (int y = 0; y < big.h; ++y)
        for (int x = 0; x < big.w; ++x) {
            const std::size_t i = std::size_t(y) * big.w + x;
            const double a = double(big.height[i]) + double(big.water[i]);
            double drops = 0.0;
            int n = 0;
            for (auto [dx, dy] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
                const int nx = x + dx, ny = y + dy;
                if (nx < 0 || ny < 0 || nx >= big.w || ny >= big.h) continue;
                const std::size_t j = std::size_t(ny) * big.w + nx;
                const double d = a - (double(big.height[j]) + double(big.water[j]));
                if (d > 0.0) drops += d, ++n;
            }
            const double moved = std::min(double(big.water[i]), drops / (1.0 + n));
            ASSERT_NEAR(one[i], moved, 1e-5 * (1.0 + moved)) << x << "," << y;
        }
}

// The `hardness` layer of hardness=steepness: 1 on flat ground, 1 − (1 − 1/√2)³ on a 45° slope.
TEST(Hydraulic, SteepnessHardnessLayerFollowsTheSlope) {
    const int w = 6, h = 5;
    std::vector<float> plane(std::size_t(w) * h), out(plane.size(), -1.0f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) plane[std::size_t(y) * w + x] = 2.0f * float(x);  // 45° on 2 m cells
    hydraulic::steepness_hardness(ConstGridView{plane.data(), w, h, 2.0}, GridView{out.data(), w, h, 2.0});
    const double expected = 1.0 - std::pow(1.0 - 1.0 / std::sqrt(2.0), 3.0);
    for (float k : out) EXPECT_NEAR(k, expected, 1e-6);
    std::vector<float> flat(plane.size(), 7.0f);
    hydraulic::steepness_hardness(ConstGridView{flat.data(), w, h, 2.0}, GridView{out.data(), w, h, 2.0});
    for (float k : out) EXPECT_EQ(k, 1.0f);
}

TEST(Hydraulic, ConservesTerrainPlusSediment) {
    Grid g = noise_terrain(97, 83, 4);
    const double before = total(g.height);
    hydraulic::Settings s;  // thesis defaults: rain 0.01, Ks 0.01, Ke 0.5, Kc 0.05
    s.solubility = 0.05;
    hydraulic::erode(g.state(), 300, s);
    const double after = total(g.height) + total(g.sediment);
    EXPECT_NEAR(after, before, 1e-7 * std::fabs(before) + 1e-3);
    // And something really moved.
    EXPECT_GT(total(g.sediment), 0.0);
    double moved = 0.0;
    Grid g0 = noise_terrain(97, 83, 4);
    for (std::size_t i = 0; i < g.height.size(); ++i) moved += std::fabs(double(g.height[i]) - g0.height[i]);
    EXPECT_GT(moved, 1.0);
}

TEST(Hydraulic, ConservesWaterWithoutRainOrEvaporation) {
    Grid g = noise_terrain(65, 65, 8);
    for (auto& w : g.water) w = 0.5f;
    const double before = total(g.water);
    hydraulic::Settings s = no_sources();
    s.solubility = 0.02;
    hydraulic::erode(g.state(), 500, s);
    EXPECT_NEAR(total(g.water), before, 1e-6 * before);
}

TEST(Hydraulic, WaterRunsDownhill) {
    Grid g(40, 40, 1.0);
    for (int y = 0; y < 40; ++y)
        for (int x = 0; x < 40; ++x) g.height[std::size_t(y) * 40 + x] = 0.5f * float(x);  // low in the west
    hydraulic::Settings s = no_sources();
    s.rain = 0.01;
    hydraulic::erode(g.state(), 200, s);
    double west = 0.0, east = 0.0;
    for (int y = 0; y < 40; ++y) {
        west += g.water[std::size_t(y) * 40 + 0];
        east += g.water[std::size_t(y) * 40 + 39];
    }
    EXPECT_GT(west, 100.0 * east);
}

TEST(Hydraulic, SteepnessHardnessLeavesFlatGroundAlone) {
    Grid g(33, 33);
    for (auto& h : g.height) h = 10.0f;
    hydraulic::Settings s;
    s.solubility = 0.5;
    hydraulic::erode(g.state(), 20, s);
    for (float h : g.height) ASSERT_EQ(h, 10.0f);
    // Constant hardness dissolves flat ground too.
    s.hardness = hydraulic::Hardness::constant;
    hydraulic::erode(g.state(), 1, s);
    EXPECT_LT(g.height[33 * 16 + 16], 10.0f);
}

TEST(Hydraulic, HardLayerStopsDissolving) {
    Grid g = noise_terrain(40, 30, 2);
    const auto before = g.height;
    std::vector<float> hard(g.height.size(), 1.0f);
    hydraulic::Settings s;
    s.hardness = hydraulic::Hardness::layer;
    s.capacity = 1e6;  // nothing to deposit either
    hydraulic::erode(g.state(), 10, s, hard.data());
    EXPECT_EQ(g.height, before);
}

TEST(Hydraulic, TwoRunsInARowEqualOneLongerRun) {
    Grid a = noise_terrain(50, 40, 6), b = a;
    hydraulic::Settings s;
    hydraulic::erode(a.state(), 60, s);
    hydraulic::erode(b.state(), 25, s);
    hydraulic::erode(b.state(), 35, s);
    EXPECT_EQ(a.height, b.height);
    EXPECT_EQ(a.water, b.water);
    EXPECT_EQ(a.sediment, b.sediment);
}

TEST(Hydraulic, SameBytesOnOneAndTwoThreads) {
    Grid a = noise_terrain(301, 257, 12), b = a;
    hydraulic::Settings s;
    {
        tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        hydraulic::erode(a.state(), 30, s);
    }
    {
        tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);
        hydraulic::erode(b.state(), 30, s);
    }
    EXPECT_EQ(std::memcmp(a.height.data(), b.height.data(), a.height.size() * 4), 0);
    EXPECT_EQ(std::memcmp(a.water.data(), b.water.data(), a.water.size() * 4), 0);
    EXPECT_EQ(std::memcmp(a.sediment.data(), b.sediment.data(), a.sediment.size() * 4), 0);
}

}  // namespace
