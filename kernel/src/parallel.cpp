#include <orogen/parallel.hpp>

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <vector>

namespace orogen {

void parallel_for(std::int64_t begin, std::int64_t end, std::int64_t grain,
                  const std::function<void(std::int64_t, std::int64_t)>& body) {
    if (end <= begin) return;
    if (grain < 1) grain = 1;
    if (end - begin <= grain) {
        body(begin, end);
        return;
    }
    tbb::parallel_for(tbb::blocked_range<std::int64_t>(begin, end, std::size_t(grain)),
                      [&](const tbb::blocked_range<std::int64_t>& r) { body(r.begin(), r.end()); });
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

int thread_count() {
    return int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
}

}  // namespace orogen
