// orogen/parallel.hpp — deterministic parallel loops.
//
// The kernel sets the thread count once (`orogen run --threads N`); plugins
// split their loops with these helpers instead of including oneTBB. Results
// must not depend on how the range is split: write each output element from
// one iteration only, and reduce in a fixed order (parallel_sum does).
#pragma once

#include <cstdint>
#include <functional>

#if defined(__x86_64__) || defined(__SSE__)
#include <xmmintrin.h>
#endif

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

/// While in scope, this thread treats denormal floats as zero (x86 FTZ | DAZ);
/// the previous mode is restored on exit. Simulations whose quantities decay
/// towards 1e-38 (evaporating water, thinning sediment) otherwise pay ~100
/// cycles per operation there. Open one at the top of every parallel body, so
/// every thread computes alike and results stay independent of the thread count.
class FlushDenormals {
public:
#if defined(__x86_64__) || defined(__SSE__)
    FlushDenormals() : saved_(_mm_getcsr()) { _mm_setcsr(saved_ | 0x8040u); }
    ~FlushDenormals() { _mm_setcsr(saved_); }

private:
    unsigned saved_;
#endif
};

}  // namespace orogen
