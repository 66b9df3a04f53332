// bench-links: TBB::tbb
// One SPH sub-step of orogen::sph::Simulation (neighbour search + density +
// forces + terrain contact + erosion), 2 threads unless said otherwise.
// Targets (issue 11, 2 cores): 100,000 particles on a 1025² terrain ≤ 15 ms,
// 1,000,000 ≤ 150 ms.
//   terrain: a 1025² terrain (1 m cells, hills of 100 m), the particles as a
//            sheet of water 3 particles deep flowing over its middle (every
//            particle has full neighbourhoods, touches the terrain, erodes).
//   dambreak: SPlisHSPlasH's dam break at its size: a 45³ = 91,125 particle
//            block in a box, for the side-by-side with SPHSimulator.
#include "sph.hpp"

#include <orogen/random.hpp>

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <cmath>
#include <vector>

namespace {

using namespace orogen;

std::vector<float> hills(int n) {
    std::vector<float> h(std::size_t(n) * n);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
            h[std::size_t(y) * n + x] =
                float(50.0 + 50.0 * std::sin(0.006 * x) * std::cos(0.005 * y) + 0.5 * random::uniform(1, x, y));
    return h;
}

void BM_sph_step_terrain(benchmark::State& state) {
    const auto count = std::size_t(state.range(0));
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, std::size_t(state.range(1)));
    const int n = 1025;
    const std::vector<float> h = hills(n);
    sph::Settings s;  // node defaults: radius 0.5 m (spacing 1 m)
    sph::Simulation sim(ConstGridView(h.data(), n, n, 1.0), s, count);
    // A sheet of water, 3 particles deep, on a square patch in the middle.
    const int side = int(std::ceil(std::sqrt(double(count) / 3.0)));
    const double x0 = 512.0 - side / 2.0;
    for (std::size_t k = 0; k < count; ++k) {
        const int layer = int(k % 3), cell = int(k / 3);
        const double x = x0 + (cell % side) + 0.5, z = x0 + (cell / side) + 0.5;
        sim.add({float(x), float(sim.surface(x, z) + 0.5 + layer * 1.0), float(z)}, {}, 2.0f, 0);
    }
    for (int i = 0; i < 20; ++i) sim.substep(0.004);  // let it start flowing
    for (auto _ : state) {
        sim.substep(0.004);
        benchmark::ClobberMemory();
    }
    state.counters["particles"] = double(sim.size());
    state.counters["bytes_per_particle"] = double(sph::Simulation::bytes_per_particle());
    state.SetItemsProcessed(state.iterations() * std::int64_t(sim.size()));
}

void BM_sph_step_dambreak(benchmark::State& state) {
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, std::size_t(state.range(0)));
    // SPlisHSPlasH's DamBreakModel at radius 0.01077: a 45³ block; ours with the same spacing.
    const double r = 0.01077, spacing = 2 * r;
    const int side = 45;
    const double cell = 0.05;
    const int w = int(std::ceil(4.0 * side * spacing / cell)) + 1, d = int(std::ceil(side * spacing / cell)) + 1;
    std::vector<float> h(std::size_t(w) * d, 0.0f);
    sph::Settings s;
    s.radius = r;
    s.sound_speed = 10.0 * std::sqrt(2.0 * 9.81 * side * spacing);
    s.viscosity = 0.02;
    s.friction = 0.0;
    s.erode = false;
    sph::Simulation sim(ConstGridView(h.data(), w, d, cell), s, std::size_t(side) * side * side);
    for (int k = 0; k < side; ++k)
        for (int j = 0; j < side; ++j)
            for (int i = 0; i < side; ++i)
                sim.add({float((i + 0.5) * spacing), float((j + 0.5) * spacing), float((k + 0.5) * spacing)}, {}, 0.0f,
                        0);
    const double dt = sim.stable_dt();
    for (int i = 0; i < 20; ++i) sim.substep(dt);
    for (auto _ : state) {
        sim.substep(dt);
        benchmark::ClobberMemory();
    }
    state.counters["particles"] = double(sim.size());
    state.SetItemsProcessed(state.iterations() * std::int64_t(sim.size()));
}

}  // namespace

BENCHMARK(BM_sph_step_terrain)
    ->ArgNames({"particles", "threads"})
    ->Args({100'000, 2})
    ->Args({1'000'000, 2})
    ->Args({100'000, 1})
    ->Args({1'000'000, 1})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_sph_step_dambreak)->ArgNames({"threads"})->Arg(2)->Arg(1)->Unit(benchmark::kMillisecond);
