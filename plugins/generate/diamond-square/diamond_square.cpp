#include "diamond_square.hpp"

#include <orogen/parallel.hpp>
#include <orogen/random.hpp>

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
                    if (up) { sum += up[cx]; n += 1.0f; }
                    if (down) { sum += down[cx]; n += 1.0f; }
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
                    if (i > 0 && mx[std::size_t(i) - 1] >= 0) { sum += row[mx[std::size_t(i) - 1]]; n += 1.0f; }
                    if (i < nx - 1 && mx[std::size_t(i)] >= 0) { sum += row[mx[std::size_t(i)]]; n += 1.0f; }
                    row[x] = sum / n + offset(k, x, scale);
                }
            }
        });

        xs = merge(xs, mx);
        ys = merge(ys, my);
        scale *= float(params.roughness);
    }
}

}  // namespace orogen::diamond_square
