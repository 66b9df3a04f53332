// The floodplains of large rivers (floodplain.hpp).
#include "floodplain.hpp"

#include "flow.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace orogen::stream_power {

bool floodplain_source(const Floodplain& fp, double cell, int dir, double area, double h, double h_receiver,
                       double& reach) {
    if (dir < 0 || !(area >= fp.area)) return false;
    if (fp.max_slope > 0.0) {  // a steep reach (a gorge) planes no floor
        const double run = cell * ((dir & 1) ? std::numbers::sqrt2 : 1.0);
        if (h - h_receiver > fp.max_slope * run) return false;
    }
    reach = fp.width / cell * std::pow(area / fp.area, fp.exponent);
    return true;
}

void stamp_floodplains(std::span<const FloodplainSource> sources, int grid_width, FloodplainWindow window,
                       std::vector<double>& nearest, std::vector<double>& floor) {
    const std::size_t n = std::size_t(window.width) * std::size_t(window.height);
    nearest.assign(n, std::numeric_limits<double>::infinity());
    floor.resize(n);
    const int wx1 = window.x0 + window.width, wy1 = window.y0 + window.height;
    for (const FloodplainSource& s : sources) {
        const int x = int(s.index % grid_width), y = int(s.index / grid_width);
        const int r = int(s.reach);
        if (x + r < window.x0 || x - r >= wx1 || y + r < window.y0 || y - r >= wy1) continue;
        for (int yy = std::max(y - r, window.y0); yy <= std::min(y + r, wy1 - 1); ++yy)
            for (int xx = std::max(x - r, window.x0); xx <= std::min(x + r, wx1 - 1); ++xx) {
                const double d = std::hypot(double(xx - x), double(yy - y));
                const std::size_t j =
                    std::size_t(yy - window.y0) * std::size_t(window.width) + std::size_t(xx - window.x0);
                if (d > s.reach || !(d < nearest[j])) continue;  // strictly nearer: ties keep the lower index
                nearest[j] = d;
                floor[j] = s.height;
            }
    }
}

double lower_to_floodplains(const Floodplain& fp, double cell, std::size_t n, const std::vector<double>& nearest,
                            const std::vector<double>& floor, const std::uint8_t* outlet, double* heights) {
    // A river cell is its own nearest (d = 0) and stays.
    const double rise = fp.slope * cell;  // m per cell
    double removed = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
        if (!(nearest[j] > 0.0) || std::isinf(nearest[j]) || (outlet && outlet[j])) continue;
        const double h = floor[j] + rise * nearest[j];
        if (h < heights[j]) {
            removed += heights[j] - h;
            heights[j] = h;
        }
    }
    return removed * cell * cell;
}

double carve_floodplains(const Floodplain& fp, int width, int height, double cell, const std::int8_t* dir,
                         const double* area, const std::uint8_t* outlet, double* heights, std::vector<double>& nearest,
                         std::vector<double>& floor) {
    // Every river's height is read before any cell is lowered.
    std::vector<FloodplainSource> sources;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(width) + std::size_t(x);
            const int k = dir[i];
            double reach = 0.0;
            const double receiver =
                k < 0 ? 0.0 : heights[std::size_t(y + kDy[k]) * std::size_t(width) + std::size_t(x + kDx[k])];
            if (floodplain_source(fp, cell, k, area[i], heights[i], receiver, reach))
                sources.push_back({std::int64_t(i), heights[i], reach});
        }
    stamp_floodplains(sources, width, {0, 0, width, height}, nearest, floor);
    return lower_to_floodplains(fp, cell, std::size_t(width) * std::size_t(height), nearest, floor, outlet, heights);
}

}  // namespace orogen::stream_power
