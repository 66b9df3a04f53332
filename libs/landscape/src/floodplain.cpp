// The floodplains of large rivers (floodplain.hpp).
#include <orogen/landscape/floodplain.hpp>

#include <orogen/landscape/flow.hpp>

#include <orogen/parallel.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <numbers>

namespace orogen::landscape {

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
    nearest.resize(n);
    floor.resize(n);
    // hypot(dx, dy) for every offset within the longest reach, once: the very values the cells compare.
    int longest = 0;
    for (const FloodplainSource& s : sources) longest = std::max(longest, int(s.reach));
    const std::size_t side = std::size_t(longest) + 1;
    std::vector<double> distance(side * side);
    for (std::size_t dy = 0; dy < side; ++dy)
        for (std::size_t dx = 0; dx < side; ++dx) distance[dy * side + dx] = std::hypot(double(dx), double(dy));
    const int wx1 = window.x0 + window.width;
    // Bands of rows in parallel: each band's cells see the sources that reach them in the same (index)
    // order as one pass over the whole window would, and only its own thread writes them.
    parallel_for(window.y0, window.y0 + window.height, 16, [&](std::int64_t yb, std::int64_t ye) {
        std::fill(nearest.begin() + std::ptrdiff_t((yb - window.y0) * window.width),
                  nearest.begin() + std::ptrdiff_t((ye - window.y0) * window.width),
                  std::numeric_limits<double>::infinity());
        const std::int64_t first_row = std::max<std::int64_t>(0, yb - longest), last_row = ye + longest;
        const auto by_index = [](const FloodplainSource& s, std::int64_t i) { return s.index < i; };
        const auto from = std::lower_bound(sources.begin(), sources.end(), first_row * grid_width, by_index);
        const auto to = std::lower_bound(from, sources.end(), last_row * grid_width, by_index);
        for (auto it = from; it != to; ++it) {
            const FloodplainSource& s = *it;
            const int x = int(s.index % grid_width), y = int(s.index / grid_width);
            const int r = int(s.reach);
            if (x + r < window.x0 || x - r >= wx1 || y + r < yb || y - r >= ye) continue;
            for (int yy = std::max<int>(y - r, int(yb)); yy <= std::min<int>(y + r, int(ye) - 1); ++yy) {
                const double* row = distance.data() + std::size_t(std::abs(yy - y)) * side;
                double* near = nearest.data() + std::size_t(yy - window.y0) * std::size_t(window.width);
                double* level = floor.data() + std::size_t(yy - window.y0) * std::size_t(window.width);
                for (int xx = std::max(x - r, window.x0); xx <= std::min(x + r, wx1 - 1); ++xx) {
                    const double d = row[std::abs(xx - x)];
                    const std::size_t j = std::size_t(xx - window.x0);
                    if (d > s.reach || !(d < near[j])) continue;  // strictly nearer: ties keep the lower index
                    near[j] = d;
                    level[j] = s.height;
                }
            }
        }
    });
}

double lower_to_floodplains(const Floodplain& fp, double cell, std::size_t n, const std::vector<double>& nearest,
                            const std::vector<double>& floor, const std::uint8_t* outlet, double* heights) {
    // A river cell is its own nearest (d = 0) and stays.
    const double rise = fp.slope * cell;  // m per cell
    const double removed = parallel_sum(0, std::int64_t(n), 1 << 16, [&](std::int64_t b, std::int64_t e) {
        double part = 0.0;
        for (std::size_t j = std::size_t(b); j < std::size_t(e); ++j) {
            if (!(nearest[j] > 0.0) || std::isinf(nearest[j]) || (outlet && outlet[j])) continue;
            const double h = floor[j] + rise * nearest[j];
            if (h < heights[j]) {
                part += heights[j] - h;
                heights[j] = h;
            }
        }
        return part;
    });
    return removed * cell * cell;
}

double carve_floodplains(const Floodplain& fp, int width, int height, double cell, const D8Flow& flow, double* heights,
                         std::vector<double>& nearest, std::vector<double>& floor) {
    const std::int8_t* const dir = flow.dir;
    const double* const area = flow.area;
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
    return lower_to_floodplains(fp, cell, std::size_t(width) * std::size_t(height), nearest, floor, flow.outlet,
                                heights);
}

}  // namespace orogen::landscape
