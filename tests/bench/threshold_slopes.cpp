// bench-links: TBB::tbb orogen_solvers
// The landslide limit (orogen::solvers::threshold::limit_slopes) at 1025², on 1 and 2 threads:
//  * from_rough: rough relief (0-600 m of noise on a 0.5 m/cell ramp) limited to 33° from scratch;
//  * after_uplift: a surface already at its limit raised 30 m inside fixed sides (one step of
//    0.5 mm/yr over 6e4 yr, as erode:stream-power's landslides see it each step), limited again.
#include <orogen/solvers/threshold_slopes.hpp>

#include <orogen/random.hpp>

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <cmath>
#include <vector>

namespace {

using namespace orogen;

constexpr int kSide = 1025;
constexpr double kCell = 30.0;
const double kSlope = std::tan(33.0 * 3.14159265358979323846 / 180.0);

std::vector<double> rough() {
    std::vector<double> h(std::size_t(kSide) * kSide);
    for (int y = 0; y < kSide; ++y)
        for (int x = 0; x < kSide; ++x) h[std::size_t(y) * kSide + x] = 600.0 * random::uniform(3, x, y) + 0.5 * x;
    return h;
}

std::vector<std::uint8_t> sides() {
    std::vector<std::uint8_t> f(std::size_t(kSide) * kSide, 0);
    for (int i = 0; i < kSide; ++i)
        f[std::size_t(i)] = f[std::size_t(kSide - 1) * kSide + i] = f[std::size_t(i) * kSide] =
            f[std::size_t(i) * kSide + kSide - 1] = 1;
    return f;
}

/// Times the limit of a copy of `start` (the copy untimed), reporting its rounds.
void limit_copies(benchmark::State& state, const std::vector<double>& start, const std::vector<std::uint8_t>& fixed) {
    for (auto _ : state) {
        state.PauseTiming();
        auto h = start;
        state.ResumeTiming();
        const auto r = solvers::threshold::limit_slopes(h.data(), kSide, kSide, kCell, {kSlope}, fixed.data());
        benchmark::DoNotOptimize(r);
        state.counters["rounds"] = r.rounds;
    }
}

void BM_threshold_from_rough(benchmark::State& state) {
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, std::size_t(state.range(0)));
    limit_copies(state, rough(), sides());
}
BENCHMARK(BM_threshold_from_rough)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_threshold_after_uplift(benchmark::State& state) {
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, std::size_t(state.range(0)));
    auto limited = rough();
    const auto fixed = sides();
    solvers::threshold::limit_slopes(limited.data(), kSide, kSide, kCell, {kSlope}, fixed.data());
    for (std::size_t i = 0; i < limited.size(); ++i)
        if (!fixed[i]) limited[i] += 30.0;
    limit_copies(state, limited, fixed);
}
BENCHMARK(BM_threshold_after_uplift)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
