// orogen/parallel.hpp — deterministic parallel loops.
//
// The kernel sets the thread count once (`orogen run --threads N`); plugins
// split their loops with these helpers instead of including oneTBB. Results
// must not depend on how the range is split: write each output element from
// one iteration only, and reduce in a fixed order (parallel_sum does).
#pragma once

#include <cstdint>
#include <functional>

namespace orogen {

/// Call body(begin, end) on disjoint sub-ranges of [begin, end) in parallel,
/// sub-ranges at least `grain` long.
void parallel_for(std::int64_t begin, std::int64_t end, std::int64_t grain,
                  const std::function<void(std::int64_t, std::int64_t)>& body);

/// Sum of body(b, e) over fixed blocks of `block` indices, added in index
/// order: the same double whatever the thread count.
double parallel_sum(std::int64_t begin, std::int64_t end, std::int64_t block,
                    const std::function<double(std::int64_t, std::int64_t)>& body);

/// The number of threads parallel loops may use.
int thread_count();

}  // namespace orogen
