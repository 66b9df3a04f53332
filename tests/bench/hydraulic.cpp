// bench-links: TBB::tbb
// Olsen hydraulic step (orogen::hydraulic::step) at 1025² (and 4097²), on 1
// and 2 threads. Target (2 cores): 1025² ≤ 2 ms.
#include "hydraulic.hpp"

#include <orogen/random.hpp>

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <cmath>
#include <vector>

namespace {

using namespace orogen;

void BM_hydraulic_step(benchmark::State& state) {
    const int n = int(state.range(0));
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, std::size_t(state.range(1)));
    const std::size_t size = std::size_t(n) * n;
    std::vector<float> buf(6 * size, 0.0f);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
            buf[std::size_t(y) * n + x] = 300.0f * float(random::uniform(1, x, y)) + 2.0f * float(x);
    auto view = [&](int k) { return GridView{buf.data() + k * size, n, n, 20.0}; };
    hydraulic::State a{view(0), view(1), view(2)}, b{view(3), view(4), view(5)};
    hydraulic::Settings s;
    // Warm up so water and sediment are spread like in a real run.
    for (int i = 0; i < 4; ++i) {
        hydraulic::step({a.height, a.water, a.sediment}, b, s);
        std::swap(a, b);
    }
    for (auto _ : state) {
        hydraulic::step({a.height, a.water, a.sediment}, b, s);
        std::swap(a, b);
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(state.iterations() * std::int64_t(size));
}

// args: size, threads
BENCHMARK(BM_hydraulic_step)
    ->ArgNames({"n", "threads"})
    ->Args({1025, 1})
    ->Args({1025, 2})
    ->Args({4097, 1})
    ->Args({4097, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
