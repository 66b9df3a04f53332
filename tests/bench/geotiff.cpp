// bench-links: orogen_geotiff
// export:geotiff on a 4097² terrain (the target: DEFLATE ≤ 2 s), per compression, to disk.
#include "export_common.hpp"
#include <orogen/geotiff/geotiff.hpp>

#include <benchmark/benchmark.h>

using namespace orogen;

static void BM_GeoTiff(benchmark::State& state) {
    const int n = 4097;
    const auto& h = bench::terrain(n);
    Heightmap terrain(n, n, 20.0);
    terrain.heights() = h;
    geotiff::WriteOptions o;
    o.compression = geotiff::Compression(state.range(0));
    o.cog = state.range(1) != 0;
    const auto file = bench::scratch() / "t.tif";
    for (auto _ : state) geotiff::write(terrain, file, o);
    state.counters["MB"] = double(std::filesystem::file_size(file)) / 1e6;
    std::filesystem::remove(file);
}
// Compression: 0 none, 1 deflate, 2 zstd, 3 lzw; second argument 1 = COG.
BENCHMARK(BM_GeoTiff)
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({2, 0})
    ->Args({1, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);
