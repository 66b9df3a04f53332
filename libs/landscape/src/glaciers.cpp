// glaciers.cpp — ice flux down the flow graph and U-shaped troughs (glaciers.hpp).
#include <orogen/landscape/glaciers.hpp>

#include <orogen/parallel.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>

namespace orogen::landscape {

namespace {
constexpr double kReferenceFlux = 1e6;  // m³/yr: the flux half_width is given for
constexpr int kMaxRadiusCells = 24;  // a trough reaches at most this many cells from its glacier

/// h = min(h, v), atomically: troughs of neighbouring glaciers overlap.
void lower_to(double& h, double v) {
    std::atomic_ref<double> target(h);
    double now = target.load(std::memory_order_relaxed);
    while (v < now && !target.compare_exchange_weak(now, v, std::memory_order_relaxed)) {}
}
}  // namespace

double Glaciers::half_width_for(double q) const { return half_width * std::pow(q / kReferenceFlux, 0.4); }

void ice_flux(const Glaciers& g, const double* heights, const std::int32_t* stack, const std::int32_t* receiver,
              std::size_t count, double cell, std::vector<double>& flux) {
    flux.assign(count, 0.0);
    const double area = cell * cell;
    // Donors before receivers: the stack reversed.
    for (std::size_t k = count; k-- > 0;) {
        const std::int32_t i = stack[k];
        const double q = std::max(0.0, flux[std::size_t(i)] + g.balance(heights[i]) * area);
        flux[std::size_t(i)] = q;
        const std::int32_t r = receiver[i];
        if (r != i) flux[std::size_t(r)] += q;
    }
}

double carve_troughs(const Glaciers& g, double* heights, const std::vector<double>& flux, const std::int32_t* receiver,
                     int width, int height, double cell) {
    const std::vector<double> before(heights, heights + flux.size());
    // The glaciers in parallel, rows of them at a time: each lowers its trough's cells by an atomic minimum,
    // and a minimum does not depend on the order its candidates come in, so neither do the bits.
    parallel_for(0, height, 8, [&](std::int64_t y0, std::int64_t y1) {
        for (int y = int(y0); y < int(y1); ++y)
            for (int x = 0; x < width; ++x) {
                const std::size_t c = std::size_t(y) * std::size_t(width) + std::size_t(x);
                const double q = flux[c];
                const std::int32_t r = receiver[c];
                if (!(q >= g.glacier_flux) || r == std::int32_t(c)) continue;
                const double R = g.half_width_for(q);
                const int reach = std::min(kMaxRadiusCells, int(R / cell));
                if (reach < 1) continue;
                // The ice's direction (fx, fy), unit, and the bed's slope down it.
                const int rx = int(r % width), ry = int(r / width);
                const double fx = rx - x, fy = ry - y, length = std::hypot(fx, fy) * cell;
                const double ux = fx * cell / length, uy = fy * cell / length;
                const double slope = std::max(0.0, (before[c] - before[std::size_t(r)]) / length);
                const double a = g.wall_slope / (2.0 * R);  // a·p²: slope 2·a·R = tan θ_w at p = R
                const double floor = before[c];
                for (int dy = -reach; dy <= reach; ++dy) {
                    const int ty = y + dy;
                    if (ty < 0 || ty >= height) continue;
                    for (int dx = -reach; dx <= reach; ++dx) {
                        const int tx = x + dx;
                        if (tx < 0 || tx >= width) continue;
                        const double s = (dx * ux + dy * uy) * cell, p = (dy * ux - dx * uy) * cell;
                        if (std::abs(s) > 0.5 * cell * 1.4142135623730951 || std::abs(p) > R) continue;
                        lower_to(heights[std::size_t(ty) * std::size_t(width) + std::size_t(tx)],
                                 floor - slope * s + a * p * p);
                    }
                }
            }
    });
    double removed = 0.0;
    for (std::size_t i = 0; i < flux.size(); ++i) removed += before[i] - heights[i];
    return removed * cell * cell;
}

}  // namespace orogen::landscape
