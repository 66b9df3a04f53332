// diffusion.cpp — alternating-direction implicit hillslope diffusion (see diffusion.hpp).
#include "diffusion.hpp"

#include <orogen/parallel.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace orogen::diffusion {

namespace {

/// Thomas coefficients of the constant tridiagonal system (1 − a δ) along one
/// line of `n` vertices: sub-diagonal −a, diagonal 1 + 2a (1 + a at a closed
/// end, 1 with no off-diagonal at a fixed end), super-diagonal −a.
struct Line {
    std::vector<double> sub, cp, m;  // a_i, c'_i, 1/(b_i − a_i c'_{i−1})

    Line(int n, double a, bool first_fixed, bool last_fixed) : sub(std::size_t(n)), cp(std::size_t(n)), m(std::size_t(n)) {
        for (int i = 0; i < n; ++i) {
            double lo = i > 0 ? -a : 0.0, hi = i + 1 < n ? -a : 0.0;
            double diag = 1.0 - lo - hi;  // 1 + a per existing neighbour: the closed-end finite-volume form
            if ((i == 0 && first_fixed) || (i == n - 1 && last_fixed)) lo = hi = 0.0, diag = 1.0;
            const double denom = diag - (i > 0 ? lo * cp[std::size_t(i - 1)] : 0.0);
            m[std::size_t(i)] = 1.0 / denom;
            cp[std::size_t(i)] = hi * m[std::size_t(i)];
            sub[std::size_t(i)] = lo;
        }
    }
};

constexpr int kColumnBlock = 64;  // columns per task in the north–south sweeps (one 512-byte strip per row)

}  // namespace

Solver::Solver(int width, int height, double cell, const Settings& settings)
    : width_(width), height_(height), cell_(cell), settings_(settings) {
    if (width < 1 || height < 1 || !(cell > 0.0)) throw std::invalid_argument("diffusion::Solver: empty grid or cell <= 0");
    scratch_.resize(std::size_t(width) * std::size_t(height));
    if (settings.critical_slope > 0.0) {
        scratch2_.resize(scratch_.size());
        kx_.resize(scratch_.size());
        ky_.resize(scratch_.size());
    }
}

void Solver::step(double* h, double dt) {
    if (!(settings_.diffusivity > 0.0) || !(dt > 0.0)) return;
    if (settings_.critical_slope > 0.0)
        nonlinear_step(h, dt);
    else
        linear_step(h, dt);
}

void Solver::linear_step(double* h, double dt) {
    const int W = width_, H = height_;
    const double r = settings_.diffusivity * dt / (cell_ * cell_);
    const bool pr = settings_.scheme == Scheme::adi;
    const double a = pr ? 0.5 * r : r;  // implicit weight
    const double b = pr ? 0.5 * r : 0.0;  // explicit weight (the other direction)
    const FixedSides& f = settings_.fixed;
    const Line lx(W, a, f.west, f.east), ly(H, a, f.north, f.south);
    double* hs = scratch_.data();
    const std::size_t w = std::size_t(W);

    // West–east sweep: rows are independent. rhs = h + b δyy h (b = 0: rhs = h).
    // Four rows at a time: each row's forward and backward recurrences are a
    // chain of dependent multiply-adds, so one row alone waits on latency;
    // four interleaved chains keep the core busy. Each row's arithmetic is
    // the same as alone, so the bits do not depend on the grouping.
    auto solved = [&](std::int64_t y) { return !((y == 0 && f.north) || (y == H - 1 && f.south) || W == 1); };
    auto sweep = [&]<int R>(const std::int64_t* ys) {
        const double* row[R];
        const double* up[R];
        const double* down[R];
        double* out[R];
        for (int k = 0; k < R; ++k) {
            row[k] = h + std::size_t(ys[k]) * w;
            out[k] = hs + std::size_t(ys[k]) * w;
            up[k] = ys[k] > 0 ? row[k] - w : nullptr;
            down[k] = ys[k] + 1 < H ? row[k] + w : nullptr;
        }
        double prev[R] = {};
        for (int x = 0; x < W; ++x) {
            const bool explicit_part = b != 0.0 && !((x == 0 && f.west) || (x == W - 1 && f.east));
            const double sub = lx.sub[std::size_t(x)], mx = lx.m[std::size_t(x)];
            for (int k = 0; k < R; ++k) {
                double rhs = row[k][x];
                if (explicit_part) {
                    double lap = 0.0;
                    if (up[k]) lap += up[k][x] - row[k][x];
                    if (down[k]) lap += down[k][x] - row[k][x];
                    rhs += b * lap;
                }
                prev[k] = (rhs - sub * prev[k]) * mx;
                out[k][x] = prev[k];
            }
        }
        for (int x = W - 2; x >= 0; --x) {
            const double cp = lx.cp[std::size_t(x)];
            for (int k = 0; k < R; ++k) out[k][x] -= cp * out[k][x + 1];
        }
    };
    parallel_for(0, H, 8, [&](std::int64_t y0, std::int64_t y1) {
        std::int64_t ys[4];
        int held = 0;
        for (std::int64_t y = y0; y < y1; ++y) {
            if (!solved(y)) {
                std::copy(h + std::size_t(y) * w, h + std::size_t(y) * w + w, hs + std::size_t(y) * w);
                continue;
            }
            ys[held++] = y;
            if (held == 4) sweep.template operator()<4>(ys), held = 0;
        }
        for (int k = 0; k < held; ++k) sweep.template operator()<1>(ys + k);
    });

    // North–south sweep: columns are independent; each task takes a strip of
    // columns and runs the recurrence down the rows (vectorised across x).
    const std::int64_t blocks = (W + kColumnBlock - 1) / kColumnBlock;
    parallel_for(0, blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
        for (std::int64_t blk = b0; blk < b1; ++blk) {
            const int x0 = int(blk) * kColumnBlock, x1 = std::min(W, x0 + kColumnBlock);
            if (H == 1) {
                std::copy(hs + x0, hs + x1, h + x0);
                continue;
            }
            for (int y = 0; y < H; ++y) {
                const double* src = hs + std::size_t(y) * w;
                double* out = h + std::size_t(y) * w;
                const double* prev = y > 0 ? out - w : nullptr;
                const double sub = ly.sub[std::size_t(y)], m = ly.m[std::size_t(y)];
                const bool fixed_row = (y == 0 && f.north) || (y == H - 1 && f.south);
                for (int x = x0; x < x1; ++x) {
                    double rhs = src[x];
                    if (b != 0.0 && !fixed_row) {
                        double lap = 0.0;
                        if (x > 0) lap += src[x - 1] - src[x];
                        if (x + 1 < W) lap += src[x + 1] - src[x];
                        rhs += b * lap;
                    }
                    out[x] = (rhs - sub * (prev ? prev[x] : 0.0)) * m;
                }
            }
            for (int y = H - 2; y >= 0; --y) {
                double* out = h + std::size_t(y) * w;
                const double* next = out + w;
                const double cp = ly.cp[std::size_t(y)];
                for (int x = x0; x < x1; ++x) out[x] -= cp * next[x];
            }
            // Fixed columns keep their height (their own north–south system would move them).
            for (int y = 0; y < H; ++y) {
                if (f.west && x0 == 0) h[std::size_t(y) * w] = hs[std::size_t(y) * w];
                if (f.east && x1 == W) h[std::size_t(y) * w + w - 1] = hs[std::size_t(y) * w + w - 1];
            }
        }
    });
}

void Solver::nonlinear_step(double* h, double dt) {
    // Lagged coefficients: each link's factor 1/(1 − (S/Sc)²) from the slope
    // across it at the start of the step; then the two backward-Euler sweeps
    // with those variable coefficients (a flux form, so Σh is still conserved
    // with closed sides).
    const int W = width_, H = height_;
    const std::size_t w = std::size_t(W);
    const double r = settings_.diffusivity * dt / (cell_ * cell_);
    const double sc = settings_.critical_slope, cap = settings_.max_factor;
    const FixedSides& f = settings_.fixed;
    auto factor = [&](double dh) {
        const double s = std::abs(dh) / cell_ / sc;
        const double d = 1.0 - s * s;
        return d <= 1.0 / cap ? cap : 1.0 / d;
    };
    // kx_[y*w + x]: link (x, x+1); ky_[y*w + x]: link (y, y+1).
    parallel_for(0, H, 16, [&](std::int64_t y0, std::int64_t y1) {
        for (std::int64_t y = y0; y < y1; ++y) {
            const double* row = h + std::size_t(y) * w;
            for (int x = 0; x + 1 < W; ++x) kx_[std::size_t(y) * w + x] = r * factor(row[x + 1] - row[x]);
            if (y + 1 < H)
                for (int x = 0; x < W; ++x) ky_[std::size_t(y) * w + x] = r * factor(row[x + w] - row[x]);
        }
    });
    double* hs = scratch_.data();
    double* cps = scratch2_.data();
    parallel_for(0, H, 8, [&](std::int64_t y0, std::int64_t y1) {
        for (std::int64_t y = y0; y < y1; ++y) {
            const double* row = h + std::size_t(y) * w;
            double* out = hs + std::size_t(y) * w;
            double* cp = cps + std::size_t(y) * w;
            const double* k = kx_.data() + std::size_t(y) * w;
            if ((y == 0 && f.north) || (y == H - 1 && f.south) || W == 1) {
                std::copy(row, row + w, out);
                continue;
            }
            double prev = 0.0, prev_cp = 0.0;
            for (int x = 0; x < W; ++x) {
                double lo = x > 0 ? -k[x - 1] : 0.0, hi = x + 1 < W ? -k[x] : 0.0;
                double diag = 1.0 - lo - hi;
                if ((x == 0 && f.west) || (x == W - 1 && f.east)) lo = hi = 0.0, diag = 1.0;
                const double m = 1.0 / (diag - lo * prev_cp);
                prev_cp = hi * m;
                cp[x] = prev_cp;
                prev = (row[x] - lo * prev) * m;
                out[x] = prev;
            }
            for (int x = W - 2; x >= 0; --x) out[x] -= cp[x] * out[x + 1];
        }
    });
    const std::int64_t blocks = (W + kColumnBlock - 1) / kColumnBlock;
    parallel_for(0, blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
        for (std::int64_t blk = b0; blk < b1; ++blk) {
            const int x0 = int(blk) * kColumnBlock, x1 = std::min(W, x0 + kColumnBlock);
            if (H == 1) {
                std::copy(hs + x0, hs + x1, h + x0);
                continue;
            }
            for (int y = 0; y < H; ++y) {
                const double* src = hs + std::size_t(y) * w;
                double* out = h + std::size_t(y) * w;
                double* cp = cps + std::size_t(y) * w;
                const bool fixed_row = (y == 0 && f.north) || (y == H - 1 && f.south);
                for (int x = x0; x < x1; ++x) {
                    double lo = y > 0 ? -ky_[std::size_t(y - 1) * w + x] : 0.0;
                    double hi = y + 1 < H ? -ky_[std::size_t(y) * w + x] : 0.0;
                    double diag = 1.0 - lo - hi;
                    if (fixed_row) lo = hi = 0.0, diag = 1.0;
                    const double pcp = y > 0 ? cp[x - std::ptrdiff_t(w)] : 0.0;
                    const double pd = y > 0 ? out[x - std::ptrdiff_t(w)] : 0.0;
                    const double m = 1.0 / (diag - lo * pcp);
                    cp[x] = hi * m;
                    out[x] = (src[x] - lo * pd) * m;
                }
            }
            for (int y = H - 2; y >= 0; --y) {
                double* out = h + std::size_t(y) * w;
                const double* cp = cps + std::size_t(y) * w;
                for (int x = x0; x < x1; ++x) out[x] -= cp[x] * out[x + w];
            }
            for (int y = 0; y < H; ++y) {
                if (f.west && x0 == 0) h[std::size_t(y) * w] = hs[std::size_t(y) * w];
                if (f.east && x1 == W) h[std::size_t(y) * w + w - 1] = hs[std::size_t(y) * w + w - 1];
            }
        }
    });
}

double total(const double* heights, std::size_t count) {
    return parallel_sum(0, std::int64_t(count), 65536, [&](std::int64_t b, std::int64_t e) {
        double s = 0.0;
        for (std::int64_t i = b; i < e; ++i) s += heights[i];
        return s;
    });
}

}  // namespace orogen::diffusion
