// bench-links: PNG::PNG
// 16-bit grayscale PNG of a 4097² terrain, as export:png bits=16 writes it (libdeflate, adaptive filters,
// levels 1, 6, 12), beside libpng + zlib at level 6 (what orogen used before, and what most tools use) on
// the same samples in the same process: the ratio is the figure (docs/benchmarks.md).
#include "export_common.hpp"

#include <orogen/io.hpp>

#include <benchmark/benchmark.h>
#include <png.h>

#include <algorithm>
#include <cstdio>
#include <fstream>

using namespace orogen;

namespace {
const std::vector<std::uint16_t>& samples(int n) {
    static std::vector<std::uint16_t> s;
    if (s.empty()) {
        const auto& h = bench::terrain(n);
        const auto [lo, hi] = std::minmax_element(h.begin(), h.end());
        s.resize(h.size());
        for (std::size_t i = 0; i < h.size(); ++i)
            s[i] = std::uint16_t(std::lround((h[i] - *lo) / (*hi - *lo) * 65535.0));
    }
    return s;
}
}  // namespace

static void BM_Png16_orogen(benchmark::State& state) {
    const int n = 4097;
    const auto& s = samples(n);
    const auto file = bench::scratch() / "t16.png";
    for (auto _ : state) {
        std::ofstream out(file, std::ios::binary);
        write_gray_png(out, n, n, 16, s, int(state.range(0)));
    }
    state.counters["MB"] = double(std::filesystem::file_size(file)) / 1e6;
    std::filesystem::remove(file);
}
BENCHMARK(BM_Png16_orogen)
    ->ArgName("level")
    ->Arg(1)
    ->Arg(6)
    ->Arg(12)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(2);

static void BM_Png16_libpng(benchmark::State& state) {
    const int n = 4097;
    const auto& s = samples(n);
    const auto file = bench::scratch() / "t16-libpng.png";
    std::vector<std::uint8_t> row(std::size_t(n) * 2);
    for (auto _ : state) {
        FILE* f = std::fopen(file.c_str(), "wb");
        png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
        png_infop info = png_create_info_struct(png);
        png_init_io(png, f);
        png_set_compression_level(png, 6);
        png_set_IHDR(png, info, n, n, 16, PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                     PNG_FILTER_TYPE_DEFAULT);
        png_write_info(png, info);
        for (int y = 0; y < n; ++y) {
            for (int x = 0; x < n; ++x) {
                const std::uint16_t v = s[std::size_t(y) * n + std::size_t(x)];
                row[2 * std::size_t(x)] = std::uint8_t(v >> 8);
                row[2 * std::size_t(x) + 1] = std::uint8_t(v);
            }
            png_write_row(png, row.data());
        }
        png_write_end(png, nullptr);
        png_destroy_write_struct(&png, &info);
        std::fclose(f);
    }
    state.counters["MB"] = double(std::filesystem::file_size(file)) / 1e6;
    std::filesystem::remove(file);
}
BENCHMARK(BM_Png16_libpng)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
