// banks.cpp — lateral erosion of river banks (banks.hpp).
#include "banks.hpp"

#include "flow.hpp"

#include <orogen/parallel.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace orogen::stream_power {

namespace {

/// The turn (in 45° steps, 0–4) from direction code `in` to `out`.
int turn(int in, int out) {
    const int d = ((out - in) % 8 + 8) % 8;
    return std::min(d, 8 - d);
}

}  // namespace

void bank_pushes(const Banks& banks, const BankWindow& w, const std::int8_t* dir, const double* area,
                 const double* incised, std::vector<double>& right, std::vector<double>& left) {
    const std::size_t n = std::size_t(w.width) * std::size_t(w.height);
    right.assign(n, 0.0);
    left.assign(n, 0.0);
    const double inv_ab = 1.0 / banks.area;
    parallel_for(w.y0, w.y1, 16, [&](std::int64_t yb, std::int64_t ye) {
        for (std::int64_t y = yb; y < ye; ++y)
            for (int x = w.x0; x < w.x1; ++x) {
                const std::size_t i = std::size_t(y) * std::size_t(w.width) + std::size_t(x);
                const int out = dir[i];
                if (out < 0 || !(incised[i] > 0.0)) continue;
                const double amount = banks.erosion * -std::expm1(-area[i] * inv_ab) * incised[i];
                // The main donor: the neighbour sending its water here that drains the most
                // (ties: the lowest direction code, the same on any tiling).
                int in = -1;
                double best = -1.0;
                for (int k = 0; k < 8; ++k) {
                    const int nx = x + kDx[k], ny = int(y) + kDy[k];
                    if (nx < 0 || ny < 0 || nx >= w.width || ny >= w.height) continue;
                    const std::size_t d = std::size_t(ny) * std::size_t(w.width) + std::size_t(nx);
                    if (dir[d] == (k + 4) % 8 && area[d] > best) best = area[d], in = dir[d];
                }
                // The right bank lies at out + 90°, the left at out − 90°; the outer bank is the one on
                // the side the water comes from (a positive dot product with the incoming direction).
                double w0 = 0.5;
                if (in >= 0) {
                    const int t = turn(in, out);
                    if (t > 0) {
                        const double b = std::min(1.0, 0.5 * t);
                        const int s0 = (out + 2) % 8;
                        const bool outer0 = kDx[s0] * kDx[in] + kDy[s0] * kDy[in] > 0;
                        w0 = outer0 ? 0.5 * (1.0 + b) : 0.5 * (1.0 - b);
                    }
                }
                right[i] = amount * w0;
                left[i] = amount * (1.0 - w0);
            }
    });
}

double lower_banks(const Banks& banks, const BankWindow& w, const std::int8_t* dir, const double* right,
                   const double* left, const std::uint8_t* outlet, double cell, double* heights,
                   std::vector<double>& scratch) {
    const double floor_slope = banks.floor_slope;
    const int cw = w.x1 - w.x0;
    scratch.assign(std::size_t(cw) * std::size_t(std::max(0, w.y1 - w.y0)), 0.0);
    parallel_for(w.y0, w.y1, 16, [&](std::int64_t yb, std::int64_t ye) {
        for (std::int64_t y = yb; y < ye; ++y)
            for (int x = w.x0; x < w.x1; ++x) {
                const std::size_t l = std::size_t(y) * std::size_t(w.width) + std::size_t(x);
                double& out = scratch[std::size_t(y - w.y0) * std::size_t(cw) + std::size_t(x - w.x0)];
                out = heights[l];
                if (outlet && outlet[l]) continue;
                double drop = 0.0, strongest = 0.0, floor = 0.0;
                for (int k = 0; k < 8; ++k) {
                    const int nx = x + kDx[k], ny = int(y) + kDy[k];
                    if (nx < 0 || ny < 0 || nx >= w.width || ny >= w.height) continue;
                    const std::size_t i = std::size_t(ny) * std::size_t(w.width) + std::size_t(nx);
                    const int d = dir[i];
                    if (d < 0) continue;
                    const int back = (k + 4) % 8;  // from the river cell i to this bank
                    double p = 0.0;
                    if ((d + 2) % 8 == back) p = right[i];
                    else if ((d + 6) % 8 == back) p = left[i];
                    if (!(p > 0.0)) continue;
                    drop += p;
                    if (p > strongest)
                        strongest = p, floor = heights[i] + ((k & 1) ? std::numbers::sqrt2 : 1.0) * cell * floor_slope;
                }
                if (drop > 0.0 && heights[l] > floor) out = std::max(floor, heights[l] - drop);
            }
    });
    double removed = 0.0;
    for (int y = w.y0; y < w.y1; ++y)
        for (int x = w.x0; x < w.x1; ++x) {
            const std::size_t l = std::size_t(y) * std::size_t(w.width) + std::size_t(x);
            const double v = scratch[std::size_t(y - w.y0) * std::size_t(cw) + std::size_t(x - w.x0)];
            removed += (heights[l] - v) * cell * cell;
            heights[l] = v;
        }
    return removed;
}

}  // namespace orogen::stream_power
