// bench-links: orogen_core_rmp_gl
// RMP at 1025², 100 iterations: the thesis's tables 4.1/4.2 and figure 4.13.
//   build-rmp/bench/bench_rmp --benchmark_min_time=1 --benchmark_counters_tabular=true
// Each benchmark runs one whole RMP (100 iterations) per benchmark iteration.
#include "cones.hpp"
#include <orogen/relief/range.hpp>
#include <orogen/relief/voronoi.hpp>
#include "rmp.hpp"

#include <benchmark/benchmark.h>

#include <vector>

using namespace orogen;

namespace {

constexpr int kSize = 1025;

void run_method(benchmark::State& state, int method) {
    rmp::RmpParams p;
    p.iterations = 100;
    p.decay = 0.99;
    if (method == 2) {
        p.cuts = int(state.range(0));
        p.regions = 2;
    } else {
        p.cones = int(state.range(0));
    }
    std::vector<float> data(std::size_t(kSize) * kSize, 0.0f);
    const GridView v{data.data(), kSize, kSize, 1.0};
    std::uint64_t seed = 1;
    for (auto _ : state) {
        if (method == 0) rmp::rmp_voronoi(v, p, seed);
        else if (method == 1) rmp::rmp_cones(v, p, seed);
        else rmp::rmp_graph(v, p, seed);
        benchmark::DoNotOptimize(data.data());
        ++seed;
    }
}

void BM_RmpVoronoi(benchmark::State& state) { run_method(state, 0); }
void BM_RmpCones(benchmark::State& state) { run_method(state, 1); }
void BM_RmpGraph(benchmark::State& state) { run_method(state, 2); }

void BM_Range(benchmark::State& state) {
    // One call as the plate simulation makes per collision: a 600-sample line.
    std::vector<float> data(std::size_t(kSize) * kSize, 0.0f);
    GridView v{data.data(), kSize, kSize, 1.0};
    relief::RangeParams p;
    p.cones = int(state.range(0));
    std::uint64_t seed = 1;
    for (auto _ : state) { benchmark::DoNotOptimize(relief::raise_range(v, {200, 300}, {800, 700}, p, seed++)); }
}

}  // namespace

/// The site counts both methods are timed at.
void site_counts(benchmark::internal::Benchmark* b) {
    for (int n : {7, 11, 16, 100, 1000, 10000, 100000}) b->Arg(n);
    b->Unit(benchmark::kMillisecond)->UseRealTime();
}
BENCHMARK(BM_RmpVoronoi)->Apply(site_counts);
BENCHMARK(BM_RmpCones)->Apply(site_counts);
BENCHMARK(BM_RmpGraph)->Arg(3)->Arg(4)->Arg(5)->Arg(50)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Range)->Arg(100)->Arg(1000)->Arg(10000)->Unit(benchmark::kMicrosecond)->UseRealTime();

namespace {

// The cone method's parts: drawing + read-back alone, for one diagram.
void BM_ConeDraw(benchmark::State& state) {
    rmp::ConeRenderer renderer(kSize, kSize);
    const auto sites = relief::random_sites(int(state.range(0)), kSize, kSize, 5);
    auto radii = relief::SiteIndex(sites, kSize, kSize).cell_radius_bounds();
    double area = 0;
    for (double& r : radii) area += 3.2154 * (r + 1) * (r + 1);  // 12-gon footprint
    for (auto _ : state) benchmark::DoNotOptimize(renderer.render(sites, radii).data());
    state.counters["overdraw"] = area / (double(kSize) * kSize);
}

}  // namespace

BENCHMARK(BM_ConeDraw)->Arg(7)->Arg(100)->Arg(1000)->Arg(100000)->Unit(benchmark::kMillisecond)->UseRealTime();
