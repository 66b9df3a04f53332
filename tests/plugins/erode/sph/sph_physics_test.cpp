// The SPH core's neighbour sums against the sum over all pairs. (The physics, a dam break against Martin &
// Moyce's measurements and a resting tank against hydrostatics, is sph_validation_test.cpp.)
#include "sph.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace {

using namespace orogen;

struct Flat {
    std::vector<float> h;
    ConstGridView view;
    Flat(int w, int d, double cell) : h(std::size_t(w) * std::size_t(d), 0.0f), view(h.data(), w, d, cell) {}
};

sph::Settings fluid(double radius, double sound_speed, double viscosity) {
    sph::Settings s;
    s.radius = radius;
    s.sound_speed = sound_speed;
    s.viscosity = viscosity;
    s.friction = 0.0;  // free slip on the floor: Martin & Moyce's tank was smooth
    s.erode = false;
    return s;
}

}  // namespace

// Martin & Moyce's dam break and hydrostatics are in sph_validation_test.cpp: in 3-D, in a tank with side
// walls (the map's closed edges carry the same boundary term as the terrain).

// The cell list finds every neighbour once: each particle's density equals the sum of the kernel over
// all pairs (O(n²), in double) for a clumpy cloud whose cells are unevenly filled, well above the floor
// (so no terrain term). A missed row of cells or a cell visited twice shifts a density by at least one
// near neighbour's W, far above float round-off (relative 1e-5 here; the sums are ~360 terms).
TEST(SphNeighbours, DensityEqualsTheSumOverAllPairs) {
    const Flat floor(41, 41, 0.05);
    sph::Settings set = fluid(0.05, 20.0, 0.05);
    const double h = 4 * set.radius, spacing = 2 * set.radius, mass = 1000.0 * spacing * spacing * spacing;
    const int count = 3000;
    sph::Simulation sim(floor.view, set, count);
    std::uint64_t state = 12345;  // a small LCG: any fixed cloud will do
    const auto next = [&] {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return double(state >> 11) / double(1ull << 53);
    };
    for (int k = 0; k < count; ++k) {
        const double u = next(), v = next(), w = next();
        ASSERT_TRUE(sim.add({float(0.5 + 0.6 * u * u), float(1.0 + 0.5 * v), float(0.5 + 0.6 * w)}, {}, 0.0f, 0));
    }
    sim.substep(0.0);  // sorts, sums the densities, moves nothing
    const auto pos = sim.positions();
    const auto rho = sim.densities();
    ASSERT_EQ(pos.size(), std::size_t(count));
    for (std::size_t i = 0; i < pos.size(); ++i) {
        double sum = 0.0;
        for (std::size_t j = 0; j < pos.size(); ++j) {
            const double dx = pos[i].x - pos[j].x, dy = pos[i].y - pos[j].y, dz = pos[i].z - pos[j].z;
            const double q = std::sqrt(dx * dx + dy * dy + dz * dz) / h;
            if (q < 1.0) sum += q <= 0.5 ? 6.0 * q * q * (q - 1.0) + 1.0 : 2.0 * (1.0 - q) * (1.0 - q) * (1.0 - q);
        }
        const double expect = mass * 8.0 / (3.14159265358979323846 * h * h * h) * sum;
        ASSERT_NEAR(rho[i], expect, 1e-5 * expect) << "particle " << i;
    }
}

// The map's closed edges carry the terrain's boundary term (the fluid's rest lattice continued behind them),
// with the quadrant where two walls meet counted once and the octant where the floor and two walls meet
// added back: a block of the rest lattice filling a closed tank has the interior's density at every wall,
// edge and corner (to float round-off), where without the walls' term a wall particle lacked up to 7/8 of it.
TEST(SphWalls, RestLatticeHasTheInteriorsDensityAtWallsEdgesAndCorners) {
    const int n = 8;
    const double s = 0.01;
    const Flat tank(n + 1, n + 1, s);  // walls at x, z = 0 and n·s
    sph::Simulation sim(tank.view, fluid(s / 2.0, 10.0, 0.05), n * n * n);
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i)
                ASSERT_TRUE(sim.add({float((i + 0.5) * s), float((j + 0.5) * s), float((k + 0.5) * s)}, {}, 0.0f, 0));
    sim.substep(0.0);  // densities only
    const auto pos = sim.positions();
    const auto rho = sim.densities();
    float interior = 0.0f;
    for (std::size_t i = 0; i < pos.size(); ++i)
        if (std::abs(pos[i].x - 4.5 * s) < 0.1 * s && std::abs(pos[i].y - 3.5 * s) < 0.1 * s &&
            std::abs(pos[i].z - 4.5 * s) < 0.1 * s)
            interior = rho[i];
    EXPECT_NEAR(interior, 1000.0f, 0.1f);
    int checked = 0;
    for (std::size_t i = 0; i < pos.size(); ++i) {
        if (pos[i].y > (n - 2) * s) continue;  // the free surface's particles lack their kernel above
        EXPECT_NEAR(rho[i], interior, 1e-4f * interior)
            << "particle at " << pos[i].x << ", " << pos[i].y << ", " << pos[i].z;
        ++checked;
    }
    EXPECT_EQ(checked, n * n * (n - 2));
}
