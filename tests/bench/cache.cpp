// The node cache's entries (kernel/src/cache/cache.cpp): reading one back (mmap, the arrays copied into fresh
// vectors that a Heightmap adopts, beside the payload's XXH3-128 checksum, all on both cores) and writing one
// (encode, checksum, temporary + rename),
// for a 2049² heightmap with four layers (80 MiB) — the size of a 4097² run's smaller values. Bytes per
// second are the entry's size over the real time. The folder is in /tmp, and read from the page cache,
// as a re-run finds it. On a shared machine the real time says little: the counter `all_threads_cpu_ms` is
// the CPU time of the whole process (every thread, user + system, page faults included) per iteration.
#include "cache/cache.hpp"

#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fcntl.h>
#include <string>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

using namespace orogen;
namespace fs = std::filesystem;

namespace {

cache::Contents terrain_entry(int n) {
    auto hm = std::make_shared<Heightmap>(n, n, 10.0);
    for (std::size_t i = 0; i < hm->size(); ++i) hm->heights()[i] = float(i % 4093) * 0.25f;
    for (const char* layer : {"water", "sediment", "flow", "eroded"}) {
        GridView l = hm->layer(layer);
        for (std::size_t i = 0; i < l.size(); ++i) l.data[i] = float((i * 7) % 1021);
    }
    cache::Contents c;
    c.values.emplace_back("", Value(std::move(hm)));
    return c;
}

fs::path folder() {
    static const fs::path f = fs::temp_directory_path() / ("orogen-bench-cache-" + std::to_string(::getpid()));
    return f;
}

/// CPU seconds of the whole process so far (every thread, user + system).
double process_cpu_seconds() {
    rusage u{};
    ::getrusage(RUSAGE_SELF, &u);
    return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

/// Times the loop's CPU (all threads) from construction to report().
struct ProcessCpu {
    double start = process_cpu_seconds();
    void report(benchmark::State& state) const {
        state.counters["all_threads_cpu_ms"] =
            1e3 * (process_cpu_seconds() - start) / double(std::max<std::int64_t>(1, state.iterations()));
    }
};

cache::Digest key() {
    cache::Hasher h;
    return h.text("bench").finish();
}

}  // namespace

static void BM_CacheRead(benchmark::State& state) {
    const int n = int(state.range(0));
    cache::Store store({folder(), std::uint64_t(8) << 30},
                       [](const std::string& w) { std::fprintf(stderr, "%s\n", w.c_str()); });
    if (!store.save(key(), terrain_entry(n))) state.SkipWithError("could not write the entry");
    const auto bytes = fs::file_size(store.path(key()));
    ProcessCpu cpu;
    for (auto _ : state) {
        auto c = store.load(key(), "bench");
        if (!c) state.SkipWithError("could not read the entry");
        benchmark::DoNotOptimize(c->values[0].second.heightmap()->heights().data());
    }
    cpu.report(state);
    state.SetBytesProcessed(std::int64_t(bytes) * state.iterations());
    fs::remove_all(folder());
}
BENCHMARK(BM_CacheRead)->Arg(2049)->Unit(benchmark::kMillisecond)->UseRealTime();

static void BM_CacheWrite(benchmark::State& state) {
    const int n = int(state.range(0));
    cache::Store store({folder(), std::uint64_t(8) << 30},
                       [](const std::string& w) { std::fprintf(stderr, "%s\n", w.c_str()); });
    const auto contents = terrain_entry(n);
    ProcessCpu cpu;
    for (auto _ : state)
        if (!store.save(key(), contents)) state.SkipWithError("could not write the entry");
    cpu.report(state);
    state.SetBytesProcessed(std::int64_t(fs::file_size(store.path(key()))) * state.iterations());
    fs::remove_all(folder());
}
BENCHMARK(BM_CacheWrite)->Arg(2049)->Unit(benchmark::kMillisecond)->UseRealTime();

/// The payload checksum alone (XXH3-128 per 1 MiB block, on every core): what a read checks.
static void BM_PayloadChecksum(benchmark::State& state) {
    std::vector<std::uint8_t> bytes(std::size_t(state.range(0)) << 20, 7);
    ProcessCpu cpu;
    for (auto _ : state) benchmark::DoNotOptimize(cache::payload_checksum(bytes));
    cpu.report(state);
    state.SetBytesProcessed(std::int64_t(bytes.size()) * state.iterations());
}
BENCHMARK(BM_PayloadChecksum)->Arg(64)->Unit(benchmark::kMillisecond)->UseRealTime();

/// The payload hash alone (the content hash of values made by nodes that always run) (SHA-256 per 1 MiB block, on every core).
static void BM_PayloadHash(benchmark::State& state) {
    std::vector<std::uint8_t> bytes(std::size_t(state.range(0)) << 20, 7);
    ProcessCpu cpu;
    for (auto _ : state) benchmark::DoNotOptimize(cache::payload_hash(bytes));
    cpu.report(state);
    state.SetBytesProcessed(std::int64_t(bytes.size()) * state.iterations());
}
BENCHMARK(BM_PayloadHash)->Arg(64)->Unit(benchmark::kMillisecond)->UseRealTime();

// ------------------------------------------------------------ exports and the cache (issue 30)
//
// The whole CLI on a 4097² grid, `export:tiles(format=glb, tile_size=513)` (85 GLB chunks and a tileset,
// ~1.1 GB; spec 0) or `export:gltf` (one 0.68 GB .glb, the case; spec 1), without the cache, with a cold cache, warm into the same --out, and warm into a new --out;
// then a plain `cp -r` of the same files, in the same process run, so the figures share the machine's
// load. Each iteration is one child process; the counters are its peak RSS (MiB) and its CPU (user +
// system, every thread). The scratch folder is under /tmp, on the same disk as the cache folder.

namespace {

const fs::path& glb_scratch() {
    static const fs::path& f = *[] {  // never destroyed: the atexit handler below still reads it
        auto* p = new fs::path(fs::temp_directory_path() / ("orogen-bench-cache-glb-" + std::to_string(::getpid())));
        fs::create_directories(*p);
        std::FILE* spec = std::fopen((*p / "glb.orogen").c_str(), "w");
        std::fputs(
            "orogen 1\nseed 7\ngrid 4097 cell=10\n"
            "t = generate:diamond-square(roughness=0.55, amplitude=1500)\n"
            "export:tiles(t, path=\"tiles/t.json\", tile_size=513, format=glb)\n",
            spec);
        std::fclose(spec);
        spec = std::fopen((*p / "gltf.orogen").c_str(), "w");
        std::fputs(
            "orogen 1\nseed 7\ngrid 4097 cell=10\n"
            "t = generate:diamond-square(roughness=0.55, amplitude=1500)\n"
            "export:gltf(t, path=\"t.glb\")\n",
            spec);
        std::fclose(spec);
        std::atexit([] {
            std::error_code ec;
            fs::remove_all(glb_scratch(), ec);
        });  // whichever benchmarks ran
        return p;
    }();
    return f;
}

struct Child {
    double seconds = 0, cpu_seconds = 0, peak_mib = 0;
    int status = -1;
};

/// Run argv to completion; its own peak RSS and CPU from wait4.
Child run_child(const std::vector<std::string>& args) {
    std::vector<char*> argv;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    const auto t0 = std::chrono::steady_clock::now();
    const pid_t pid = ::fork();
    if (pid == 0) {
        const int null = ::open("/dev/null", O_WRONLY);
        ::dup2(null, 1);
        ::execv(argv[0], argv.data());
        ::_exit(127);
    }
    Child c;
    rusage u{};
    ::wait4(pid, &c.status, 0, &u);
    c.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    c.cpu_seconds =
        double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
    c.peak_mib = double(u.ru_maxrss) / 1024.0;
    return c;
}

/// The spec of scenario `spec` (0: export:tiles, 1: export:gltf) and its --out folder.
fs::path spec_path(int spec) { return glb_scratch() / (spec == 0 ? "glb.orogen" : "gltf.orogen"); }
fs::path out_path(int spec) { return glb_scratch() / (spec == 0 ? "out" : "out-gltf"); }

std::vector<std::string> orogen_run(const fs::path& out, const char* cache_mode, int spec = 0) {
    std::vector<std::string> a{OROGEN_CLI, "run",    spec_path(spec).string(), "--out", out.string(), "--threads",
                               "2",        "--quiet"};
    if (std::string(cache_mode) == "none") a.push_back("--no-cache");
    else a.insert(a.end(), {"--cache", (glb_scratch() / "cache").string()});
    return a;
}

void report(benchmark::State& state, const std::vector<Child>& runs) {
    double cpu = 0, peak = 0;
    for (const auto& r : runs) {
        if (r.status != 0) state.SkipWithError("the child failed");
        cpu += r.cpu_seconds;
        peak = std::max(peak, r.peak_mib);
    }
    state.counters["child_cpu_s"] = cpu / double(std::max<std::size_t>(1, runs.size()));
    state.counters["peak_rss_MiB"] = peak;
}

}  // namespace

/// Mode 0: --no-cache; 1: a cold cache (emptied before each run); 2: warm, into the same --out (files in
/// place); 3: warm, into a new --out (the recorded GLB files are missing: the exporter runs again).
/// Spec 0: export:tiles; 1: export:gltf.
static void BM_Glb4097Run(benchmark::State& state) {
    const int mode = int(state.range(0)), spec = int(state.range(1));
    const fs::path out = out_path(spec), cache_dir = glb_scratch() / "cache";
    std::vector<Child> runs;
    if (mode >= 2) {  // warm the cache (and --out) once
        fs::remove_all(cache_dir);
        fs::remove_all(out);
        if (run_child(orogen_run(out, "cache", spec)).status != 0) state.SkipWithError("warming failed");
    }
    for (auto _ : state) {
        state.PauseTiming();
        if (mode == 1) fs::remove_all(cache_dir);
        if (mode != 2) fs::remove_all(out);
        ::sync();
        state.ResumeTiming();
        runs.push_back(run_child(orogen_run(out, mode == 0 ? "none" : "cache", spec)));
    }
    report(state, runs);
    state.SetLabel(std::string(spec == 0 ? "tiles, " : "gltf, ") +
                   (mode == 0       ? "--no-cache"
                        : mode == 1 ? "cold cache"
                        : mode == 2 ? "warm, same --out"
                                    : "warm, new --out"));
}
BENCHMARK(BM_Glb4097Run)
    ->ArgsProduct({{0, 1, 2, 3}, {0, 1}})
    ->Iterations(3)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// `cp -r` of the files the run above wrote (its --out), to a fresh folder on the same disk.
static void BM_Glb4097PlainCopy(benchmark::State& state) {
    const int spec = int(state.range(0));
    const fs::path out = out_path(spec), copy = glb_scratch() / "copy";
    if (!fs::exists(out / "manifest.json")) run_child(orogen_run(out, "none", spec));
    std::vector<Child> runs;
    for (auto _ : state) {
        state.PauseTiming();
        fs::remove_all(copy);
        ::sync();
        state.ResumeTiming();
        runs.push_back(run_child({"/bin/cp", "-r", out.string(), copy.string()}));
    }
    report(state, runs);
    std::uint64_t bytes = 0;
    for (const auto& e : fs::recursive_directory_iterator(out))
        if (e.is_regular_file()) bytes += e.file_size();
    state.counters["MiB"] = double(bytes) / double(1 << 20);
    state.SetLabel(spec == 0 ? "tiles" : "gltf");
}
BENCHMARK(BM_Glb4097PlainCopy)->Arg(0)->Arg(1)->Iterations(3)->Unit(benchmark::kMillisecond)->UseRealTime();
