// export:vdb on a 4097² terrain (20 m cells, voxel = cell, half-width 3):
// the surface level set and the height grid, built and written to disk.
#include "export_common.hpp"
#include "vdb_writer.hpp"

#include <benchmark/benchmark.h>

using namespace orogen;

static void BM_VdbTerrain(benchmark::State& state) {
    const int n = int(state.range(0));
    const auto& h = bench::terrain(n);
    vdb::TerrainOptions o;
    o.half_float = state.range(1) != 0;
    vdb::TerrainSummary s;
    for (auto _ : state) s = vdb::write_terrain({h.data(), n, n, 20.0}, nullptr, bench::scratch() / "t.vdb", o);
    state.counters["Mvoxels"] = double(s.surface_voxels) / 1e6;
    state.counters["MB"] = double(std::filesystem::file_size(bench::scratch() / "t.vdb")) / 1e6;
    std::filesystem::remove(bench::scratch() / "t.vdb");
}
// Args: size, half floats for the level set (the default)
BENCHMARK(BM_VdbTerrain)
    ->Args({4097, 0})
    ->Args({4097, 1})
    ->Args({1025, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);
