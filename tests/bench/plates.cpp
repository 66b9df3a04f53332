// Plate simulation: 12 plates, 1000 steps on a 1025² heightmap with uplift
// (the target: ≤ 3 s), and platec's measured configurations
// (THESIS-NOTES: 512²/10 plates/1042 steps, 1024²/12/1140, 2048²/20/1124).
// Counters: steps per second, seconds inside Box2D and raising relief.
//   build-plates/bench/bench_plates --benchmark_min_time=1
#include "plates.hpp"

#include <benchmark/benchmark.h>

#include <vector>

using namespace orogen;
using namespace orogen::plates;

static void BM_Plates(benchmark::State& state) {
    const int n = int(state.range(0));
    const int count = int(state.range(1));
    const int steps = int(state.range(2));
    Params p;
    p.steps = steps;
    p.max_plates = max_plates(n, n);
    const auto start = random_plates(area_size(n, n), count, 0.5, p.speed, 42);
    std::vector<float> height(std::size_t(n) * n), uplift(height.size()), boundary(height.size()), plate(height.size());
    double box2d = 0, relief = 0;
    std::int64_t events = 0, rifts = 0;
    for (auto _ : state) {
        state.PauseTiming();
        std::fill(height.begin(), height.end(), 0.0f);
        std::fill(uplift.begin(), uplift.end(), 0.0f);
        std::fill(boundary.begin(), boundary.end(), 0.0f);
        state.ResumeTiming();
        const Layers layers{{height.data(), n, n, 20.0},
                            {uplift.data(), n, n, 20.0},
                            {boundary.data(), n, n, 20.0},
                            {plate.data(), n, n, 20.0}};
        const Result r = simulate(start, p, 42, layers);
        box2d += r.stats.box2d_seconds;
        relief += r.stats.relief_seconds;
        events = r.stats.events[1] + r.stats.events[2] + r.stats.events[3];
        rifts = r.stats.rifts;
        benchmark::DoNotOptimize(height.data());
    }
    const double it = double(state.iterations());
    state.counters["steps_per_s"] = benchmark::Counter(double(steps) * it, benchmark::Counter::kIsRate);
    state.counters["box2d_s"] = box2d / it;
    state.counters["relief_s"] = relief / it;
    state.counters["events"] = double(events);
    state.counters["rifts"] = double(rifts);
}
BENCHMARK(BM_Plates)
    ->ArgNames({"n", "plates", "steps"})
    ->Args({1025, 12, 1000})
    ->Args({513, 10, 1042})
    ->Args({1025, 12, 1140})
    ->Args({2049, 20, 1124})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
