#include "diamond_square.hpp"

#include <orogen/parallel.hpp>
#include <orogen/random.hpp>

#include <algorithm>
#include <orogen/error.hpp>
#include <vector>

namespace orogen::diamond_square {

namespace {

/// Offset in [-scale, scale) for vertex (x, y): one mix per vertex.
inline float offset(std::uint64_t row_key, int x, float scale) {
    return scale * random::symmetric_float(random::mix(row_key ^ (std::uint64_t(x) * 0xD6E8FEB86659FD93ull)));
}

inline std::uint64_t row_key(std::uint64_t seed, int y) { return random::hash(seed, std::uint64_t(y)); }

/// Midpoint of each interval [v[i], v[i+1]], or -1 if it has no interior point.
std::vector<int> midpoints(const std::vector<int>& v) {
    std::vector<int> mid(v.size() - 1, -1);
    for (std::size_t i = 0; i + 1 < v.size(); ++i)
        if (v[i + 1] - v[i] >= 2) mid[i] = (v[i] + v[i + 1]) / 2;
    return mid;
}

std::vector<int> merge(const std::vector<int>& v, const std::vector<int>& mid) {
    std::vector<int> out;
    out.reserve(v.size() * 2);
    for (std::size_t i = 0; i < v.size(); ++i) {
        out.push_back(v[i]);
        if (i < mid.size() && mid[i] >= 0) out.push_back(mid[i]);
    }
    return out;
}

}  // namespace

void generate(GridView out, const Params& params, std::uint64_t seed) {
    const int W = out.width, H = out.height;
    if (W < 1 || H < 1) return;
    const float amplitude = float(params.amplitude);
    std::vector<int> xs = {0, W - 1}, ys = {0, H - 1};
    if (W == 1) xs = {0};
    if (H == 1) ys = {0};
    for (int y : ys) {
        const std::uint64_t k = row_key(seed, y);
        for (int x : xs) out.at(x, y) = offset(k, x, amplitude);
    }

    float scale = amplitude * float(params.roughness);
    while (true) {
        const std::vector<int> mx = midpoints(xs), my = midpoints(ys);
        bool any = false;
        for (int m : mx) any = any || m >= 0;
        for (int m : my) any = any || m >= 0;
        if (!any) break;
        const int nx = int(xs.size()), ny = int(ys.size());

        // Diamond step: centres of squares split on both axes.
        parallel_for(0, ny - 1, 8, [&](std::int64_t j0, std::int64_t j1) {
            for (std::int64_t j = j0; j < j1; ++j) {
                const int cy = my[std::size_t(j)];
                if (cy < 0) continue;
                const float* top = out.row(ys[std::size_t(j)]);
                const float* bottom = out.row(ys[std::size_t(j) + 1]);
                float* centre = out.row(cy);
                const std::uint64_t k = row_key(seed, cy);
                for (int i = 0; i < nx - 1; ++i) {
                    const int cx = mx[std::size_t(i)];
                    if (cx < 0) continue;
                    const int l = xs[std::size_t(i)], r = xs[std::size_t(i) + 1];
                    centre[cx] = 0.25f * (top[l] + top[r] + bottom[l] + bottom[r]) + offset(k, cx, scale);
                }
            }
        });

        // Square step, rows of existing points: midpoints of horizontal edges.
        parallel_for(0, ny, 8, [&](std::int64_t j0, std::int64_t j1) {
            for (std::int64_t j = j0; j < j1; ++j) {
                const int y = ys[std::size_t(j)];
                float* row = out.row(y);
                const float* up = j > 0 && my[std::size_t(j) - 1] >= 0 ? out.row(my[std::size_t(j) - 1]) : nullptr;
                const float* down = j < ny - 1 && my[std::size_t(j)] >= 0 ? out.row(my[std::size_t(j)]) : nullptr;
                const std::uint64_t k = row_key(seed, y);
                for (int i = 0; i < nx - 1; ++i) {
                    const int cx = mx[std::size_t(i)];
                    if (cx < 0) continue;
                    float sum = row[xs[std::size_t(i)]] + row[xs[std::size_t(i) + 1]];
                    float n = 2.0f;
                    if (up) {
                        sum += up[cx];
                        n += 1.0f;
                    }
                    if (down) {
                        sum += down[cx];
                        n += 1.0f;
                    }
                    row[cx] = sum / n + offset(k, cx, scale);
                }
            }
        });

        // Square step, new rows: midpoints of vertical edges.
        parallel_for(0, ny - 1, 8, [&](std::int64_t j0, std::int64_t j1) {
            for (std::int64_t j = j0; j < j1; ++j) {
                const int cy = my[std::size_t(j)];
                if (cy < 0) continue;
                const float* top = out.row(ys[std::size_t(j)]);
                const float* bottom = out.row(ys[std::size_t(j) + 1]);
                float* row = out.row(cy);
                const std::uint64_t k = row_key(seed, cy);
                for (int i = 0; i < nx; ++i) {
                    const int x = xs[std::size_t(i)];
                    float sum = top[x] + bottom[x];
                    float n = 2.0f;
                    if (i > 0 && mx[std::size_t(i) - 1] >= 0) {
                        sum += row[mx[std::size_t(i) - 1]];
                        n += 1.0f;
                    }
                    if (i < nx - 1 && mx[std::size_t(i)] >= 0) {
                        sum += row[mx[std::size_t(i)]];
                        n += 1.0f;
                    }
                    row[x] = sum / n + offset(k, x, scale);
                }
            }
        });

        xs = merge(xs, mx);
        ys = merge(ys, my);
        scale *= float(params.roughness);
    }
}

namespace {

/// A window of one level's lattice (xs × ys of that level): index ranges
/// [x_lo, x_hi] into xs and [y_lo, y_hi] into ys, inclusive.
struct Window {
    int x_lo = 0, x_hi = -1, y_lo = 0, y_hi = -1;
    int width() const { return x_hi - x_lo + 1; }
    int height() const { return y_hi - y_lo + 1; }
};

/// For each i of a lattice, the index of xs[i] in merge(xs, mid) (`old`) and of mid[i] there (`mid_at`, −1 if none).
void positions(const std::vector<int>& mid, std::size_t n, std::vector<int>& old, std::vector<int>& mid_at) {
    old.assign(n, 0);
    mid_at.assign(n, -1);
    int at = 0;
    for (std::size_t i = 0; i < n; ++i) {
        old[i] = at++;
        if (i < mid.size() && mid[i] >= 0) mid_at[i] = at++;
    }
}

}  // namespace

void generate_tile(GridView out, int x0, int y0, int W, int H, const Params& params, std::uint64_t seed) {
    if (W < 1 || H < 1 || out.width < 1 || out.height < 1) return;
    if (x0 < 0 || y0 < 0 || x0 + out.width > W || y0 + out.height > H)
        throw Error("diamond_square::generate_tile: the tile lies outside the grid");
    const float amplitude = float(params.amplitude);
    // Every level's lattice, as generate() builds them (1-D, cheap).
    std::vector<std::vector<int>> X{{0, W - 1}}, Y{{0, H - 1}}, MX, MY;
    if (W == 1) X[0] = {0};
    if (H == 1) Y[0] = {0};
    while (true) {
        std::vector<int> mx = midpoints(X.back()), my = midpoints(Y.back());
        bool any = false;
        for (int m : mx) any = any || m >= 0;
        for (int m : my) any = any || m >= 0;
        if (!any) break;
        X.push_back(merge(X.back(), mx));
        Y.push_back(merge(Y.back(), my));
        MX.push_back(std::move(mx));
        MY.push_back(std::move(my));
    }
    const int levels = int(MX.size());
    // The windows each level must produce, from the finest (the tile: the last
    // lattice is every vertex) to the coarsest: the enclosing vertices of the
    // coarser lattice, and one more on each side (a square-step vertex reads
    // the diamond centres on both sides of it, which read their corners).
    std::vector<Window> win(std::size_t(levels) + 1);
    win[std::size_t(levels)] = {x0, x0 + out.width - 1, y0, y0 + out.height - 1};
    auto widen = [](const std::vector<int>& coarse, int lo_coord, int hi_coord, int& lo, int& hi) {
        const int a = int(std::upper_bound(coarse.begin(), coarse.end(), lo_coord) - coarse.begin()) - 1;
        const int b = int(std::lower_bound(coarse.begin(), coarse.end(), hi_coord) - coarse.begin());
        lo = std::max(0, a - 1);
        hi = std::min(int(coarse.size()) - 1, b + 1);
    };
    for (int L = levels - 1; L >= 0; --L) {
        const Window& f = win[std::size_t(L) + 1];
        Window& c = win[std::size_t(L)];
        widen(X[std::size_t(L)], X[std::size_t(L) + 1][std::size_t(f.x_lo)], X[std::size_t(L) + 1][std::size_t(f.x_hi)],
              c.x_lo, c.x_hi);
        widen(Y[std::size_t(L)], Y[std::size_t(L) + 1][std::size_t(f.y_lo)], Y[std::size_t(L) + 1][std::size_t(f.y_hi)],
              c.y_lo, c.y_hi);
    }
    // Level 0: the corners in the window.
    std::vector<float> v(std::size_t(win[0].width()) * std::size_t(win[0].height()));
    for (int j = win[0].y_lo; j <= win[0].y_hi; ++j) {
        const std::uint64_t k = row_key(seed, Y[0][std::size_t(j)]);
        for (int i = win[0].x_lo; i <= win[0].x_hi; ++i)
            v[std::size_t(j - win[0].y_lo) * std::size_t(win[0].width()) + std::size_t(i - win[0].x_lo)] =
                offset(k, X[0][std::size_t(i)], amplitude);
    }
    float scale = amplitude * float(params.roughness);
    std::vector<int> ox, mxa, oy, mya;
    std::vector<float> span;
    for (int L = 0; L < levels; ++L) {
        const std::vector<int>&xs = X[std::size_t(L)], &ys = Y[std::size_t(L)], &mx = MX[std::size_t(L)],
              &my = MY[std::size_t(L)];
        const int nx = int(xs.size()), ny = int(ys.size());
        const Window w = win[std::size_t(L)], next = win[std::size_t(L) + 1];
        positions(mx, xs.size(), ox, mxa);
        positions(my, ys.size(), oy, mya);
        // The finer lattice's span over this window (indices of the finer lattice).
        const int sx0 = ox[std::size_t(w.x_lo)], sy0 = oy[std::size_t(w.y_lo)];
        const int sw = ox[std::size_t(w.x_hi)] - sx0 + 1, sh = oy[std::size_t(w.y_hi)] - sy0 + 1;
        span.assign(std::size_t(sw) * std::size_t(sh), 0.0f);
        auto S = [&](int fy, int fx) -> float& {
            return span[std::size_t(fy - sy0) * std::size_t(sw) + std::size_t(fx - sx0)];
        };
        auto V = [&](int j, int i) {
            return v[std::size_t(j - w.y_lo) * std::size_t(w.width()) + std::size_t(i - w.x_lo)];
        };
        // Whether a vertex of the finer lattice lies in the window the next level needs.
        auto wanted = [&](int fy, int fx) {
            return fx >= next.x_lo && fx <= next.x_hi && fy >= next.y_lo && fy <= next.y_hi;
        };
        for (int j = w.y_lo; j <= w.y_hi; ++j)
            for (int i = w.x_lo; i <= w.x_hi; ++i) S(oy[std::size_t(j)], ox[std::size_t(i)]) = V(j, i);
        // Diamond step: every centre of the window (the square steps below read them), as generate() computes it.
        for (int j = w.y_lo; j < w.y_hi; ++j) {
            const int cy = my[std::size_t(j)];
            if (cy < 0) continue;
            const std::uint64_t k = row_key(seed, cy);
            for (int i = w.x_lo; i < w.x_hi; ++i) {
                const int cx = mx[std::size_t(i)];
                if (cx < 0) continue;
                S(mya[std::size_t(j)], mxa[std::size_t(i)]) =
                    0.25f * (V(j, i) + V(j, i + 1) + V(j + 1, i) + V(j + 1, i + 1)) + offset(k, cx, scale);
            }
        }
        // A square-step vertex the next level needs must find its centres in the window.
        auto need = [&](bool ok) {
            if (!ok) throw Error("internal error: diamond_square::generate_tile: a window is too small");
        };
        // Square step, rows of existing points: midpoints of horizontal edges.
        for (int j = w.y_lo; j <= w.y_hi; ++j) {
            const std::uint64_t k = row_key(seed, ys[std::size_t(j)]);
            for (int i = w.x_lo; i < w.x_hi; ++i) {
                const int cx = mx[std::size_t(i)];
                if (cx < 0 || !wanted(oy[std::size_t(j)], mxa[std::size_t(i)])) continue;
                float sum = V(j, i) + V(j, i + 1);
                float n = 2.0f;
                if (j > 0 && my[std::size_t(j) - 1] >= 0) {
                    need(j - 1 >= w.y_lo);
                    sum += S(mya[std::size_t(j) - 1], mxa[std::size_t(i)]);
                    n += 1.0f;
                }
                if (j < ny - 1 && my[std::size_t(j)] >= 0) {
                    need(j + 1 <= w.y_hi);
                    sum += S(mya[std::size_t(j)], mxa[std::size_t(i)]);
                    n += 1.0f;
                }
                S(oy[std::size_t(j)], mxa[std::size_t(i)]) = sum / n + offset(k, cx, scale);
            }
        }
        // Square step, new rows: midpoints of vertical edges.
        for (int j = w.y_lo; j < w.y_hi; ++j) {
            const int cy = my[std::size_t(j)];
            if (cy < 0) continue;
            const std::uint64_t k = row_key(seed, cy);
            for (int i = w.x_lo; i <= w.x_hi; ++i) {
                if (!wanted(mya[std::size_t(j)], ox[std::size_t(i)])) continue;
                const int x = xs[std::size_t(i)];
                float sum = V(j, i) + V(j + 1, i);
                float n = 2.0f;
                if (i > 0 && mx[std::size_t(i) - 1] >= 0) {
                    need(i - 1 >= w.x_lo);
                    sum += S(mya[std::size_t(j)], mxa[std::size_t(i) - 1]);
                    n += 1.0f;
                }
                if (i < nx - 1 && mx[std::size_t(i)] >= 0) {
                    need(i + 1 <= w.x_hi);
                    sum += S(mya[std::size_t(j)], mxa[std::size_t(i)]);
                    n += 1.0f;
                }
                S(mya[std::size_t(j)], ox[std::size_t(i)]) = sum / n + offset(k, x, scale);
            }
        }
        // Keep what the next level needs.
        v.assign(std::size_t(next.width()) * std::size_t(next.height()), 0.0f);
        for (int fy = next.y_lo; fy <= next.y_hi; ++fy)
            for (int fx = next.x_lo; fx <= next.x_hi; ++fx)
                v[std::size_t(fy - next.y_lo) * std::size_t(next.width()) + std::size_t(fx - next.x_lo)] = S(fy, fx);
        scale *= float(params.roughness);
    }
    // The finest lattice is every vertex: the window is the tile.
    for (int y = 0; y < out.height; ++y)
        std::copy(v.begin() + std::ptrdiff_t(std::size_t(y) * std::size_t(out.width)),
                  v.begin() + std::ptrdiff_t(std::size_t(y + 1) * std::size_t(out.width)), out.row(y));
}

}  // namespace orogen::diamond_square
