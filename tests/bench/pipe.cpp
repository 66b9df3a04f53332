// bench-links: TBB::tbb
// One pipe-model sub-step (orogen::pipe::Solver::advance with a dt below the
// CFL limit, so exactly one sub-step) at 1025² and 4097², on 1 and 2 threads.
// Targets (2 cores): 1025² ≤ 6 ms, 4097² ≤ 100 ms.
#include "pipe.hpp"

#include <orogen/random.hpp>

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <cmath>
#include <vector>

namespace {

using namespace orogen;

void BM_pipe_substep(benchmark::State& state) {
    const int n = int(state.range(0));
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, std::size_t(state.range(1)));
    const std::size_t size = std::size_t(n) * n;
    std::vector<float> buf(8 * size, 0.0f);
    const double cell = 10.0;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
            buf[std::size_t(y) * n + x] = 20.0f * float(random::uniform(1, x, y)) +
                100.0f * std::sin(0.01f * float(x)) * std::cos(0.013f * float(y));
    auto view = [&](int k) { return GridView{buf.data() + k * size, n, n, cell}; };
    pipe::State st{view(0), view(1), view(2), view(3), view(4), view(5), view(6), view(7)};
    pipe::Settings s;
    s.rain = 0.001;
    pipe::Solver solver(st, s);
    std::int64_t step = 0;
    for (int i = 0; i < 20; ++i) solver.advance(0.5, ++step);  // wet the terrain first
    const std::int64_t before = solver.substeps();
    for (auto _ : state) {
        solver.advance(0.05, ++step);
        benchmark::ClobberMemory();
    }
    state.counters["substeps_per_step"] = double(solver.substeps() - before) / double(state.iterations());
    state.SetItemsProcessed(state.iterations() * std::int64_t(size));
}

// args: size, threads
BENCHMARK(BM_pipe_substep)
    ->ArgNames({"n", "threads"})
    ->Args({1025, 1})
    ->Args({1025, 2})
    ->Args({4097, 1})
    ->Args({4097, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
