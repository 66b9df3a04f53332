// bench-links: TBB::tbb orogen_climate
// The orographic rain a stream-power step asks for (orogen::climate::orographic_rain_coarse, 250 m grid,
// the default wind) over rough relief at 1025² and 4097² (30 m), on 2 threads, into a reused array as the
// model does. At 4097² the coarse grid is 513² padded to 1024².
#include <orogen/climate/orographic_rain.hpp>

#include <orogen/random.hpp>

#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

namespace {

void BM_orographic_rain(benchmark::State& state) {
    const int n = int(state.range(0));
    std::vector<double> h(std::size_t(n) * n);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
            h[std::size_t(y) * n + x] =
                1500.0 * std::sin(0.004 * x) * std::cos(0.003 * y) + 200.0 * orogen::random::uniform(3, x, y);
    std::vector<double> rain;
    const orogen::climate::OrographicRain air;
    for (auto _ : state) {
        orogen::climate::orographic_rain_coarse(h.data(), n, n, 30.0, air, 250.0, rain);
        benchmark::DoNotOptimize(rain.data());
    }
    state.SetItemsProcessed(state.iterations() * std::int64_t(n) * n);
}

BENCHMARK(BM_orographic_rain)->ArgNames({"n"})->Arg(1025)->Arg(4097)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
