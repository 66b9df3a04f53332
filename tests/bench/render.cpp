// bench-links: orogen_core_render_terrain orogen_core_render_bloom orogen_core_diamond_square orogen_core_video
// render:terrain, render:bloom and export:video through OSMesa (llvmpipe) on
// a 1025² Diamond-Square terrain: one 1920 × 1080 frame with splatting,
// shadows, sky and bloom, the time of each stage as counters; and a
// turntable encoded to H.264. Figures in docs/benchmarks.md.
//   build/bench/bench_render --benchmark_min_time=1 --benchmark_repetitions=3
#include "bloom.hpp"
#include "diamond_square.hpp"
#include "render_terrain.hpp"
#include "video_encoder.hpp"

#include <orogen/gl_context.hpp>

#include <benchmark/benchmark.h>

#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

using namespace orogen;

namespace {

std::shared_ptr<const Heightmap> terrain_1025() {
    static std::shared_ptr<const Heightmap> t = [] {
        auto h = std::make_shared<Heightmap>(1025, 1025, 15.0);
        diamond_square::generate(h->view(), {.amplitude = 900.0, .roughness = 0.55}, 42);
        return h;
    }();
    return t;
}

/// CPU seconds of the whole process (every thread: llvmpipe rasterises on its own threads).
double process_cpu() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

long peak_rss_kb() {
    std::ifstream status("/proc/self/status");
    std::string line;
    while (std::getline(status, line))
        if (line.rfind("VmHWM:", 0) == 0) return std::stol(line.substr(6));
    return 0;
}

// One 1080p frame: scene (shadow map, sky, splatted terrain) + bloom, with the stages' times.
void BM_Frame1080p(benchmark::State& state) {
    render::Style style;
    style.samples = int(state.range(0));
    render::TerrainRenderer renderer(terrain_1025(), style);
    render::Camera camera;
    render::Timings total;
    double bloom_seconds = 0;
    render::bloom(renderer.render(1920, 1080, camera), {});  // llvmpipe compiles each shader on first use
    const double cpu0 = process_cpu();
    for (auto _ : state) {
        render::Timings t;
        Image frame = renderer.render(1920, 1080, camera, nullptr, &t);
        const double b0 = now();
        Image out = render::bloom(frame, {});
        bloom_seconds += now() - b0;
        benchmark::DoNotOptimize(out.rgba32f.data());
        total.shadow += t.shadow;
        total.scene += t.scene;
        total.resolve_and_read += t.resolve_and_read;
    }
    const double n = double(state.iterations());
    // All threads' CPU per frame: on an idle 2-core machine the frame takes about half of it.
    state.counters["cpu_all_threads_s"] = (process_cpu() - cpu0) / n;
    state.counters["shadow_s"] = total.shadow / n;
    state.counters["scene_s"] = total.scene / n;
    state.counters["resolve_read_s"] = total.resolve_and_read / n;
    state.counters["bloom_s"] = bloom_seconds / n;
    state.SetLabel(gl::renderer_name());
}
BENCHMARK(BM_Frame1080p)->Arg(1)->Arg(4)->Unit(benchmark::kMillisecond)->UseRealTime();

// A lone 1080p frame, as one `render:terrain` + `render:bloom` of a pipeline makes it: a new renderer each time
// (the heights uploaded, the shadow map drawn), where BM_Frame1080p's renderer keeps its shadow map from one
// frame to the next as a turntable's does.
void BM_LoneFrame1080p(benchmark::State& state) {
    render::bloom(render::TerrainRenderer(terrain_1025(), {}).render(1920, 1080, {}), {});  // shader compiles
    const double cpu0 = process_cpu();
    render::Timings total;
    for (auto _ : state) {
        render::TerrainRenderer renderer(terrain_1025(), {});
        render::Timings t;
        Image out = render::bloom(renderer.render(1920, 1080, {}, nullptr, &t), {});
        benchmark::DoNotOptimize(out.rgba32f.data());
        total.shadow += t.shadow;
        total.scene += t.scene;
    }
    const double n = double(state.iterations());
    state.counters["cpu_all_threads_s"] = (process_cpu() - cpu0) / n;
    state.counters["shadow_s"] = total.shadow / n;
    state.counters["scene_s"] = total.scene / n;
}
BENCHMARK(BM_LoneFrame1080p)->Unit(benchmark::kMillisecond)->UseRealTime();

// The bloom alone (bright pass, blur x, blur y, combine) on a 1080p frame.
void BM_Bloom1080p(benchmark::State& state) {
    render::TerrainRenderer renderer(terrain_1025(), {});
    const Image frame = renderer.render(1920, 1080, {});
    render::bloom(frame, {});  // warm-up: llvmpipe compiles each shader on first use
    const double cpu0 = process_cpu();
    for (auto _ : state) {
        Image out = render::bloom(frame, {});
        benchmark::DoNotOptimize(out.rgba32f.data());
    }
    state.counters["cpu_all_threads_s"] = (process_cpu() - cpu0) / double(state.iterations());
}
BENCHMARK(BM_Bloom1080p)->Unit(benchmark::kMillisecond)->UseRealTime();

// A turntable: `frames` frames orbiting the terrain, each rendered, bloomed
// and streamed into the H.264 encoder (never all held).
void BM_Turntable(benchmark::State& state) {
    const int frames = int(state.range(0)), width = int(state.range(1)), height = width * 9 / 16;
    render::TerrainRenderer renderer(terrain_1025(), {});
    const auto path = std::filesystem::temp_directory_path() / "orogen-bench-turntable.mp4";
    const double cpu0 = process_cpu();
    for (auto _ : state) {
        video::encode_video(path, std::size_t(frames),
                            [&](std::size_t i) {
                                render::Camera c;
                                c.azimuth = 360.0 * double(i) / frames;
                                return render::bloom(renderer.render(width, height, c), {});
                            },
                            {});
    }
    state.counters["frames"] = frames;
    state.counters["cpu_all_threads_s"] = (process_cpu() - cpu0) / double(state.iterations());
    state.counters["s_per_frame"] = benchmark::Counter(double(frames) * double(state.iterations()),
                                                       benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
    state.counters["peak_rss_MB"] = double(peak_rss_kb()) / 1024.0;
    std::filesystem::remove(path);
}
BENCHMARK(BM_Turntable)->Args({30, 1920})->Args({300, 1920})->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

}  // namespace
