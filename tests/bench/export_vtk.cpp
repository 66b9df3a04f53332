// bench-links: orogen_vtk
// export:vtk on a 4097² terrain with two layers: .vti (raw appended; up=y
// writes the samples without a copy, up=z, the default, copies each array
// with its rows reversed) and the .vtp mesh, written to disk (fsync included).
#include "export_common.hpp"
#include <orogen/vtk/vtk_writer.hpp>

#include <benchmark/benchmark.h>

using namespace orogen;

static void BM_Vtk(benchmark::State& state) {
    const int n = 4097;
    const auto& h = bench::terrain(n);
    static std::vector<float> water(h.size(), 0.5f), sediment(h.size(), 0.01f);
    const std::vector<vtk::NamedGrid> layers = {{"water", {water.data(), n, n, 20.0}},
                                                {"sediment", {sediment.data(), n, n, 20.0}}};
    const auto file = bench::scratch() / (state.range(0) == 0 ? "t.vti" : "t.vtp");
    vtk::Options o;
    o.compress = state.range(1) != 0;
    o.up = state.range(2) == 0 ? vtk::Up::z : vtk::Up::y;
    for (auto _ : state) vtk::write_heightmap({h.data(), n, n, 20.0}, layers, file, o);
    state.counters["MB"] = double(std::filesystem::file_size(file)) / 1e6;
    std::filesystem::remove(file);
}
// Args: (0 = .vti, 1 = .vtp), compress, (0 = up z, 1 = up y)
BENCHMARK(BM_Vtk)
    ->Args({0, 0, 0})
    ->Args({0, 0, 1})
    ->Args({0, 1, 0})
    ->Args({1, 0, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);
