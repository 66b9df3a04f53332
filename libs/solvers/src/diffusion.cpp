// diffusion.cpp — alternating-direction implicit hillslope diffusion (see diffusion.hpp).
#include <orogen/solvers/diffusion.hpp>

#include <orogen/parallel.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace orogen::solvers::diffusion {

namespace {

/// Thomas coefficients of the constant tridiagonal system (1 − a δ) along one
/// line of `n` vertices: sub-diagonal −a, diagonal 1 + 2a (1 + a at a closed
/// end, 1 with no off-diagonal at a fixed end), super-diagonal −a.
struct Line {
    std::vector<double> sub, cp, m;  // a_i, c'_i, 1/(b_i − a_i c'_{i−1})

    Line(int n, double a, bool first_fixed, bool last_fixed)
        : sub(std::size_t(n)), cp(std::size_t(n)), m(std::size_t(n)) {
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

/// `pass(x0, x1)` over strips of kColumnBlock columns within [first, first + count), in parallel.
template <typename Pass>
void strips(int first, int count, const Pass& pass) {
    const std::int64_t blocks = (count + kColumnBlock - 1) / kColumnBlock;
    parallel_for(0, blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
        for (std::int64_t blk = b0; blk < b1; ++blk) {
            const int x0 = first + int(blk) * kColumnBlock;
            pass(x0, std::min(first + count, x0 + kColumnBlock));
        }
    });
}

}  // namespace

Solver::Solver(int width, int height, double cell, const Settings& settings)
    : W_(width), H_(height), x0_(0), y0_(0), tw_(width), th_(height), cell_(cell), settings_(settings) {
    if (width < 1 || height < 1 || !(cell > 0.0))
        throw std::invalid_argument("solvers::diffusion::Solver: empty grid or cell <= 0");
    scratch_.resize(std::size_t(width) * std::size_t(height));
    if (settings.critical_slope > 0.0) {
        scratch2_.resize(scratch_.size());
        kx_.resize(std::size_t(tw_ + 1) * std::size_t(th_));
        ky_.resize(std::size_t(tw_) * std::size_t(th_ + 1));
    }
}

Solver::Solver(Tiling& tiles, double cell, const Settings& settings)
    : Solver(tiles.owned().width, tiles.owned().height, cell, settings) {
    tiles_ = &tiles;
    W_ = tiles.grid_width(), H_ = tiles.grid_height();
    x0_ = tiles.owned().x0, y0_ = tiles.owned().y0;
}

void Solver::step(double* h, double dt) {
    if (!(settings_.diffusivity > 0.0) || !(dt > 0.0)) return;
    if (settings_.critical_slope > 0.0) nonlinear_step(h, dt);
    else linear_step(h, dt);
}

void Solver::carry(Tiling::Toward toward, std::vector<double>& values, int per_line,
                   const std::function<void(int first, int count)>& advance) {
    if (tiles_) tiles_->carry(toward, values, per_line, advance);
    else advance(0, int(values.size() / std::size_t(per_line)));
}

void Solver::edge_rows(const double* g) {
    const std::size_t w = std::size_t(tw_);
    north_.assign(w, 0.0), south_.assign(w, 0.0);
    if (!tiles_) return;  // one tile: the grid has no rows beyond it
    // South: what comes in is the north neighbour's last row; my last row goes on.
    carry_.assign(w, 0.0);
    carry(Tiling::Toward::south, carry_, 1, [&](int first, int count) {
        for (int x = first; x < first + count; ++x)
            north_[std::size_t(x)] = carry_[std::size_t(x)],
            carry_[std::size_t(x)] = g[std::size_t(th_ - 1) * w + std::size_t(x)];
    });
    carry_.assign(w, 0.0);
    carry(Tiling::Toward::north, carry_, 1, [&](int first, int count) {
        for (int x = first; x < first + count; ++x)
            south_[std::size_t(x)] = carry_[std::size_t(x)], carry_[std::size_t(x)] = g[std::size_t(x)];
    });
}

void Solver::edge_columns(const double* g) {
    const std::size_t w = std::size_t(tw_), n = std::size_t(th_);
    west_.assign(n, 0.0), east_.assign(n, 0.0);
    if (!tiles_) return;
    carry_.assign(n, 0.0);
    carry(Tiling::Toward::east, carry_, 1, [&](int first, int count) {
        for (int y = first; y < first + count; ++y)
            west_[std::size_t(y)] = carry_[std::size_t(y)], carry_[std::size_t(y)] = g[std::size_t(y) * w + w - 1];
    });
    carry_.assign(n, 0.0);
    carry(Tiling::Toward::west, carry_, 1, [&](int first, int count) {
        for (int y = first; y < first + count; ++y)
            east_[std::size_t(y)] = carry_[std::size_t(y)], carry_[std::size_t(y)] = g[std::size_t(y) * w];
    });
}

// Both steps below are written for a tile (x0_, y0_, tw_ × th_) of the whole
// W_ × H_ grid; the whole grid is the one tile. Coefficients, boundary tests
// and stencils use whole-grid positions; a recurrence starts from the carried
// value (0 at the grid's first line, as alone), and a stencil reads the
// neighbour's edge line (edge_rows, edge_columns) where it reaches past the
// tile. Every value is computed by the same operations in the same order as
// with one tile, so any split gives the same bits.

void Solver::linear_step(double* h, double dt) {
    const int W = W_, H = H_, X0 = x0_, Y0 = y0_, TW = tw_, TH = th_;
    const double r = settings_.diffusivity * dt / (cell_ * cell_);
    const bool pr = settings_.scheme == Scheme::adi;
    const double a = pr ? 0.5 * r : r;  // implicit weight
    const double b = pr ? 0.5 * r : 0.0;  // explicit weight (the other direction)
    const FixedSides& f = settings_.fixed;
    const Line lx(W, a, f.west, f.east), ly(H, a, f.north, f.south);
    double* hs = scratch_.data();
    const std::size_t w = std::size_t(TW);
    const bool eastmost = X0 + TW == W, southmost = Y0 + TH == H;
    if (b != 0.0) edge_rows(h);

    // West–east sweep: rows are independent. rhs = h + b δyy h (b = 0: rhs = h).
    // Four rows at a time: each row's forward and backward recurrences are a
    // chain of dependent multiply-adds, so one row alone waits on latency;
    // four interleaved chains keep the core busy. Each row's arithmetic is
    // the same as alone, so the bits do not depend on the grouping.
    auto solved = [&](std::int64_t y) { return !((Y0 + y == 0 && f.north) || (Y0 + y == H - 1 && f.south) || W == 1); };
    auto forward = [&]<int R>(const std::int64_t* ys) {
        const double* row[R];
        const double* up[R];
        const double* down[R];
        double* out[R];
        double prev[R];
        for (int k = 0; k < R; ++k) {
            const std::int64_t gy = Y0 + ys[k];
            row[k] = h + std::size_t(ys[k]) * w;
            out[k] = hs + std::size_t(ys[k]) * w;
            up[k] = gy > 0 ? (ys[k] > 0 ? row[k] - w : north_.data()) : nullptr;
            down[k] = gy + 1 < H ? (ys[k] + 1 < TH ? row[k] + w : south_.data()) : nullptr;
            prev[k] = carry_[std::size_t(ys[k])];
        }
        for (int x = 0; x < TW; ++x) {
            const int gx = X0 + x;
            const bool explicit_part = b != 0.0 && !((gx == 0 && f.west) || (gx == W - 1 && f.east));
            const double sub = lx.sub[std::size_t(gx)], mx = lx.m[std::size_t(gx)];
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
        for (int k = 0; k < R; ++k) carry_[std::size_t(ys[k])] = prev[k];
    };
    auto backward = [&]<int R>(const std::int64_t* ys) {
        double* out[R];
        for (int k = 0; k < R; ++k) out[k] = hs + std::size_t(ys[k]) * w;
        if (!eastmost) {  // the first value east of the tile: the east neighbour's solution
            const double cp = lx.cp[std::size_t(X0 + TW - 1)];
            for (int k = 0; k < R; ++k) out[k][TW - 1] -= cp * carry_[std::size_t(ys[k])];
        }
        for (int x = TW - 2; x >= 0; --x) {
            const double cp = lx.cp[std::size_t(X0 + x)];
            for (int k = 0; k < R; ++k) out[k][x] -= cp * out[k][x + 1];
        }
        for (int k = 0; k < R; ++k) carry_[std::size_t(ys[k])] = out[k][0];
    };
    // Rows [first, first + count) of the tile, four at a time, in parallel; `pass` gets the solved ones.
    auto rows = [&](int first, int count, auto&& pass, bool copy_unsolved) {
        parallel_for(first, first + count, 8, [&](std::int64_t y0, std::int64_t y1) {
            std::int64_t ys[4];
            int held = 0;
            for (std::int64_t y = y0; y < y1; ++y) {
                if (!solved(y)) {
                    if (copy_unsolved)
                        std::copy(h + std::size_t(y) * w, h + std::size_t(y) * w + w, hs + std::size_t(y) * w);
                    continue;
                }
                ys[held++] = y;
                if (held == 4) pass.template operator()<4>(ys), held = 0;
            }
            for (int k = 0; k < held; ++k) pass.template operator()<1>(ys + k);
        });
    };
    carry_.assign(std::size_t(TH), 0.0);
    carry(Tiling::Toward::east, carry_, 1, [&](int first, int count) { rows(first, count, forward, true); });
    carry_.assign(std::size_t(TH), 0.0);
    carry(Tiling::Toward::west, carry_, 1, [&](int first, int count) { rows(first, count, backward, false); });

    // North–south sweep: columns are independent; each task takes a strip of
    // columns and runs the recurrence down the rows (vectorised across x).
    if (H == 1) {
        std::copy(hs, hs + w * std::size_t(TH), h);
        return;
    }
    if (b != 0.0) edge_columns(hs);
    carry_.assign(w, 0.0);
    carry(Tiling::Toward::south, carry_, 1, [&](int first, int count) {
        strips(first, count, [&](int x0, int x1) {
            for (int y = 0; y < TH; ++y) {
                const int gy = Y0 + y;
                const double* src = hs + std::size_t(y) * w;
                double* out = h + std::size_t(y) * w;
                const double* prev = y > 0 ? out - w : carry_.data();  // 0 above the grid's first row
                const double sub = ly.sub[std::size_t(gy)], m = ly.m[std::size_t(gy)];
                const bool fixed_row = (gy == 0 && f.north) || (gy == H - 1 && f.south);
                if (b != 0.0 && !fixed_row) {
                    const double west = X0 + x0 > 0 ? (x0 > 0 ? src[x0 - 1] : west_[std::size_t(y)]) : 0.0;
                    const double east = X0 + x1 < W ? (x1 < TW ? src[x1] : east_[std::size_t(y)]) : 0.0;
                    for (int x = x0; x < x1; ++x) {
                        double lap = 0.0;
                        if (X0 + x > 0) lap += (x > x0 ? src[x - 1] : west) - src[x];
                        if (X0 + x + 1 < W) lap += (x + 1 < x1 ? src[x + 1] : east) - src[x];
                        out[x] = (src[x] + b * lap - sub * prev[x]) * m;
                    }
                } else {
                    for (int x = x0; x < x1; ++x) out[x] = (src[x] - sub * prev[x]) * m;
                }
            }
            for (int x = x0; x < x1; ++x) carry_[std::size_t(x)] = h[std::size_t(TH - 1) * w + std::size_t(x)];
        });
    });
    carry_.assign(w, 0.0);
    carry(Tiling::Toward::north, carry_, 1, [&](int first, int count) {
        strips(first, count, [&](int x0, int x1) {
            for (int y = southmost ? TH - 2 : TH - 1; y >= 0; --y) {
                double* out = h + std::size_t(y) * w;
                const double* next = y + 1 < TH ? out + w : carry_.data();  // the south neighbour's solution
                const double cp = ly.cp[std::size_t(Y0 + y)];
                for (int x = x0; x < x1; ++x) out[x] -= cp * next[x];
            }
            for (int x = x0; x < x1; ++x) carry_[std::size_t(x)] = h[std::size_t(x)];  // before the fixed columns below
            // Fixed columns keep their height (their own north–south system would move them).
            for (int y = 0; y < TH; ++y) {
                if (f.west && X0 + x0 == 0) h[std::size_t(y) * w] = hs[std::size_t(y) * w];
                if (f.east && eastmost && x1 == TW) h[std::size_t(y) * w + w - 1] = hs[std::size_t(y) * w + w - 1];
            }
        });
    });
}

void Solver::nonlinear_step(double* h, double dt) {
    // Lagged coefficients: each link's factor 1/(1 − (S/Sc)²) from the slope
    // across it at the start of the step; then the two backward-Euler sweeps
    // with those variable coefficients (a flux form, so Σh is still conserved
    // with closed sides).
    const int W = W_, H = H_, X0 = x0_, Y0 = y0_, TW = tw_, TH = th_;
    const std::size_t w = std::size_t(TW), kw = w + 1;
    const double r = settings_.diffusivity * dt / (cell_ * cell_);
    const double sc = settings_.critical_slope, cap = settings_.max_factor;
    const FixedSides& f = settings_.fixed;
    const bool eastmost = X0 + TW == W, southmost = Y0 + TH == H;
    auto factor = [&](double dh) {
        const double s = std::abs(dh) / cell_ / sc;
        const double d = 1.0 - s * s;
        return d <= 1.0 / cap ? cap : 1.0 / d;
    };
    edge_rows(h);
    edge_columns(h);
    // The links' factors, the tile's and those to the vertices just outside it:
    // kx_[y·kw + x + 1] is link (x, x+1) of row y, x from −1; ky_[(y + 1)·w + x]
    // link (y, y+1) of column x, y from −1 (tile coordinates). A link outside
    // the whole grid is never read.
    auto at = [&](int x, int y) {  // h at tile position (x, y), one vertex past the tile on one side at most
        if (x < 0) return west_[std::size_t(y)];
        if (x >= TW) return east_[std::size_t(y)];
        if (y < 0) return north_[std::size_t(x)];
        if (y >= TH) return south_[std::size_t(x)];
        return h[std::size_t(y) * w + std::size_t(x)];
    };
    parallel_for(-1, TH, 16, [&](std::int64_t y0, std::int64_t y1) {
        for (auto y = int(y0); y < int(y1); ++y) {
            if (y >= 0) {
                const double* row = h + std::size_t(y) * w;
                double* k = kx_.data() + std::size_t(y) * kw + 1;
                for (int x = 0; x + 1 < TW; ++x) k[x] = r * factor(row[x + 1] - row[x]);  // inside the tile
                if (X0 > 0) k[-1] = r * factor(at(0, y) - at(-1, y));
                if (X0 + TW < W) k[TW - 1] = r * factor(at(TW, y) - at(TW - 1, y));
            }
            if (Y0 + y < 0 || Y0 + y + 1 >= H) continue;
            double* k = ky_.data() + std::size_t(y + 1) * w;
            if (y >= 0 && y + 1 < TH) {
                const double* row = h + std::size_t(y) * w;
                for (int x = 0; x < TW; ++x) k[x] = r * factor(row[x + w] - row[x]);
            } else {
                for (int x = 0; x < TW; ++x) k[x] = r * factor(at(x, y + 1) - at(x, y));
            }
        }
    });
    double* hs = scratch_.data();
    double* cps = scratch2_.data();
    auto unsolved = [&](int y) { return (Y0 + y == 0 && f.north) || (Y0 + y == H - 1 && f.south) || W == 1; };
    carry_.assign(2 * std::size_t(TH), 0.0);  // per row: the last c' and solution value
    carry(Tiling::Toward::east, carry_, 2, [&](int first, int count) {
        parallel_for(first, first + count, 8, [&](std::int64_t y0, std::int64_t y1) {
            for (auto y = int(y0); y < int(y1); ++y) {
                const double* row = h + std::size_t(y) * w;
                double* out = hs + std::size_t(y) * w;
                double* cp = cps + std::size_t(y) * w;
                const double* k = kx_.data() + std::size_t(y) * kw + 1;  // k[x]: link (x, x+1)
                if (unsolved(y)) {
                    std::copy(row, row + w, out);
                    continue;
                }
                double prev_cp = carry_[2 * std::size_t(y)], prev = carry_[2 * std::size_t(y) + 1];
                for (int x = 0; x < TW; ++x) {
                    const int gx = X0 + x;
                    double lo = gx > 0 ? -k[x - 1] : 0.0, hi = gx + 1 < W ? -k[x] : 0.0;
                    double diag = 1.0 - lo - hi;
                    if ((gx == 0 && f.west) || (gx == W - 1 && f.east)) lo = hi = 0.0, diag = 1.0;
                    const double m = 1.0 / (diag - lo * prev_cp);
                    prev_cp = hi * m;
                    cp[x] = prev_cp;
                    prev = (row[x] - lo * prev) * m;
                    out[x] = prev;
                }
                carry_[2 * std::size_t(y)] = prev_cp, carry_[2 * std::size_t(y) + 1] = prev;
            }
        });
    });
    carry_.assign(std::size_t(TH), 0.0);
    carry(Tiling::Toward::west, carry_, 1, [&](int first, int count) {
        parallel_for(first, first + count, 8, [&](std::int64_t y0, std::int64_t y1) {
            for (auto y = int(y0); y < int(y1); ++y) {
                if (unsolved(y)) continue;
                double* out = hs + std::size_t(y) * w;
                const double* cp = cps + std::size_t(y) * w;
                if (!eastmost) out[TW - 1] -= cp[TW - 1] * carry_[std::size_t(y)];
                for (int x = TW - 2; x >= 0; --x) out[x] -= cp[x] * out[x + 1];
                carry_[std::size_t(y)] = out[0];
            }
        });
    });
    if (H == 1) {
        std::copy(hs, hs + w * std::size_t(TH), h);
        return;
    }
    carry_.assign(2 * w, 0.0);  // per column: the last c' and solution value
    carry(Tiling::Toward::south, carry_, 2, [&](int first, int count) {
        strips(first, count, [&](int x0, int x1) {
            for (int y = 0; y < TH; ++y) {
                const int gy = Y0 + y;
                const double* src = hs + std::size_t(y) * w;
                double* out = h + std::size_t(y) * w;
                double* cp = cps + std::size_t(y) * w;
                const bool fixed_row = (gy == 0 && f.north) || (gy == H - 1 && f.south);
                for (int x = x0; x < x1; ++x) {
                    double lo = gy > 0 ? -ky_[std::size_t(y) * w + std::size_t(x)] : 0.0;  // link (y − 1, y)
                    double hi = gy + 1 < H ? -ky_[std::size_t(y + 1) * w + std::size_t(x)] : 0.0;
                    double diag = 1.0 - lo - hi;
                    if (fixed_row) lo = hi = 0.0, diag = 1.0;
                    const double pcp = y > 0 ? cp[x - std::ptrdiff_t(w)] : carry_[2 * std::size_t(x)];
                    const double pd = y > 0 ? out[x - std::ptrdiff_t(w)] : carry_[2 * std::size_t(x) + 1];
                    const double m = 1.0 / (diag - lo * pcp);
                    cp[x] = hi * m;
                    out[x] = (src[x] - lo * pd) * m;
                }
            }
            for (int x = x0; x < x1; ++x) {
                carry_[2 * std::size_t(x)] = cps[std::size_t(TH - 1) * w + std::size_t(x)];
                carry_[2 * std::size_t(x) + 1] = h[std::size_t(TH - 1) * w + std::size_t(x)];
            }
        });
    });
    carry_.assign(w, 0.0);
    carry(Tiling::Toward::north, carry_, 1, [&](int first, int count) {
        strips(first, count, [&](int x0, int x1) {
            for (int y = southmost ? TH - 2 : TH - 1; y >= 0; --y) {
                double* out = h + std::size_t(y) * w;
                const double* cp = cps + std::size_t(y) * w;
                const double* next = y + 1 < TH ? out + w : carry_.data();
                for (int x = x0; x < x1; ++x) out[x] -= cp[x] * next[x];
            }
            for (int x = x0; x < x1; ++x) carry_[std::size_t(x)] = h[std::size_t(x)];  // before the fixed columns
            for (int y = 0; y < TH; ++y) {
                if (f.west && X0 + x0 == 0) h[std::size_t(y) * w] = hs[std::size_t(y) * w];
                if (f.east && eastmost && x1 == TW) h[std::size_t(y) * w + w - 1] = hs[std::size_t(y) * w + w - 1];
            }
        });
    });
}

double total(const double* heights, std::size_t count) {
    return parallel_sum(0, std::int64_t(count), 65536, [&](std::int64_t b, std::int64_t e) {
        double s = 0.0;
        for (std::int64_t i = b; i < e; ++i) s += heights[i];
        return s;
    });
}

}  // namespace orogen::solvers::diffusion
