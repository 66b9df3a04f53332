// The node cache's entries (kernel/src/cache.cpp): reading one back (mmap, the arrays copied into fresh
// vectors that a Heightmap adopts, beside the payload's XXH3-128 checksum, all on both cores) and writing one
// (encode, checksum, temporary + rename),
// for a 2049² heightmap with four layers (80 MiB) — the size of a 4097² run's smaller values. Bytes per
// second are the entry's size over the real time. The folder is in /tmp, and read from the page cache,
// as a re-run finds it. On a shared machine the real time says little: the counter `all_threads_cpu_ms` is
// the CPU time of the whole process (every thread, user + system, page faults included) per iteration.
#include "cache.hpp"

#include <benchmark/benchmark.h>

#include <filesystem>
#include <sys/resource.h>
#include <unistd.h>

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
        state.counters["all_threads_cpu_ms"] = 1e3 * (process_cpu_seconds() - start) / double(std::max<std::int64_t>(1, state.iterations()));
    }
};

cache::Digest key() {
    cache::Hasher h;
    return h.text("bench").finish();
}

}  // namespace

static void BM_CacheRead(benchmark::State& state) {
    const int n = int(state.range(0));
    cache::Store store({folder(), std::uint64_t(8) << 30}, [](const std::string& w) { std::fprintf(stderr, "%s\n", w.c_str()); });
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
    cache::Store store({folder(), std::uint64_t(8) << 30}, [](const std::string& w) { std::fprintf(stderr, "%s\n", w.c_str()); });
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
