// banks.cpp — lateral erosion of river banks (banks.hpp).
#include "banks.hpp"

#include "flow.hpp"

#include <orogen/parallel.hpp>

#include <algorithm>
#include <cmath>

namespace orogen::stream_power {

namespace {

/// The turn (in 45° steps, 0–4) from direction code `in` to `out`.
int turn(int in, int out) {
    const int d = ((out - in) % 8 + 8) % 8;
    return std::min(d, 8 - d);
}

/// The share of a river cell's right and left pushes that falls on its edge neighbour at
/// direction 2·e from it, for each direction d it flows towards: the whole push on the neighbour
/// across an axis flow ((d + 2) mod 8 right, (d + 6) left), half on each of the two edge neighbours
/// flanking a diagonal flow on that side ((d + 1), (d + 3) right; (d + 5), (d + 7) left).
struct Shares {
    double right[8][4] = {}, left[8][4] = {};
};
constexpr Shares make_shares() {
    Shares s;
    for (int d = 0; d < 8; ++d)
        for (int e = 0; e < 4; ++e) {
            const int back = 2 * e;
            if (d % 2 == 0) {
                s.right[d][e] = back == (d + 2) % 8 ? 1.0 : 0.0;
                s.left[d][e] = back == (d + 6) % 8 ? 1.0 : 0.0;
            } else {
                s.right[d][e] = back == (d + 1) % 8 || back == (d + 3) % 8 ? 0.5 : 0.0;
                s.left[d][e] = back == (d + 5) % 8 || back == (d + 7) % 8 ? 0.5 : 0.0;
            }
        }
    return s;
}
constexpr Shares kShares = make_shares();

}  // namespace

BankAreaFactor::BankAreaFactor(const Banks& banks, double cell)
    : a0_(cell * cell), inv_a0_(1.0 / (cell * cell)), inv_ab_(1.0 / banks.area) {
    table_.resize(1 << 16);
    for (std::size_t c = 0; c < table_.size(); ++c) table_[c] = -std::expm1(-double(c) * a0_ * inv_ab_);
}

double BankAreaFactor::operator()(double area) const {
    const double c = area * inv_a0_;
    if (c < double(table_.size() - 1)) {
        const auto ci = std::size_t(c + 0.5);
        if (double(ci) * a0_ == area) return table_[ci];
    }
    return -std::expm1(-area * inv_ab_);
}

void bank_pushes(const Banks& banks, const BankAreaFactor& factor, const BankWindow& w, const std::int8_t* dir,
                 const double* area, const double* incised, std::vector<double>& right, std::vector<double>& left) {
    const std::size_t n = std::size_t(w.width) * std::size_t(w.height);
    if (right.size() != n || left.size() != n) {  // the cells outside the computed ones stay 0 (or a halo's)
        right.assign(n, 0.0);
        left.assign(n, 0.0);
    }
    double* const rp = right.data();
    double* const lp = left.data();
    const int W = w.width, H = w.height;
    const double kappa = banks.erosion;
    parallel_for(w.y0, w.y1, 16, [=, &factor](std::int64_t yb, std::int64_t ye) {
        for (std::int64_t y = yb; y < ye; ++y)
            for (int x = w.x0; x < w.x1; ++x) {
                const std::size_t i = std::size_t(y) * std::size_t(W) + std::size_t(x);
                const int out = dir[i];
                rp[i] = lp[i] = 0.0;
                if (out < 0 || !(incised[i] > 0.0)) continue;
                const double amount = kappa * factor(area[i]) * incised[i];
                // The main donor: the neighbour sending its water here that drains the most
                // (ties: the lowest direction code, the same on any tiling).
                int in = -1;
                double best = -1.0;
                for (int k = 0; k < 8; ++k) {
                    const int nx = x + kDx[k], ny = int(y) + kDy[k];
                    if (nx < 0 || ny < 0 || nx >= W || ny >= H) continue;
                    const std::size_t d = std::size_t(ny) * std::size_t(W) + std::size_t(nx);
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
                rp[i] = amount * w0;
                lp[i] = amount * (1.0 - w0);
            }
    });
}

double lower_banks(const Banks& banks, const BankWindow& w, const std::int8_t* dir, const double* right,
                   const double* left, const std::uint8_t* outlet, double cell, double* heights,
                   std::vector<double>& scratch) {
    const double rise = cell * banks.floor_slope;
    const int W = w.width, H = w.height, cw = w.x1 - w.x0, ch = std::max(0, w.y1 - w.y0);
    scratch.resize(std::size_t(cw) * std::size_t(ch) + std::size_t(ch));  // new heights, then each row's volume
    double* const out = scratch.data();
    double* const row_volume = out + std::size_t(cw) * std::size_t(ch);
    const std::int64_t off[4] = {1, W, -1, -std::int64_t(W)};  // the edge neighbours, codes 0, 2, 4, 6
    parallel_for(w.y0, w.y1, 16, [=](std::int64_t yb, std::int64_t ye) {
        for (std::int64_t y = yb; y < ye; ++y)
            for (int x = w.x0; x < w.x1; ++x) {
                const std::size_t l = std::size_t(y) * std::size_t(W) + std::size_t(x);
                double& o = out[std::size_t(y - w.y0) * std::size_t(cw) + std::size_t(x - w.x0)];
                const double hl = heights[l];
                o = hl;
                if (outlet && outlet[l]) continue;
                const bool inner = x > 0 && y > 0 && x + 1 < W && y + 1 < H;
                double drop = 0.0, strongest = 0.0, floor = 0.0;
                for (int e = 0; e < 4; ++e) {  // banks are the rivers' edge neighbours
                    const int k = 2 * e;
                    if (!inner) {
                        const int nx = x + kDx[k], ny = int(y) + kDy[k];
                        if (nx < 0 || ny < 0 || nx >= W || ny >= H) continue;
                    }
                    const std::size_t i = std::size_t(std::int64_t(l) + off[e]);
                    const int d = dir[i];
                    if (d < 0) continue;
                    const int back = (e + 2) % 4;  // the direction from the river cell i to this bank, halved
                    const double p = right[i] * kShares.right[d][back] + left[i] * kShares.left[d][back];
                    if (!(p > 0.0)) continue;
                    drop += p;
                    if (p > strongest) strongest = p, floor = heights[i] + rise;
                }
                if (drop > 0.0 && hl > floor) o = std::max(floor, hl - drop);
            }
    });
    // Write back and sum the volume row by row (each row's sum in a fixed order, then the rows in order).
    parallel_for(w.y0, w.y1, 16, [=](std::int64_t yb, std::int64_t ye) {
        for (std::int64_t y = yb; y < ye; ++y) {
            double v = 0.0;
            for (int x = w.x0; x < w.x1; ++x) {
                const std::size_t l = std::size_t(y) * std::size_t(W) + std::size_t(x);
                const double o = out[std::size_t(y - w.y0) * std::size_t(cw) + std::size_t(x - w.x0)];
                v += heights[l] - o;
                heights[l] = o;
            }
            row_volume[y - w.y0] = v;
        }
    });
    double removed = 0.0;
    for (int r = 0; r < ch; ++r) removed += row_volume[r];
    return removed * cell * cell;
}

}  // namespace orogen::stream_power
