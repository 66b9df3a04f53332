// bench-links: TBB::tbb orogen_landscape
// One step of the stream-power landscape model (orogen::landscape::Model::step:
// uplift, D8 routing, pit resolution, drainage area (D8, or multiple flow
// directions with mfd:1), implicit diffusion, implicit incision, and with banks:4 the rivers cutting
// their banks) at 1025² and 4097², and its parts. Targets (2 cores): one step
// at 1025² ≤ 60 ms, at 4097² ≤ 1.2 s.
//
// Two starting states:
//  * "evolved": a dome with ridges and valleys (a few real depressions) after
//    3 warm-up steps, so the timed steps are the steps of a long run;
//  * "fsl": the protocol of /work/shared/peers/fastscapelib_lem.cpp (fsl_lem):
//    uniform noise in [0, 1) m, every side a fixed base level, U = 1 mm/yr
//    inside, K = 2e-4, m = 0.4, n = 1, D = 0.01 m²/yr, dt = 2e4 yr, the
//    average over the first `steps` steps from the noise (the first step
//    resolves about a third of the cells as pits).
#include <orogen/landscape/stream_power.hpp>

#include <orogen/random.hpp>

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <chrono>
#include <cmath>
#include <vector>

namespace {

using namespace orogen;
using namespace orogen::landscape;

std::vector<double> dome(int n) {
    std::vector<double> h(std::size_t(n) * n);
    const double c = 0.5 * (n - 1);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const double r = std::hypot(x - c, y - c) / c;
            h[std::size_t(y) * n + x] =
                1500.0 * (1.0 - r) + 80.0 * std::sin(0.031 * x) * std::cos(0.027 * y) + 5.0 * random::uniform(3, x, y);
        }
    return h;
}

void BM_stream_power_step(benchmark::State& state) {
    const int n = int(state.range(0));
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, std::size_t(state.range(1)));
    Settings s;
    s.erodibility = 2e-5;
    s.area_exponent = 0.45;
    s.slope_exponent = 1.0;
    s.diffusivity = state.range(2) ? 0.01 : 0.0;
    s.mfd_exponent = state.range(3) ? 1.1 : 0.0;  // routing=mfd: drainage area by multiple flow directions
    s.deposition = double(state.range(4));  // G of Yuan et al. (2019); 0: detachment-limited
    s.banks.erosion = double(state.range(5));  // rivers cut their banks (banks.hpp); 0: none
    s.banks.area = 3e4;
    // wide 1: floors five cells wide along rivers draining 0.3 km²; 2: and seven from 1 km²; 3: and on to fifteen
    // (bank_widest_floor, as pipelines/kahurangi.orogen had until bf73596, 2026-12-06; thirteen since)
    s.banks.wide_area = state.range(6) ? 3e5 : 0.0;
    s.banks.wider_area = state.range(6) >= 2 ? 1e6 : 0.0;
    s.banks.widest_floor = state.range(6) >= 3 ? 15 : 0;
    s.banks.floor_slope = std::tan(1.0 * M_PI / 180.0);
    Model model(n, n, 30.0, dome(n), std::vector<double>(std::size_t(n) * n, 1e-3), s);
    for (int i = 0; i < 3; ++i) model.step(1e4);
    std::int64_t pits = 0, passes = 0;
    for (auto _ : state) {
        pits += model.step(1e4);
        passes += model.deposition_passes();
        benchmark::ClobberMemory();
    }
    state.counters["pits/step"] = double(pits) / double(state.iterations());
    if (s.deposition > 0.0) state.counters["passes"] = double(passes) / double(state.iterations());
    state.SetItemsProcessed(state.iterations() * std::int64_t(n) * n);
}
BENCHMARK(BM_stream_power_step)
    ->ArgNames({"n", "threads", "diffusion", "mfd", "G", "banks", "wide"})
    ->Args({1025, 1, 1, 0, 0, 0, 0})
    ->Args({1025, 2, 1, 0, 0, 0, 0})
    ->Args({1025, 2, 0, 0, 0, 0, 0})
    ->Args({1025, 2, 1, 1, 0, 0, 0})
    ->Args({1025, 1, 1, 0, 1, 0, 0})
    ->Args({1025, 2, 1, 0, 1, 0, 0})
    ->Args({1025, 2, 1, 0, 0, 4, 0})
    ->Args({1025, 2, 1, 0, 0, 4, 1})
    ->Args({1025, 2, 1, 0, 0, 4, 2})
    ->Args({1025, 2, 1, 0, 0, 4, 3})
    ->Args({4097, 2, 1, 0, 0, 0, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Routing alone (D8, pits, stack) + drainage area, on the evolved state.
void BM_stream_power_route(benchmark::State& state) {
    const int n = int(state.range(0));
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, std::size_t(state.range(1)));
    Settings s;
    Model model(n, n, 30.0, dome(n), std::vector<double>(std::size_t(n) * n, 1e-3), s);
    for (int i = 0; i < 3; ++i) model.step(1e4);
    for (auto _ : state) {
        model.route_only();
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(state.iterations() * std::int64_t(n) * n);
}
BENCHMARK(BM_stream_power_route)
    ->ArgNames({"n", "threads"})
    ->Args({1025, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// fsl_lem's protocol: per-step average of the first `steps` steps from noise.
void BM_stream_power_fsl(benchmark::State& state) {
    const int n = int(state.range(0)), steps = int(state.range(1));
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, std::size_t(state.range(2)));
    Settings s;
    s.erodibility = 2e-4;
    s.area_exponent = 0.4;
    s.slope_exponent = 1.0;
    s.diffusivity = 0.01;
    std::vector<double> h(std::size_t(n) * n), u(h.size(), 1e-3);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) h[std::size_t(y) * n + x] = random::uniform(1, x, y);
    double pits = 0.0;
    for (auto _ : state) {
        state.PauseTiming();
        Model model(n, n, 30.0, h, u, s);
        state.ResumeTiming();
        for (int i = 0; i < steps; ++i) pits += double(model.step(2e4));
        benchmark::ClobberMemory();
    }
    state.counters["ms/step"] = benchmark::Counter(
        double(steps) * 1e-3, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
    state.counters["pits/step"] = pits / double(state.iterations() * steps);
}
BENCHMARK(BM_stream_power_fsl)
    ->ArgNames({"n", "steps", "threads"})
    ->Args({1025, 10, 1})
    ->Args({1025, 10, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
