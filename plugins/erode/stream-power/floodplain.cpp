// The floodplains of large rivers (floodplain.hpp).
#include "floodplain.hpp"

#include "flow.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace orogen::stream_power {

double carve_floodplains(const Floodplain& fp, int width, int height, double cell, const std::int8_t* dir,
                         const double* area, const std::uint8_t* outlet, double* heights, std::vector<double>& nearest,
                         std::vector<double>& floor) {
    const std::size_t n = std::size_t(width) * std::size_t(height);
    constexpr double none = std::numeric_limits<double>::infinity();
    nearest.assign(n, none);  // distance (cells) to the nearest river whose floodplain reaches the cell
    floor.resize(n);  // that river's height (m)
    const double reach_at_area = fp.width / cell;  // cells
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(width) + std::size_t(x);
            if (dir[i] < 0 || !(area[i] >= fp.area)) continue;
            if (fp.max_slope > 0.0) {  // a steep reach (a gorge) planes no floor
                const int k = dir[i];
                const std::size_t to = std::size_t(y + kDy[k]) * std::size_t(width) + std::size_t(x + kDx[k]);
                const double run = cell * ((k & 1) ? std::numbers::sqrt2 : 1.0);
                if (heights[i] - heights[to] > fp.max_slope * run) continue;
            }
            const double reach = reach_at_area * std::pow(area[i] / fp.area, fp.exponent);
            const int r = int(reach);
            for (int dy = -r; dy <= r; ++dy) {
                const int yy = y + dy;
                if (yy < 0 || yy >= height) continue;
                for (int dx = -r; dx <= r; ++dx) {
                    const int xx = x + dx;
                    if (xx < 0 || xx >= width) continue;
                    const double d = std::hypot(double(dx), double(dy));
                    const std::size_t j = std::size_t(yy) * std::size_t(width) + std::size_t(xx);
                    if (d > reach || !(d < nearest[j])) continue;  // strictly nearer: ties keep the lower index
                    nearest[j] = d;
                    floor[j] = heights[i];
                }
            }
        }
    // The rivers' own heights were read above before any cell is lowered; a river cell is its own nearest
    // (d = 0) and stays.
    const double rise = fp.slope * cell;  // m per cell
    double removed = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
        if (!(nearest[j] > 0.0) || nearest[j] == none || (outlet && outlet[j])) continue;
        const double h = floor[j] + rise * nearest[j];
        if (h < heights[j]) {
            removed += heights[j] - h;
            heights[j] = h;
        }
    }
    return removed * cell * cell;
}

}  // namespace orogen::stream_power
