#include "thermal.hpp"

#include <orogen/error.hpp>
#include <orogen/parallel.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

// The row loops are built for plain x86-64, AVX2 and AVX-512, picked at run
// time. All compute every lane with the same operations in the same order
// (and no FMA contraction, see CMakeLists.txt), so the results are
// bit-identical. (Fused multiply-adds for the gains were measured: no faster
// here, and the plain x86-64 clone would have to call fmaf.)
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define OROGEN_THERMAL_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define OROGEN_THERMAL_CLONES
#endif

namespace orogen::thermal {

Neighbourhood parse_neighbourhood(std::string_view name) {
    if (name == "von-neumann") return Neighbourhood::von_neumann;
    if (name == "rotated") return Neighbourhood::rotated;
    if (name == "moore") return Neighbourhood::moore;
    throw BadInput("unknown neighbourhood '" + std::string(name) + "': use von-neumann, rotated or moore");
}

namespace {

struct Offset {
    int dx, dy;
    bool diagonal;
};

constexpr Offset kVonNeumann[] = {{1, 0, false}, {-1, 0, false}, {0, 1, false}, {0, -1, false}};
constexpr Offset kRotated[] = {{1, 1, true}, {-1, 1, true}, {1, -1, true}, {-1, -1, true}};
constexpr Offset kMoore[] = {{1, 0, false}, {-1, 0, false}, {0, 1, false}, {0, -1, false},
                             {1, 1, true},  {-1, 1, true},  {1, -1, true}, {-1, -1, true}};

template <Neighbourhood N>
constexpr auto& offsets() {
    if constexpr (N == Neighbourhood::von_neumann) return kVonNeumann;
    else if constexpr (N == Neighbourhood::rotated) return kRotated;
    else return kMoore;
}

/// Index of the first diagonal (or axis) neighbour in offsets<N>(), −1 if none.
template <Neighbourhood N>
constexpr int first_of(bool diagonal) {
    for (int k = 0; k < int(std::size(offsets<N>())); ++k)
        if (offsets<N>()[k].diagonal == diagonal) return k;
    return -1;
}

/// Per-step constants shared by every row.
struct Rule {
    float t_axis = 0.0f;  ///< threshold to an axis neighbour, metres
    float t_diag = 0.0f;  ///< threshold to a diagonal neighbour, metres
    float rate = 0.5f;
    Hardness hardness = Hardness::constant;
    float h_min = 0.0f, h_max = 1.0f;
    const float* hardness_layer = nullptr;

    float threshold(bool diagonal) const { return diagonal ? t_diag : t_axis; }
};

Rule make_rule(const Settings& s, double cell) {
    Rule r;
    if (s.talus_height >= 0.0) {
        r.t_axis = r.t_diag = float(s.talus_height);
    } else {
        r.t_axis = float(s.talus_slope * cell);
        r.t_diag = float(s.talus_slope * cell * std::sqrt(2.0));
    }
    r.rate = float(s.rate);
    r.hardness = s.hardness;
    r.h_min = s.height_min;
    r.h_max = s.height_max;
    return r;
}

/// Softness of a cell with the hardness mode fixed at compile time (so the
/// row loops vectorise); `layer` is the cell's row of the hardness layer.
template <Hardness H>
inline float softness_fast(const Rule& r, float h, const float* layer, int x) {
    if constexpr (H == Hardness::constant) {
        return 1.0f;
    } else if constexpr (H == Hardness::height) {
        const float inv = r.h_max > r.h_min ? 1.0f / (r.h_max - r.h_min) : 0.0f;
        float t = (r.h_max - h) * inv;
        t = std::min(std::max(t, 0.0f), 1.0f);
        return r.h_max > r.h_min ? t * t : 1.0f;
    } else {
        const float k = std::min(std::max(layer[x], 0.0f), 1.0f);
        return 1.0f - k;
    }
}

/// Height of the wall around the grid (metres): every local row of heights
/// has a wall column at −1 and at `width`, and a row outside the grid is all
/// wall, with F = 0 in the matching columns and rows of F. A wall cell is
/// never lower than a neighbour (its drop, h − 1e30 = −1e30, is below every
/// threshold and every real drop) and gives F·e = 0 to it, so the edge cells
/// run through the same loops as the others, with the same bits as if their
/// missing neighbours were skipped.
constexpr float kWall = 1e30f;

/// Rows y−1, y, y+1 of one height field around row y (see kWall).
struct Rows3 {
    const float* row[3];
    int width;
};

/// F and the outflow O = rate·softness·max(0, excess) (metres) for every
/// cell of the row `in` is centred on, into f[0..width) and o[0..width). A
/// cell's outflow is Σ_i F·d_i over its lower neighbours = F·Σ d_i = O, so
/// the update needs only O, not one product per neighbour. `layer` is the
/// row of the hardness layer (Hardness::layer only).
template <Neighbourhood N, Hardness H>
OROGEN_THERMAL_CLONES void factor_row(const Rows3& in, const Rule& r, const float* layer, float* __restrict f,
                                      float* __restrict o) {
    constexpr auto& offs = offsets<N>();
    constexpr int K = int(std::size(offs));
    const float* __restrict nb[K];
    float t[K];
    for (int k = 0; k < K; ++k) {
        nb[k] = in.row[1 + offs[k].dy] + offs[k].dx;
        t[k] = r.threshold(offs[k].diagonal);
    }
    const float* __restrict c = in.row[1];
    const float rate = r.rate;
    // The largest drop per threshold class (axis, diagonal), minus its
    // threshold once: rounding is monotone, so max_k(d_k − t) = max_k(d_k) − t
    // bit for bit, and this saves one subtraction per neighbour.
    const float t_axis = r.t_axis, t_diag = r.t_diag;
    const int w = in.width;
    // The destination rows never overlap the sources: no alias checks needed.
#pragma GCC ivdep
    for (int x = 0; x < w; ++x) {
        const float h = c[x];
        // Every neighbour is a number (see kWall), so each maximum starts
        // from its class's first drop instead of −∞ (two operations less).
        float max_axis = 0.0f, max_diag = 0.0f, sum = 0.0f;
#pragma GCC unroll 8
        for (int k = 0; k < K; ++k) {
            const float d = h - nb[k][x];
            if (offs[k].diagonal) max_diag = k == first_of<N>(true) ? d : std::max(max_diag, d);
            else max_axis = k == first_of<N>(false) ? d : std::max(max_axis, d);
            sum = d > t[k] ? sum + d : sum;  // the same bits as sum + (d > t ? d : 0): sum ≥ +0
        }
        float excess = 0.0f;
        if constexpr (N != Neighbourhood::rotated) excess = std::max(excess, max_axis - t_axis);
        if constexpr (N != Neighbourhood::von_neumann) excess = std::max(excess, max_diag - t_diag);
        const float soft = softness_fast<H>(r, h, layer, x);
        const float out = rate * soft * excess;  // excess ≥ 0: 0 when nothing is above the threshold
        f[x] = out / std::max(sum, 1e-30f);
        o[x] = out;
    }
}

/// The next step of the row `in` is centred on, into dst[0..width), from F
/// of the rows above, at and below (f) and the row's own outflow (o).
template <Neighbourhood N>
OROGEN_THERMAL_CLONES void update_row(const Rows3& in, const Rule& r, const float* const f[3],
                                      const float* __restrict o, float* __restrict dst) {
    constexpr auto& offs = offsets<N>();
    constexpr int K = int(std::size(offs));
    const float* __restrict nb[K];
    const float* __restrict nf[K];
    float t[K];
    for (int k = 0; k < K; ++k) {
        nb[k] = in.row[1 + offs[k].dy] + offs[k].dx;
        nf[k] = f[1 + offs[k].dy] + offs[k].dx;
        t[k] = r.threshold(offs[k].diagonal);
    }
    const float* __restrict c = in.row[1];
    const int w = in.width;
    // The destination row never overlaps the sources: no alias checks needed.
#pragma GCC ivdep
    for (int x = 0; x < w; ++x) {
        const float h = c[x];
        float gain = 0.0f;
#pragma GCC unroll 8
        for (int k = 0; k < K; ++k) {
            const float e = nb[k][x] - h;  // drop from the neighbour (from a wall: its F is 0)
            const float fn = nf[k][x];  // loaded unconditionally so the loop vectorises
            gain += e > t[k] ? fn * e : 0.0f;
        }
        dst[x] = (h - o[x]) + gain;
    }
}

/// Most steps done in one sweep over the grid (temporal blocking).
constexpr int kMaxStepsPerSweep = kStepsPerSweep;

/// `steps` (1..kMaxStepsPerSweep) steps from `in` to `out` in one sweep.
///
/// Row y of step s+1 depends on rows y−2..y+2 of step s (the gain from a
/// neighbour uses its F, which looks one row further). Each band of output
/// rows [y0, y1) is computed as a pipeline: step s keeps a ring of 4 rows of
/// heights (step 0: copies of the input rows) and 3 rows of F and O, and
/// produces its rows on demand from step s−1 (rows
/// [y0 − 2(steps−s), y1 + 2(steps−s)), recomputed by both neighbouring
/// bands). So the grid is read and written once per `steps` steps, and the
/// intermediate rows stay in L1/L2. Every row of every step is the same pure
/// function of the previous step as in a single step, with the same
/// operations in the same order: the result is bit-identical to `steps`
/// single steps, whatever the bands or the thread count.
template <Neighbourhood N, Hardness H>
void sweep(ConstGridView in, GridView out, const Rule& r, int steps) {
    const int w = in.width, hgt = in.height;
    // Bands of rows: for one step 32 (its halo is one row of F); for several
    // two per thread, so that the recomputed halos (2·steps·(steps−1) rows
    // of heights per band) cost little. The result does not depend on them.
    const std::int64_t per_thread_bands = 2 * std::int64_t(std::max(1, thread_count()));
    const std::int64_t band =
        std::max<std::int64_t>(16, steps == 1 ? hgt / 32 : (hgt + per_thread_bands - 1) / per_thread_bands);
    const std::int64_t bands = (hgt + band - 1) / band;
    // Local rows: column 0 on a 64-byte boundary (the loops' centre loads and
    // stores are whole cache lines), a wall column on each side, and not a
    // multiple of 1 KiB apart (which would put them all in the same cache sets).
    std::size_t stride = (std::size_t(w) + 17 + 15) & ~std::size_t(15);
    if (stride % 256 == 0) stride += 16;
    const std::size_t height_rows = std::size_t(steps) * 4, rows = height_rows + std::size_t(steps) * 6 + 2;
    // In place (`in` and `out` the same grid): a band overwrites its output
    // row y only after it has copied in input rows up to y + 2·steps, so its
    // own rows are safe; but the 2·steps rows on each side of a boundary
    // between bands are also read by the band across it, which may already
    // have overwritten them: those come from a copy taken before the sweep.
    const bool in_place = in.data == out.data;
    const int halo = 2 * steps;
    const std::size_t edge_rows = std::size_t(2 * halo);  // per boundary: rows [yb − halo, yb + halo)
    std::vector<float> edges(in_place ? std::size_t(bands - 1) * edge_rows * std::size_t(w) : 0);
    if (in_place)
        parallel_for(0, bands - 1, 1, [&](std::int64_t b0, std::int64_t b1) {
            for (std::int64_t b = b0; b < b1; ++b)
                for (std::size_t i = 0; i < edge_rows; ++i) {
                    const std::int64_t y = (b + 1) * band - halo + std::int64_t(i);
                    if (y < hgt)
                        std::memcpy(edges.data() + (std::size_t(b) * edge_rows + i) * std::size_t(w), in.row(int(y)),
                                    std::size_t(w) * sizeof(float));
                }
        });
    // Input row y for the band [y0, y1) with index b.
    auto input_row = [&](std::int64_t b, int y0, int y1, int y) -> const float* {
        if (!in_place || (y >= y0 && y < y1)) return in.row(y);
        const std::int64_t boundary = y < y0 ? b - 1 : b;
        const std::int64_t first = (boundary + 1) * band - halo;
        return edges.data() + (std::size_t(boundary) * edge_rows + std::size_t(y - first)) * std::size_t(w);
    };
    parallel_for(0, bands, 1, [&](std::int64_t b0, std::int64_t b1) {
        FlushDenormals ftz;
        thread_local std::vector<float> store;
        store.resize(stride * rows + 16);
        float* const base =
            reinterpret_cast<float*>((reinterpret_cast<std::uintptr_t>(store.data()) + 63) & ~std::uintptr_t(63));
        auto slot = [&](std::size_t i) { return base + stride * i + 16; };  // column 0 of local row i
        // Rows outside the grid: heights (wall) and F (0).
        float* const wall_row = slot(rows - 2);
        float* const zero_row = slot(rows - 1);
        std::fill(wall_row - 1, wall_row + w + 1, kWall);
        std::fill(zero_row - 1, zero_row + w + 1, 0.0f);
        for (std::size_t i = 0; i < height_rows; ++i) slot(i)[-1] = slot(i)[w] = kWall;
        for (std::size_t i = height_rows; i < rows - 2; ++i) slot(i)[-1] = slot(i)[w] = 0.0f;
        // Heights of step s (0 ≤ s < steps), F and O of step s, row y.
        auto hrow = [&](int s, int y) { return slot(std::size_t(s * 4 + (y & 3))); };
        auto frow = [&](int s, int y) { return slot(height_rows + std::size_t(s * 6 + y % 3)); };
        auto orow = [&](int s, int y) { return slot(height_rows + std::size_t(s * 6 + 3 + y % 3)); };
        auto rows3 = [&](int s, int y) {
            Rows3 rs{{wall_row, wall_row, wall_row}, w};
            for (int dy = -1; dy <= 1; ++dy)
                if (y + dy >= 0 && y + dy < hgt) rs.row[1 + dy] = hrow(s, y + dy);
            return rs;
        };
        for (std::int64_t b = b0; b < b1; ++b) {
            const int y0 = int(b * band), y1 = int(std::min<std::int64_t>(hgt, (b + 1) * band));
            int next_h[kMaxStepsPerSweep + 1];  // next row of heights to produce, per step
            int next_f[kMaxStepsPerSweep + 1];  // next row of F/O to compute, per step
            for (int s = 0; s <= steps; ++s) {
                next_h[s] = std::max(0, y0 - 2 * (steps - s));
                next_f[s] = std::max(0, y0 - 2 * (steps - s - 1) - 1);
            }
            // Demand-driven: producing heights of step s, row y, first makes
            // sure F of step s−1 exists up to row y+1, which makes sure the
            // heights of step s−1 exist up to row y+2.
            auto ensure_f = [&](auto& self_h, int s, int upto) -> void {
                upto = std::min(upto, hgt - 1);
                for (; next_f[s] <= upto; ++next_f[s]) {
                    const int y = next_f[s];
                    self_h(self_h, s, std::min(y + 1, hgt - 1));
                    const float* layer =
                        r.hardness_layer ? r.hardness_layer + std::size_t(y) * std::size_t(w) : nullptr;
                    factor_row<N, H>(rows3(s, y), r, layer, frow(s, y), orow(s, y));
                }
            };
            auto ensure_h = [&](auto& self, int s, int upto) -> void {
                for (; next_h[s] <= upto; ++next_h[s]) {
                    const int y = next_h[s];
                    if (s == 0) {
                        std::memcpy(hrow(0, y), input_row(b, y0, y1, y), std::size_t(w) * sizeof(float));
                        continue;
                    }
                    ensure_f(self, s - 1, y + 1);
                    const float* f[3] = {y > 0 ? frow(s - 1, y - 1) : zero_row, frow(s - 1, y),
                                         y + 1 < hgt ? frow(s - 1, y + 1) : zero_row};
                    update_row<N>(rows3(s - 1, y), r, f, orow(s - 1, y), s == steps ? out.row(y) : hrow(s, y));
                }
            };
            ensure_h(ensure_h, steps, y1 - 1);
        }
    });
}

/// `steps` (1..kMaxStepsPerSweep) steps from `in` to `out`: the same grid, or grids that do not overlap.
void steps_into(ConstGridView in, GridView out, const Settings& settings, const float* hardness, int steps) {
    Rule r = make_rule(settings, in.cell);
    r.hardness_layer = hardness;
    auto with_hardness = [&]<Neighbourhood N>() {
        switch (settings.hardness) {
            case Hardness::constant: sweep<N, Hardness::constant>(in, out, r, steps); break;
            case Hardness::height: sweep<N, Hardness::height>(in, out, r, steps); break;
            case Hardness::layer: sweep<N, Hardness::layer>(in, out, r, steps); break;
        }
    };
    switch (settings.neighbourhood) {
        case Neighbourhood::von_neumann: with_hardness.template operator()<Neighbourhood::von_neumann>(); break;
        case Neighbourhood::rotated: with_hardness.template operator()<Neighbourhood::rotated>(); break;
        case Neighbourhood::moore: with_hardness.template operator()<Neighbourhood::moore>(); break;
    }
}

}  // namespace

void step(ConstGridView in, GridView out, const Settings& settings, const float* hardness) {
    if (in.width != out.width || in.height != out.height)
        throw Error("thermal::step: input and output grids differ in size");
    if (settings.hardness == Hardness::layer && hardness == nullptr)
        throw Error("thermal::step: hardness layer mode needs a hardness layer");
    steps_into(in, out, settings, hardness, 1);
}

void steps(ConstGridView in, GridView out, int count, const Settings& settings, const float* hardness) {
    if (in.width != out.width || in.height != out.height)
        throw Error("thermal::steps: input and output grids differ in size");
    if (count < 1 || count > kStepsPerSweep)
        throw Error("thermal::steps: count must be 1.." + std::to_string(kStepsPerSweep));
    if (settings.hardness == Hardness::layer && hardness == nullptr)
        throw Error("thermal::steps: hardness layer mode needs a hardness layer");
    steps_into(in, out, settings, hardness, count);
}

void erode(GridView heights, std::int64_t iterations, const Settings& settings, const float* hardness,
           const std::function<void(std::int64_t, ConstGridView)>& on_step) {
    if (iterations <= 0) return;
    if (settings.hardness == Hardness::layer && hardness == nullptr)
        throw Error("thermal::erode: hardness layer mode needs a hardness layer");
    // In place, kStepsPerSweep steps per sweep: each row is read from and
    // written to memory once per sweep instead of once per step, and no
    // second buffer is needed (its page faults would cost more than a step
    // at 4097²).
    for (std::int64_t i = 0; i < iterations;) {
        const int k = int(std::min<std::int64_t>(kStepsPerSweep, iterations - i));
        steps_into(heights, heights, settings, hardness, k);
        i += k;
        if (on_step) on_step(i, heights);
    }
}

}  // namespace orogen::thermal
