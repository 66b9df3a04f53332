// The SPH eroder on terrain: contact (no particle below the surface),
// conservation of material and particles, determinism, seeds and ditches.
#include "diamond_square.hpp"
#include "shape.hpp"
#include "sph.hpp"

#include <orogen/error.hpp>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

namespace {

using namespace orogen;

constexpr int kSize = 65;  // 64 m × 64 m of 1 m cells: small enough for seconds

std::vector<float> make_shape(shape::Kind kind, double height = 20.0) {
    std::vector<float> h(std::size_t(kSize) * kSize);
    shape::ShapeParams p;
    p.kind = kind;
    p.height = height;
    shape::make_shape(GridView{h.data(), kSize, kSize, 1.0}, p);
    return h;
}

std::vector<float> make_diamond_square(std::uint64_t seed) {
    std::vector<float> h(std::size_t(kSize) * kSize);
    diamond_square::Params p;
    p.amplitude = 15.0;
    p.roughness = 0.6;
    diamond_square::generate(GridView{h.data(), kSize, kSize, 1.0}, p, seed);
    return h;
}

ConstGridView view(const std::vector<float>& h) { return {h.data(), kSize, kSize, 1.0}; }

sph::Settings erosion_settings() {
    sph::Settings s;  // the node's defaults
    s.radius = 0.5;
    s.capacity = 0.5;
    return s;
}

/// Rain for `steps` steps of 0.05 s, 40 particles a step, lifespan 60 steps.
void rain(sph::Simulation& sim, int steps, std::uint64_t seed, int first = 1) {
    for (int step = first; step < first + steps; ++step) {
        sim.rain(40, 2.0, seed, step, 2.0f, 60);
        sim.advance(0.05, step);
        sim.end_step();
    }
}

}  // namespace

TEST(SphContact, NoParticleEverEndsBelowTheSurfaceOnTheShapesAndDiamondSquare) {
    struct Terrain {
        const char* name;
        std::vector<float> h;
    };
    const Terrain terrains[] = {{"crooked", make_shape(shape::Kind::crooked)},
                                {"pyramid", make_shape(shape::Kind::pyramid)},
                                {"hemisphere", make_shape(shape::Kind::hemisphere)},
                                {"diamond-square", make_diamond_square(11)}};
    for (const Terrain& t : terrains) {
        sph::Simulation sim(view(t.h), erosion_settings(), 20000);
        std::int64_t substeps = 0;
        for (int step = 1; step <= 40; ++step) {
            sim.rain(60, 3.0, 5, step, 2.0f, 200);
            double left = 0.05;
            while (left > 0.0) {  // sub-step by sub-step, checking after each
                const double dt = std::min(sim.stable_dt(), left);
                sim.substep(dt);
                left -= dt;
                ++substeps;
                ASSERT_GE(sim.min_clearance(), 0.0) << t.name << ", step " << step << ", sub-step " << substeps;
            }
            sim.end_step();
            ASSERT_GE(sim.min_clearance(), 0.0) << t.name << " after evaporation at step " << step;
        }
        EXPECT_GT(sim.size(), 1000u) << t.name;
        // The water reached the ground and flows on it (contact, not a hover).
        int touching = 0;
        for (const sph::Vec3& p : sim.positions()) touching += (p.y - sim.surface(p.x, p.z)) < 0.5 ? 1 : 0;
        EXPECT_GT(touching, int(sim.size() / 2)) << t.name;
    }
}

TEST(SphContact, FastParticlesAreStoppedByTheTrianglesTheyCross) {
    // A particle fired steeply into a hemisphere must not tunnel through it.
    const std::vector<float> h = make_shape(shape::Kind::hemisphere);
    sph::Settings s = erosion_settings();
    s.erode = false;
    sph::Simulation sim(view(h), s, 16);
    ASSERT_TRUE(sim.add({20.0f, float(sim.surface(20, 30) + 1.0), 30.0f}, {30.0f, -200.0f, 10.0f}, 0.0f, 0));
    for (int i = 0; i < 50; ++i) {
        sim.substep(0.002);
        ASSERT_GE(sim.min_clearance(), 0.0) << "sub-step " << i;
    }
}

TEST(SphConservation, TerrainPlusCarriedPlusRemovedIsConstantAndParticlesAreCounted) {
    for (const auto boundary : {sph::Boundary::closed, sph::Boundary::open}) {
        const std::vector<float> h = make_shape(shape::Kind::pyramid);
        sph::Settings s = erosion_settings();
        s.boundary = boundary;
        // Closed: the pyramid's foot is at 0 m, water that pools there (below 1 m) is
        // removed into the "sea"; open: no sea, the water runs off the edges.
        if (boundary == sph::Boundary::closed) s.sea_level = 1.0;
        sph::Simulation sim(view(h), s, 20000);
        const double before = sim.terrain_volume();
        rain(sim, 80, 3);
        const double terrain = sim.terrain_volume(), carried = sim.carried_sediment(), removed = sim.removed_sediment();
        const double moved = std::abs(terrain - before);
        EXPECT_GT(moved, 1e-3) << "no erosion happened";
        EXPECT_GT(carried, 0.0);
        EXPECT_NEAR(terrain + carried + removed, before, 1e-9 * std::abs(before))
            << "terrain " << terrain << " carried " << carried << " removed " << removed;
        const sph::Counts& c = sim.counts();
        EXPECT_EQ(c.spawned, 80 * 40);
        EXPECT_EQ(c.spawned, std::int64_t(sim.size()) + c.evaporated + c.left + c.sea);
        EXPECT_GT(c.evaporated, 0);
        if (boundary == sph::Boundary::open) {
            EXPECT_GT(c.left, 0);
            EXPECT_EQ(c.sea, 0);
        } else {
            EXPECT_EQ(c.left, 0);
            EXPECT_GT(c.sea, 0);
            EXPECT_EQ(removed, 0.0);
        }
    }
}

TEST(SphDeterminism, SameBytesOnOneAndTwoThreads) {
    const std::vector<float> h = make_diamond_square(3);
    std::vector<std::vector<float>> terrain(2), positions(2);
    for (int threads : {1, 2}) {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
        sph::Simulation sim(view(h), erosion_settings(), 20000);
        rain(sim, 40, 9);
        auto& t = terrain[std::size_t(threads - 1)];
        t.resize(h.size());
        sim.write_terrain(GridView{t.data(), kSize, kSize, 1.0});
        for (const sph::Vec3& p : sim.positions())
            positions[std::size_t(threads - 1)].insert(positions[std::size_t(threads - 1)].end(), {p.x, p.y, p.z});
    }
    ASSERT_EQ(terrain[0].size(), terrain[1].size());
    EXPECT_EQ(0, std::memcmp(terrain[0].data(), terrain[1].data(), terrain[0].size() * sizeof(float)));
    ASSERT_EQ(positions[0].size(), positions[1].size());
    ASSERT_GT(positions[0].size(), 100u);
    EXPECT_EQ(0, std::memcmp(positions[0].data(), positions[1].data(), positions[0].size() * sizeof(float)));
}

// The terrain exchange runs in parallel over fixed chunks of particles, rows two
// chunks share applied afterwards in particle order (settle() in integrator.cpp): every
// vertex must receive its additions in the serial loop's order, so chunks of
// 1000 particles (bands of rows each owns, a few rows shared) and of 3 (every
// row shared by many) on 2 threads give the serial loop's bits: the double
// terrain volume, the carried and removed sediment, the float terrain and
// every particle, with sea kills (closed) and departures over the edges
// (open). Fails when the queued shared rows are dropped (checked); reversing
// the chunk order of the queue was not caught (those additions commuted here).
TEST(SphDeterminism, TheChunkedTerrainExchangeGivesTheSerialLoopsBits) {
    const std::vector<float> h = make_diamond_square(4);
    const double lowest = *std::min_element(h.begin(), h.end());
    for (const auto boundary : {sph::Boundary::closed, sph::Boundary::open}) {
        struct Run {
            double volume = 0, carried = 0, removed = 0;
            std::vector<float> terrain, positions;
            sph::Counts counts;
        };
        std::vector<Run> runs;
        for (const std::size_t chunk : {std::numeric_limits<std::size_t>::max(), std::size_t(1000), std::size_t(3)}) {
            tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
            sph::Settings s = erosion_settings();
            s.boundary = boundary;
            if (boundary == sph::Boundary::closed) s.sea_level = lowest + 2.0;  // m: the lowest pools
            s.settle_chunk = chunk;
            sph::Simulation sim(view(h), s, 20000);
            for (int step = 1; step <= 50; ++step) {  // 100 rain particles a step living 200 steps
                sim.rain(100, 2.0, 11, step, 2.0f, 200);
                sim.advance(0.05, step);
                sim.end_step();
            }
            Run r;
            r.volume = sim.terrain_volume();
            r.carried = sim.carried_sediment();
            r.removed = sim.removed_sediment();
            r.terrain.resize(h.size());
            sim.write_terrain(GridView{r.terrain.data(), kSize, kSize, 1.0});
            for (const sph::Vec3& p : sim.positions()) r.positions.insert(r.positions.end(), {p.x, p.y, p.z});
            r.counts = sim.counts();
            runs.push_back(std::move(r));
        }
        const Run& serial = runs[0];
        ASSERT_GT(serial.positions.size(), 3u * 1000u);  // chunks of 1000: bands of rows owned and shared
        for (std::size_t k = 1; k < runs.size(); ++k) {
            const Run& chunked = runs[k];
            SCOPED_TRACE(k == 1 ? "chunks of 1000" : "chunks of 3");
            EXPECT_EQ(serial.volume, chunked.volume);
            EXPECT_EQ(serial.carried, chunked.carried);
            EXPECT_EQ(serial.removed, chunked.removed);
            EXPECT_EQ(
                0, std::memcmp(serial.terrain.data(), chunked.terrain.data(), serial.terrain.size() * sizeof(float)));
            ASSERT_EQ(serial.positions.size(), chunked.positions.size());
            EXPECT_EQ(0,
                      std::memcmp(serial.positions.data(), chunked.positions.data(),
                                  serial.positions.size() * sizeof(float)));
            EXPECT_EQ(serial.counts.sea, chunked.counts.sea);
            EXPECT_EQ(serial.counts.left, chunked.counts.left);
        }
        if (boundary == sph::Boundary::closed) EXPECT_GT(serial.counts.sea, 0);
        if (boundary == sph::Boundary::open) EXPECT_GT(serial.counts.left, 0);
    }
}

TEST(SphDeterminism, MergingTheParticlesThatChangedCellGivesTheRadixSortsBits) {
    // The sort by cell merges the few particles that changed cell into the others' order (their order
    // from the last sort) instead of radix-sorting all: both must give the same permutation, and with
    // it every neighbour and summation order. Rain keeps adding particles (movers) and they flow.
    const std::vector<float> h = make_diamond_square(4);
    struct Run {
        std::vector<float> terrain, positions, densities;
        std::int64_t merged = 0, substeps = 0;
    };
    std::vector<Run> runs;
    for (const double up_to : {0.0, 0.125, 1.0}) {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
        sph::Settings s = erosion_settings();
        s.merge_movers_up_to = up_to;
        sph::Simulation sim(view(h), s, 20000);
        for (int step = 1; step <= 40; ++step) {
            sim.rain(100, 2.0, 5, step, 2.0f, 200);
            sim.advance(0.05, step);
            sim.end_step();
        }
        Run r;
        r.terrain.resize(h.size());
        sim.write_terrain(GridView{r.terrain.data(), kSize, kSize, 1.0});
        for (const sph::Vec3& p : sim.positions()) r.positions.insert(r.positions.end(), {p.x, p.y, p.z});
        r.densities.assign(sim.densities().begin(), sim.densities().end());
        r.merged = sim.merged_sorts();
        r.substeps = sim.substeps();
        runs.push_back(std::move(r));
    }
    EXPECT_EQ(runs[0].merged, 0);
    EXPECT_GT(2 * runs[1].merged, runs[1].substeps);  // most sub-steps: few particles change cell
    EXPECT_GT(runs[2].merged, runs[1].merged);  // with no limit, more of them
    ASSERT_GT(runs[0].positions.size(), 3u * 2000u);
    for (std::size_t k = 1; k < runs.size(); ++k) {
        SCOPED_TRACE(k == 1 ? "merge up to 1/8 moved" : "merge always");
        ASSERT_EQ(runs[0].positions.size(), runs[k].positions.size());
        EXPECT_EQ(0, std::memcmp(runs[0].positions.data(), runs[k].positions.data(), runs[0].positions.size() * 4));
        EXPECT_EQ(0, std::memcmp(runs[0].densities.data(), runs[k].densities.data(), runs[0].densities.size() * 4));
        EXPECT_EQ(0, std::memcmp(runs[0].terrain.data(), runs[k].terrain.data(), runs[0].terrain.size() * 4));
    }
}

TEST(SphDitches, DifferentSeedsCutDifferentDitchesAndTheSameSeedTheSame) {
    // The thesis (§4.1): its SPH runs gave "totally different surface
    // transformations" each time; here that is the seed's doing, and repeatable.
    const std::vector<float> h = make_shape(shape::Kind::crooked);
    auto change = [&](std::uint64_t seed) {
        sph::Simulation sim(view(h), erosion_settings(), 20000);
        rain(sim, 80, seed);
        std::vector<float> t(h.size());
        sim.write_terrain(GridView{t.data(), kSize, kSize, 1.0});
        for (std::size_t i = 0; i < t.size(); ++i) t[i] -= h[i];
        return t;
    };
    const std::vector<float> a = change(1), a2 = change(1), b = change(2);
    EXPECT_EQ(0, std::memcmp(a.data(), a2.data(), a.size() * sizeof(float)));
    double norm = 0.0, diff = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        norm += double(a[i]) * a[i];
        diff += double(a[i] - b[i]) * (a[i] - b[i]);
    }
    EXPECT_GT(norm, 1e-4) << "no ditches were cut";
    EXPECT_GT(std::sqrt(diff), 0.3 * std::sqrt(norm)) << "two seeds cut nearly the same ditches";
}

TEST(SphFailure, ANonFiniteParticleFailsTheRunNamingTheStepAndTheParticleCount) {
    const std::vector<float> h = make_shape(shape::Kind::pyramid);
    sph::Simulation sim(view(h), erosion_settings(), 100);
    sim.rain(10, 2.0, 1, 1, 2.0f, 10);
    ASSERT_TRUE(sim.add({30.0f, 30.0f, 30.0f}, {std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f}, 0.0f, 0));
    try {
        sim.advance(0.05, 7);
        FAIL() << "a NaN velocity went unnoticed";
    } catch (const Error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("step 7"), std::string::npos) << what;
        EXPECT_NE(what.find("11 particles"), std::string::npos) << what;
        EXPECT_NE(what.find("non-finite"), std::string::npos) << what;
    }
}
