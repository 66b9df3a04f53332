#include <orogen/formats/heightmap_png.hpp>

#include <orogen/parallel.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace orogen::formats::png {

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

std::vector<std::uint16_t> hillshade(ConstGridView h, int bits, double azimuth_degrees, double elevation_degrees,
                                     double vertical_scale) {
    const double top = bits == 16 ? 65535.0 : 255.0;
    const double az = azimuth_degrees * 3.14159265358979323846 / 180.0;
    const double el = elevation_degrees * 3.14159265358979323846 / 180.0;
    // Light direction in (east, south, up): north is −y.
    const double lx = std::sin(az) * std::cos(el), ly = -std::cos(az) * std::cos(el), lz = std::sin(el);
    std::vector<std::uint16_t> out(h.size());
    parallel_for(0, h.height, 16, [&](std::int64_t y0, std::int64_t y1) {
        for (std::int64_t yy = y0; yy < y1; ++yy) {
            const int y = int(yy);
            const int ya = std::max(y - 1, 0), yb = std::min(y + 1, h.height - 1);
            for (int x = 0; x < h.width; ++x) {
                const int xa = std::max(x - 1, 0), xb = std::min(x + 1, h.width - 1);
                const double gx =
                    xb > xa ? (double(h.at(xb, y)) - h.at(xa, y)) * vertical_scale / ((xb - xa) * h.cell) : 0.0;
                const double gy =
                    yb > ya ? (double(h.at(x, yb)) - h.at(x, ya)) * vertical_scale / ((yb - ya) * h.cell) : 0.0;
                // Normal (−∂h/∂x, −∂h/∂y, 1), normalised.
                const double shade = (-gx * lx - gy * ly + lz) / std::sqrt(gx * gx + gy * gy + 1.0);
                const double v = std::round(std::clamp(std::isnan(shade) ? 0.0 : shade, 0.0, 1.0) * top);
                out[std::size_t(y) * std::size_t(h.width) + std::size_t(x)] = std::uint16_t(v);
            }
        }
    });
    return out;
}

}  // namespace orogen::formats::png
