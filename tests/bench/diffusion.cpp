// bench-links: TBB::tbb orogen_solvers
// One hillslope-diffusion step (orogen::solvers::diffusion::Solver::step) at 1025² and
// 4097², per scheme, on 1 and 2 threads. Target (2 cores): 1025² ≤ 15 ms.
#include <orogen/solvers/diffusion.hpp>

#include <orogen/random.hpp>

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <vector>

namespace {

using namespace orogen;

void BM_diffusion_step(benchmark::State& state) {
    const int n = int(state.range(0));
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, std::size_t(state.range(2)));
    std::vector<double> h(std::size_t(n) * n);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) h[std::size_t(y) * n + x] = 300.0 * random::uniform(1, x, y) + 0.5 * x;
    solvers::diffusion::Settings s;
    s.diffusivity = 0.01;
    s.scheme = solvers::diffusion::Scheme(state.range(1) & 1);
    s.critical_slope = state.range(1) == 2 ? 1.2 : 0.0;
    s.fixed = {true, true, true, true};
    solvers::diffusion::Solver solver(n, n, 30.0, s);
    for (auto _ : state) {
        solver.step(h.data(), 1e4);
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(state.iterations() * std::int64_t(n) * n);
}

// args: size, scheme (0 implicit, 1 adi, 2 critical-slope implicit), threads
BENCHMARK(BM_diffusion_step)
    ->ArgNames({"n", "scheme", "threads"})
    ->Args({1025, 0, 1})
    ->Args({1025, 0, 2})
    ->Args({1025, 1, 2})
    ->Args({1025, 2, 2})
    ->Args({4097, 0, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
