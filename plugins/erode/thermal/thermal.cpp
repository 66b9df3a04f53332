#include "thermal.hpp"

#include <orogen/error.hpp>
#include <orogen/parallel.hpp>

#if defined(__x86_64__) || defined(__SSE__)
#include <xmmintrin.h>
#endif

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

// The row loops are built for plain x86-64 and for AVX2, picked at run time.
// Both compute every lane with the same operations in the same order (and no
// FMA contraction, see CMakeLists.txt), so the results are bit-identical.
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

/// Flush denormals to zero inside a parallel body (restored on exit). Water
/// evaporating and sediment thinning out decay towards 1e-38 and below,
/// where every float operation costs ~100 cycles. Set on every thread for
/// every row, so results are the same whatever the thread count.
struct FlushDenormals {
#if defined(__x86_64__) || defined(__SSE__)
    unsigned saved = _mm_getcsr();
    FlushDenormals() { _mm_setcsr(saved | 0x8040u); }  // FTZ | DAZ
    ~FlushDenormals() { _mm_setcsr(saved); }
#endif
};

struct Offset {
    int dx, dy;
    bool diagonal;
};

constexpr Offset kVonNeumann[] = {{1, 0, false}, {-1, 0, false}, {0, 1, false}, {0, -1, false}};
constexpr Offset kRotated[] = {{1, 1, true}, {-1, 1, true}, {1, -1, true}, {-1, -1, true}};
constexpr Offset kMoore[] = {{1, 0, false}, {-1, 0, false}, {0, 1, false}, {0, -1, false},
                             {1, 1, true},  {-1, 1, true},  {1, -1, true},  {-1, -1, true}};

template <Neighbourhood N>
constexpr auto& offsets() {
    if constexpr (N == Neighbourhood::von_neumann) return kVonNeumann;
    else if constexpr (N == Neighbourhood::rotated) return kRotated;
    else return kMoore;
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

/// Softness (0..1) of the cell at index i with height h: scales what it gives.
inline float softness(const Rule& r, float h, std::size_t i) {
    switch (r.hardness) {
        case Hardness::constant: return 1.0f;
        case Hardness::height: return 1.0f - height_hardness(h, r.h_min, r.h_max);
        case Hardness::layer: {
            const float k = r.hardness_layer[i];
            return 1.0f - (k < 0.0f ? 0.0f : (k > 1.0f ? 1.0f : k));
        }
    }
    return 1.0f;
}

/// F for cell (x, y) with bounds checks (edge cells); its outflow into `out`.
template <Neighbourhood N>
float factor_checked(ConstGridView in, const Rule& r, int x, int y, float& out) {
    const float h = in.at(x, y);
    float excess = 0.0f, sum = 0.0f;
    for (const Offset& o : offsets<N>()) {
        const int nx = x + o.dx, ny = y + o.dy;
        if (nx < 0 || ny < 0 || nx >= in.width || ny >= in.height) continue;
        const float t = r.threshold(o.diagonal);
        const float d = h - in.at(nx, ny);
        excess = std::max(excess, d - t);
        sum += d > t ? d : 0.0f;
    }
    out = r.rate * softness(r, h, std::size_t(y) * std::size_t(in.width) + std::size_t(x)) * excess;
    return out / std::max(sum, 1e-30f);
}

/// Softness of interior cells, with the hardness mode fixed at compile time
/// so the row loops vectorise.
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

/// F and the outflow O = rate·softness·max(0, excess) (metres) for every
/// cell of row y into f[0..width) and o[0..width). A cell's outflow is
/// Σ_i F·d_i over its lower neighbours = F·Σ d_i = O, so the update needs
/// only O, not one product per neighbour.
template <Neighbourhood N, Hardness H>
OROGEN_THERMAL_CLONES void factor_row(ConstGridView in, const Rule& r, int y, float* __restrict f,
                                      float* __restrict o) {
    const int w = in.width;
    if (y == 0 || y == in.height - 1 || w < 3) {
        for (int x = 0; x < w; ++x) f[x] = factor_checked<N>(in, r, x, y, o[x]);
        return;
    }
    f[0] = factor_checked<N>(in, r, 0, y, o[0]);
    f[w - 1] = factor_checked<N>(in, r, w - 1, y, o[w - 1]);
    constexpr auto& offs = offsets<N>();
    constexpr int K = int(std::size(offs));
    const float* __restrict nb[K];
    float t[K];
    for (int k = 0; k < K; ++k) {
        nb[k] = in.row(y + offs[k].dy) + offs[k].dx;
        t[k] = r.threshold(offs[k].diagonal);
    }
    const float* __restrict c = in.row(y);
    const float* layer = r.hardness_layer ? r.hardness_layer + std::size_t(y) * std::size_t(w) : nullptr;
    const float rate = r.rate;
    // The destination rows never overlap the sources: no alias checks needed.
    // The largest drop per threshold class (axis, diagonal), minus its
    // threshold once: rounding is monotone, so max_k(d_k − t) = max_k(d_k) − t
    // bit for bit, and this saves one subtraction per neighbour.
    const float t_axis = r.t_axis, t_diag = r.t_diag;
#pragma GCC ivdep
    for (int x = 1; x < w - 1; ++x) {
        const float h = c[x];
        float max_axis = -INFINITY, max_diag = -INFINITY, sum = 0.0f;
#pragma GCC unroll 8
        for (int k = 0; k < K; ++k) {
            const float d = h - nb[k][x];
            if (offs[k].diagonal) max_diag = std::max(max_diag, d);
            else max_axis = std::max(max_axis, d);
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

/// New height of cell (x, y) with bounds checks. frow(dy) gives F of row
/// y+dy, `out` is the cell's own outflow.
template <Neighbourhood N, typename FRow>
float update_checked(ConstGridView in, const Rule& r, int x, int y, const FRow& frow, float out) {
    const float h = in.at(x, y);
    float gain = 0.0f;
    for (const Offset& o : offsets<N>()) {
        const int nx = x + o.dx, ny = y + o.dy;
        if (nx < 0 || ny < 0 || nx >= in.width || ny >= in.height) continue;
        const float t = r.threshold(o.diagonal);
        const float e = in.at(nx, ny) - h;  // drop from the neighbour
        gain += e > t ? frow(o.dy)[nx] * e : 0.0f;
    }
    return (h - out) + gain;
}

template <Neighbourhood N>
OROGEN_THERMAL_CLONES void update_row(ConstGridView in, GridView outv, const Rule& r, int y, const float* const f[3],
                                      const float* __restrict o) {
    const int w = in.width;
    float* __restrict dst = outv.row(y);
    auto frow = [&](int dy) { return f[1 + dy]; };
    if (y == 0 || y == in.height - 1 || w < 3) {
        for (int x = 0; x < w; ++x) dst[x] = update_checked<N>(in, r, x, y, frow, o[x]);
        return;
    }
    dst[0] = update_checked<N>(in, r, 0, y, frow, o[0]);
    dst[w - 1] = update_checked<N>(in, r, w - 1, y, frow, o[w - 1]);
    constexpr auto& offs = offsets<N>();
    constexpr int K = int(std::size(offs));
    const float* __restrict nb[K];
    const float* __restrict nf[K];
    float t[K];
    for (int k = 0; k < K; ++k) {
        nb[k] = in.row(y + offs[k].dy) + offs[k].dx;
        nf[k] = f[1 + offs[k].dy] + offs[k].dx;
        t[k] = r.threshold(offs[k].diagonal);
    }
    const float* __restrict c = in.row(y);
    // The destination row never overlaps the sources: no alias checks needed.
#pragma GCC ivdep
    for (int x = 1; x < w - 1; ++x) {
        const float h = c[x];
        float gain = 0.0f;
#pragma GCC unroll 8
        for (int k = 0; k < K; ++k) {
            const float e = nb[k][x] - h;  // drop from the neighbour
            const float fn = nf[k][x];     // loaded unconditionally so the loop vectorises
            gain += e > t[k] ? fn * e : 0.0f;
        }
        dst[x] = (h - o[x]) + gain;
    }
}

template <Neighbourhood N, Hardness H>
void step_impl(ConstGridView in, GridView out, const Rule& r) {
    const int w = in.width, h = in.height;
    // Rows in parallel. Each chunk recomputes F for its one-row halo; F of a
    // row is the same pure function of `in` wherever it is computed, so the
    // result does not depend on the chunking.
    const std::int64_t grain = std::max<std::int64_t>(16, h / 32);
    parallel_for(0, h, grain, [&](std::int64_t y0, std::int64_t y1) {
        FlushDenormals ftz;
        // Ring of 3 rows of F, and of the outflow O.
        std::vector<float> ring(std::size_t(w) * 6);
        auto slot = [&](std::int64_t y) { return ring.data() + std::size_t(((y % 3) + 3) % 3) * std::size_t(w); };
        auto oslot = [&](std::int64_t y) { return slot(y) + 3 * std::size_t(w); };
        if (y0 > 0) factor_row<N, H>(in, r, int(y0 - 1), slot(y0 - 1), oslot(y0 - 1));
        factor_row<N, H>(in, r, int(y0), slot(y0), oslot(y0));
        for (std::int64_t y = y0; y < y1; ++y) {
            if (y + 1 < h) factor_row<N, H>(in, r, int(y + 1), slot(y + 1), oslot(y + 1));
            // Rows outside the grid are never read (update_* checks bounds there).
            const float* f[3] = {slot(y - 1), slot(y), slot(y + 1)};
            update_row<N>(in, out, r, int(y), f, oslot(y));
        }
    });
}

}  // namespace

void step(ConstGridView in, GridView out, const Settings& settings, const float* hardness) {
    if (in.width != out.width || in.height != out.height)
        throw Error("thermal::step: input and output grids differ in size");
    if (settings.hardness == Hardness::layer && hardness == nullptr)
        throw Error("thermal::step: hardness layer mode needs a hardness layer");
    Rule r = make_rule(settings, in.cell);
    r.hardness_layer = hardness;
    auto with_hardness = [&]<Neighbourhood N>() {
        switch (settings.hardness) {
            case Hardness::constant: step_impl<N, Hardness::constant>(in, out, r); break;
            case Hardness::height: step_impl<N, Hardness::height>(in, out, r); break;
            case Hardness::layer: step_impl<N, Hardness::layer>(in, out, r); break;
        }
    };
    switch (settings.neighbourhood) {
        case Neighbourhood::von_neumann: with_hardness.template operator()<Neighbourhood::von_neumann>(); break;
        case Neighbourhood::rotated: with_hardness.template operator()<Neighbourhood::rotated>(); break;
        case Neighbourhood::moore: with_hardness.template operator()<Neighbourhood::moore>(); break;
    }
}

void erode(GridView heights, std::int64_t iterations, const Settings& settings, const float* hardness,
           const std::function<void(std::int64_t, ConstGridView)>& on_step) {
    if (iterations <= 0) return;
    std::vector<float> scratch(heights.size());
    GridView a = heights;
    GridView b{scratch.data(), heights.width, heights.height, heights.cell};
    for (std::int64_t i = 1; i <= iterations; ++i) {
        step(a, b, settings, hardness);
        std::swap(a, b);
        if (on_step) on_step(i, a);
    }
    if (a.data != heights.data) std::memcpy(heights.data, a.data, heights.size() * sizeof(float));
}

}  // namespace orogen::thermal
