// bench-links: TBB::tbb
// Thermal erosion step (orogen::thermal::step) at 1025² and 4097², per
// neighbourhood, on 1 and 2 threads. Targets (2 cores): 1025² ≤ 0.5 ms, 4097² ≤ 8 ms.
#include "thermal.hpp"

#include <orogen/random.hpp>

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <chrono>
#include <cmath>
#include <vector>

namespace {

using namespace orogen;

void BM_thermal_step(benchmark::State& state) {
    const int n = int(state.range(0));
    const auto nb = thermal::Neighbourhood(state.range(1));
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, std::size_t(state.range(2)));
    std::vector<float> a(std::size_t(n) * n), b(a.size());
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
            a[std::size_t(y) * n + x] = 300.0f * float(random::uniform(1, x, y)) + 0.5f * float(x);
    thermal::Settings s;
    s.neighbourhood = nb;
    s.hardness = state.range(3) ? thermal::Hardness::height : thermal::Hardness::constant;
    s.height_max = 800.0f;
    GridView va{a.data(), n, n, 20.0}, vb{b.data(), n, n, 20.0};
    for (auto _ : state) {
        thermal::step(va, vb, s);
        std::swap(va, vb);
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(state.iterations() * std::int64_t(n) * n);
}

// args: size, neighbourhood (0 von-neumann, 1 rotated, 2 moore), threads, height-aware
BENCHMARK(BM_thermal_step)
    ->ArgNames({"n", "nb", "threads", "height"})
    ->Args({257, 1, 1, 0})
    ->Args({257, 2, 1, 0})
    ->Args({1025, 1, 1, 0})
    ->Args({1025, 2, 1, 0})
    ->Args({1025, 1, 2, 0})
    ->Args({1025, 0, 2, 0})
    ->Args({1025, 2, 2, 0})
    ->Args({1025, 1, 2, 1})
    ->Args({4097, 1, 1, 0})
    ->Args({4097, 2, 1, 0})
    ->Args({4097, 1, 2, 0})
    ->Args({4097, 2, 2, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// thermal::erode (several steps per sweep over the grid, see
// kStepsPerSweep): the reported time is per step (the run of `steps` steps,
// including erode()'s scratch allocation, divided by `steps`).
void BM_thermal_erode_per_step(benchmark::State& state) {
    const int n = int(state.range(0));
    const auto nb = thermal::Neighbourhood(state.range(1));
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, std::size_t(state.range(2)));
    const std::int64_t steps = state.range(3);
    std::vector<float> a(std::size_t(n) * n);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
            a[std::size_t(y) * n + x] = 300.0f * float(random::uniform(1, x, y)) + 0.5f * float(x);
    thermal::Settings s;
    s.neighbourhood = nb;
    s.height_max = 800.0f;
    for (auto _ : state) {
        const auto t0 = std::chrono::steady_clock::now();
        thermal::erode(GridView{a.data(), n, n, 20.0}, steps, s);
        const auto t1 = std::chrono::steady_clock::now();
        benchmark::ClobberMemory();
        state.SetIterationTime(std::chrono::duration<double>(t1 - t0).count() / double(steps));
    }
    state.SetItemsProcessed(state.iterations() * std::int64_t(n) * n);
}

// args: size, neighbourhood (0 von-neumann, 1 rotated, 2 moore), threads, steps per erode() call
BENCHMARK(BM_thermal_erode_per_step)
    ->ArgNames({"n", "nb", "threads", "steps"})
    ->Args({1025, 1, 1, 32})
    ->Args({1025, 2, 1, 32})
    ->Args({1025, 1, 2, 32})
    ->Args({1025, 0, 2, 32})
    ->Args({1025, 2, 2, 32})
    ->Args({4097, 1, 1, 16})
    ->Args({4097, 2, 1, 16})
    ->Args({4097, 1, 2, 16})
    ->Args({4097, 2, 2, 16})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();

}  // namespace
