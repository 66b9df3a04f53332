#include <orogen/parallel.hpp>

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace orogen {

#if defined(__SANITIZE_THREAD__)
#define OROGEN_THREAD_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define OROGEN_THREAD_SANITIZER 1
#endif
#endif

#ifdef OROGEN_THREAD_SANITIZER
namespace {
// Under ThreadSanitizer (make tsan) the loops run on plain std::threads. libtbb is not built with TSan, so
// TSan would not see oneTBB's own synchronisation and would report its scheduler's bookkeeping as races in
// every loop; it does see thread start, join and std::atomic. The bodies, which are what it is here to check,
// run concurrently on the same number of threads and sub-ranges of the same kind (at least `grain` long).
void parallel_for_threads(std::int64_t begin, std::int64_t end, std::int64_t grain,
                          const std::function<void(std::int64_t, std::int64_t)>& body) {
    const int threads =
        std::max(1, int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism)));
    // sub-ranges of at least `grain`, about 16 a thread (TSan makes every atomic step costly)
    grain = std::max(grain, (end - begin + 16 * threads - 1) / (16 * threads));
    std::atomic<std::int64_t> next{begin};
    std::mutex failure_mutex;
    std::exception_ptr failure;
    auto work = [&] {
        for (;;) {
            const std::int64_t lo = next.fetch_add(grain);
            if (lo >= end) return;
            try {
                body(lo, std::min(end, lo + grain));
            } catch (...) {
                std::lock_guard lock(failure_mutex);
                if (!failure) failure = std::current_exception();
                next = end;  // the others stop at their next sub-range
            }
        }
    };
    std::vector<std::thread> helpers;
    for (int t = 1; t < threads && std::int64_t(t) * grain < end - begin; ++t) helpers.emplace_back(work);
    work();
    for (auto& h : helpers) h.join();
    if (failure) std::rethrow_exception(failure);
}
}  // namespace
#endif

void parallel_for(std::int64_t begin, std::int64_t end, std::int64_t grain,
                  const std::function<void(std::int64_t, std::int64_t)>& body) {
    if (end <= begin) return;
    if (grain < 1) grain = 1;
    if (end - begin <= grain) {
        body(begin, end);
        return;
    }
#ifdef OROGEN_THREAD_SANITIZER
    parallel_for_threads(begin, end, grain, body);
#else
    tbb::parallel_for(tbb::blocked_range<std::int64_t>(begin, end, std::size_t(grain)),
                      [&](const tbb::blocked_range<std::int64_t>& r) { body(r.begin(), r.end()); });
#endif
}

double parallel_sum(std::int64_t begin, std::int64_t end, std::int64_t block,
                    const std::function<double(std::int64_t, std::int64_t)>& body) {
    if (end <= begin) return 0.0;
    if (block < 1) block = 1;
    const std::int64_t blocks = (end - begin + block - 1) / block;
    std::vector<double> partial(std::size_t(blocks), 0.0);
    parallel_for(0, blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
        for (std::int64_t b = b0; b < b1; ++b) {
            const std::int64_t lo = begin + b * block;
            const std::int64_t hi = std::min(end, lo + block);
            partial[std::size_t(b)] = body(lo, hi);
        }
    });
    double sum = 0.0;  // fixed order: identical for every thread count
    for (double p : partial) sum += p;
    return sum;
}

int thread_count() { return int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism)); }

}  // namespace orogen
