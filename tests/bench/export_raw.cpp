// bench-links: orogen_formats
// export:raw on a 4097² terrain: .r16 (quantised) and .r32, with the sidecar, to disk.
#include "export_common.hpp"
#include <orogen/formats/raw.hpp>

#include <benchmark/benchmark.h>

using namespace orogen;

static void BM_Raw(benchmark::State& state) {
    const int n = 4097;
    const auto& h = bench::terrain(n);
    const auto file = bench::scratch() / (state.range(0) == 16 ? "t.r16" : "t.r32");
    for (auto _ : state) formats::raw::write_raw({h.data(), n, n, 20.0}, file);
    std::filesystem::remove(file);
    std::filesystem::remove(file.string() + ".json");
}
BENCHMARK(BM_Raw)->Arg(16)->Arg(32)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(5);
