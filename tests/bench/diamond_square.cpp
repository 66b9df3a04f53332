// Diamond-Square: targets 1025² ≤ 5 ms, 4097² ≤ 100 ms (2 cores).
#include "diamond_square.hpp"

#include <orogen/values.hpp>

#include <benchmark/benchmark.h>

static void BM_DiamondSquare(benchmark::State& state) {
    const int n = int(state.range(0));
    orogen::Heightmap hm(n, n, 1.0);
    std::uint64_t seed = 0;
    for (auto _ : state) {
        orogen::diamond_square::generate(hm.view(), {100.0, 0.5}, seed++);
        benchmark::DoNotOptimize(hm.heights().data());
    }
    state.SetItemsProcessed(state.iterations() * std::int64_t(n) * n);
}
BENCHMARK(BM_DiamondSquare)->Arg(1025)->Arg(4097)->Unit(benchmark::kMillisecond)->UseRealTime();
