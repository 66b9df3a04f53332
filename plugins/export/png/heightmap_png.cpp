#include "heightmap_png.hpp"

#include <orogen/parallel.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace orogen::png_export {

Range range_of(ConstGridView grid) {
    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    for (float v : grid.span()) {
        if (v < lo) lo = v;
        if (v > hi) hi = v;
    }
    if (lo > hi) lo = hi = 0.0f;  // empty or all NaN
    return {lo, hi};
}

std::vector<std::uint16_t> quantise(ConstGridView grid, int bits, Range range) {
    const double top = bits == 16 ? 65535.0 : 255.0;
    const double span = double(range.high) - double(range.low);
    const double scale = span > 0.0 ? top / span : 0.0;
    std::vector<std::uint16_t> out(grid.size());
    parallel_for(0, std::int64_t(grid.size()), 1 << 16, [&](std::int64_t i0, std::int64_t i1) {
        for (std::int64_t i = i0; i < i1; ++i) {
            const double v = std::round((double(grid.data[i]) - range.low) * scale);
            out[std::size_t(i)] = std::uint16_t(std::clamp(std::isnan(v) ? 0.0 : v, 0.0, top));
        }
    });
    return out;
}

}  // namespace orogen::png_export
