// Fault: target 1000 lines at 1025² ≤ 10 ms (2 cores).
#include "fault.hpp"

#include <orogen/values.hpp>

#include <benchmark/benchmark.h>

static void BM_Fault(benchmark::State& state) {
    const int n = int(state.range(0));
    const int lines = int(state.range(1));
    orogen::Heightmap hm(n, n, 1.0);
    std::uint64_t seed = 0;
    for (auto _ : state) {
        orogen::fault::apply(hm.view(), lines, 1.0, seed++);
        benchmark::DoNotOptimize(hm.heights().data());
    }
    state.SetItemsProcessed(state.iterations() * std::int64_t(n) * n);
}
BENCHMARK(BM_Fault)->Args({1025, 1000})->Args({4097, 1000})->Unit(benchmark::kMillisecond)->UseRealTime();
