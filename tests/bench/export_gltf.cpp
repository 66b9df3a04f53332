// bench-links: orogen_gltf
// export:gltf on a 4097² terrain (20 m cells): .glb with the default automatic
// chunks (16-bit indices) and 2048² texture, written to disk (fsync included).
#include "export_common.hpp"
#include <orogen/gltf/gltf_writer.hpp>
#include <orogen/io.hpp>
#include <orogen/mesh/terrain_mesh.hpp>

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <string>
#include <vector>

using namespace orogen;

static void BM_GltfGlb(benchmark::State& state) {
    const int n = int(state.range(0));
    const auto& h = bench::terrain(n);
    gltf::Options o;
    o.decimate = int(state.range(1));
    std::size_t bytes = 0;
    for (auto _ : state)
        bytes = gltf::write_gltf(ConstGridView(h.data(), n, n, 20.0), o, bench::scratch() / "t.glb").bytes;
    state.counters["MB"] = double(bytes) / 1e6;
    std::filesystem::remove(bench::scratch() / "t.glb");
}
BENCHMARK(BM_GltfGlb)
    ->Args({4097, 1})
    ->Args({4097, 4})
    ->Args({1025, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);

// The floor to compare with, in the same run on the same disk: `cp` of the same .glb and `sync` of the copy
// (coreutils: an in-kernel copy_file_range, then the flush). `make bench-check` holds export:gltf within
// 1.5x of it (docs/benchmarks.md).
static void BM_GltfCopyFloor(benchmark::State& state) {
    const int n = int(state.range(0));
    const auto& h = bench::terrain(n);
    const auto from = bench::scratch() / "floor.glb", to = bench::scratch() / "floor-copy.glb";
    gltf::write_gltf(ConstGridView(h.data(), n, n, 20.0), gltf::Options{}, from);
    const std::string cmd = "cp '" + from.string() + "' '" + to.string() + "' && sync '" + to.string() + "'";
    for (auto _ : state) {
        std::filesystem::remove(to);
        if (std::system(cmd.c_str()) != 0) state.SkipWithError("cp or sync failed");
    }
    state.counters["MB"] = double(std::filesystem::file_size(from)) / 1e6;
    std::filesystem::remove(from);
    std::filesystem::remove(to);
}
BENCHMARK(BM_GltfCopyFloor)->Arg(4097)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

// The parts, in memory: splat texture bake and its PNG, and one pass of mesh data.
static void BM_SplatTexture(benchmark::State& state) {
    const auto& h = bench::terrain(4097);
    const int t = int(state.range(0));
    for (auto _ : state) {
        auto rgba = mesh::bake_splat_texture(ConstGridView(h.data(), 4097, 4097, 20.0), t, t);
        benchmark::DoNotOptimize(orogen::encode_rgba_png(rgba, t, t, 1));
    }
}
BENCHMARK(BM_SplatTexture)->Arg(2048)->Unit(benchmark::kMillisecond)->UseRealTime();

static void BM_MeshData(benchmark::State& state) {
    const auto& h = bench::terrain(4097);
    const auto mesh = mesh::plan_mesh(ConstGridView(h.data(), 4097, 4097, 20.0), 1, 0, 1.0);
    std::vector<float> f;
    std::vector<std::uint16_t> u;
    for (auto _ : state)
        for (const auto& c : mesh.chunks) {
            f.resize(c.vertex_count() * 3);
            mesh::chunk_positions(mesh, c, f);
            mesh::chunk_normals(mesh, c, f);
            u.resize(c.triangle_count() * 3);
            mesh::chunk_indices(c, std::span<std::uint16_t>(u));
            benchmark::DoNotOptimize(f.data());
        }
}
BENCHMARK(BM_MeshData)->Unit(benchmark::kMillisecond)->UseRealTime();
