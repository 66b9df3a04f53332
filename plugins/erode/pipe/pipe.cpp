#include "pipe.hpp"

#include <orogen/error.hpp>
#include <orogen/parallel.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <cstring>
#include <ctime>
#include <sstream>
#include <utility>

// Row loops built for plain x86-64 and for AVX2, chosen at run time; the same
// operations per lane in the same order (no FMA contraction), so the same bits.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define OROGEN_PIPE_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define OROGEN_PIPE_CLONES
#endif

namespace orogen::pipe {
namespace {

/// Constants of one sub-step, in float for the row loops.
struct Sub {
    float dt;  ///< s
    float rain_dt;  ///< m of rain this sub-step (before the mask)
    float flux_gain;  ///< dt·g·A/l: m³/s of flux per metre of surface drop
    float area;  ///< l², m²
    float inv_area;  ///< 1/l²
    float l, inv_l;  ///< cell size, m
    float capacity, min_slope;
    float take, drop;  ///< 1 − e^(−Ks·dt), 1 − e^(−Kd·dt)
    float keep;  ///< e^(−Ke·dt)
    float speed_cap;  ///< m/s: capacity uses min(|v|, c)
    float inv_erosion_depth;  ///< 1/m
    float gravity;  ///< m/s²
    float kappa;  ///< creep·dt/l², dimensionless, at most 0.2 (stable)
    bool open;
};

inline float speed_of(float u, float v) { return std::sqrt(u * u + v * v); }

/// The speed kept in the `flow` layer and used by the CFL limit: |v| capped
/// at the wave speed √(g·d) of the cell's water (see water_cell).
inline float flow_speed(float u, float v, float d, float gravity) {
    return std::sqrt(std::min(u * u + v * v, gravity * d));
}

/// The arrays of one sub-step.
struct Arrays {
    const float* b;  ///< terrain now
    float* b_next;  ///< terrain after erosion/deposition
    float* d;  ///< water (updated in place by pass 2: no one reads a neighbour's depth there)
    float* s;  ///< sediment (stored; pass 3 writes it)
    float* s1;  ///< sediment after erosion/deposition, before transport
    float* u;  ///< velocity east, m/s
    float* v;  ///< velocity south, m/s
    float *fw, *fe, *fn, *fs;  ///< outflow fluxes, m³/s (pass 1 updates each cell's own in place)
    const float* mask;
    int w, h;
    int sum_x0, sum_w;  ///< the columns row_sums() covers: all of them, or a tiled run's owned ones
};

struct RowSums {
    double s1 = 0.0, water = 0.0, check = 0.0;
    float vmax = 0.0f, dmax = 0.0f;
};

inline float rain_factor(const Arrays& a, std::size_t i) { return a.mask ? a.mask[i] : 1.0f; }

/// Which of a cell's neighbours exist (west, east, north, south).
struct Sides {
    bool w, e, n, s;
};
/// The rain mask at a cell's neighbours (0 where absent) and at the cell.
struct MaskAround {
    float w, e, n, s, c;
};

/// Pass 1 for one cell. The flags say which neighbours exist; the interior
/// loop passes constants so the compiler drops the tests and vectorises.
[[gnu::always_inline]] inline void flux_cell(const Arrays a, const Sub k, std::size_t i, std::size_t W, const Sides has,
                                             const MaskAround m) {
    const bool hw = has.w, he = has.e, hn = has.n, hs = has.s;
    const float mw = m.w, me = m.e, mn = m.n, ms = m.s, mc = m.c;
    const float* __restrict b = a.b;
    const float* __restrict d = a.d;
    const float d1 = d[i] + k.rain_dt * mc;
    const float surface = b[i] + d1;
    // Drop to each neighbour's water surface; off the grid: closed → no pipe,
    // open → onto dry ground at this cell's height (drop = d1).
    const float dw = hw ? surface - (b[i - 1] + (d[i - 1] + k.rain_dt * mw)) : d1;
    const float de = he ? surface - (b[i + 1] + (d[i + 1] + k.rain_dt * me)) : d1;
    const float dn = hn ? surface - (b[i - W] + (d[i - W] + k.rain_dt * mn)) : d1;
    const float ds = hs ? surface - (b[i + W] + (d[i + W] + k.rain_dt * ms)) : d1;
    const float edge = k.open ? 1.0f : 0.0f;
    const float fw = std::max(0.0f, a.fw[i] + k.flux_gain * dw) * (hw ? 1.0f : edge);
    const float fe = std::max(0.0f, a.fe[i] + k.flux_gain * de) * (he ? 1.0f : edge);
    const float fn = std::max(0.0f, a.fn[i] + k.flux_gain * dn) * (hn ? 1.0f : edge);
    const float fs = std::max(0.0f, a.fs[i] + k.flux_gain * ds) * (hs ? 1.0f : edge);
    // K: never send more than the cell holds (a hair less, so that round-off
    // cannot leave a negative depth to clamp).
    const float out = ((fw + fe) + (fn + fs)) * k.dt;
    const float volume = d1 * k.area;
    const float ratio = volume / std::max(out, 1e-30f) * 0.99999f;
    const float scale = out > volume ? ratio : 1.0f;
    a.fw[i] = fw * scale;
    a.fe[i] = fe * scale;
    a.fn[i] = fn * scale;
    a.fs[i] = fs * scale;
}

template <bool HasMask>
OROGEN_PIPE_CLONES void flux_row_impl(const Arrays a, const Sub k, int y) {
    const int W = a.w;
    const std::size_t Ws = std::size_t(W), row = std::size_t(y) * Ws;
    const bool hn = y > 0, hs = y + 1 < a.h;
    auto m = [&](std::size_t i) { return HasMask ? a.mask[i] : 1.0f; };
    auto edge = [&](int x) {
        const std::size_t i = row + std::size_t(x);
        const bool hw = x > 0, he = x + 1 < W;
        flux_cell(a, k, i, Ws, {hw, he, hn, hs},
                  {hw ? m(i - 1) : 0.0f, he ? m(i + 1) : 0.0f, hn ? m(i - Ws) : 0.0f, hs ? m(i + Ws) : 0.0f, m(i)});
    };
    if (!hn || !hs || W < 3) {
        for (int x = 0; x < W; ++x) edge(x);
        return;
    }
    edge(0);
    edge(W - 1);
#pragma GCC ivdep
    for (std::size_t i = row + 1; i < row + Ws - 1; ++i)
        flux_cell(a, k, i, Ws, {true, true, true, true}, {m(i - 1), m(i + 1), m(i - Ws), m(i + Ws), m(i)});
}

void flux_row(const Arrays& a, const Sub& k, int y) {
    if (a.mask) flux_row_impl<true>(a, k, y);
    else flux_row_impl<false>(a, k, y);
}

/// The factors of the terrain's tilt at a cell: 1/l one-sided, 1/(2l) central, 0 with no neighbour.
struct TiltScale {
    float x, y;
};
/// Whether the stored sediment is scaled by `scale` as it is read.
struct SedimentScale {
    bool rescale;
    double scale;
};

/// Pass 2 for one cell; returns its speed, adds to the row sums.
[[gnu::always_inline]] inline void water_cell(const Arrays a, const Sub k, std::size_t i, std::size_t W,
                                              const Sides has, const TiltScale tilt, float mc,
                                              const SedimentScale sed) {
    const bool hw = has.w, he = has.e, hn = has.n, hs = has.s;
    const float gx_scale = tilt.x, gy_scale = tilt.y;
    const bool rescale = sed.rescale;
    const double scale = sed.scale;
    const float* __restrict b = a.b;
    const float d1 = a.d[i] + k.rain_dt * mc;
    const float from_w = hw ? a.fe[i - 1] : 0.0f;
    const float from_e = he ? a.fw[i + 1] : 0.0f;
    const float from_n = hn ? a.fs[i - W] : 0.0f;
    const float from_s = hs ? a.fn[i + W] : 0.0f;
    const float fw = a.fw[i], fe = a.fe[i], fn = a.fn[i], fs = a.fs[i];
    const float inflow = (from_w + from_e) + (from_n + from_s);
    const float outflow = (fw + fe) + (fn + fs);
    const float d2 = std::max(0.0f, d1 + k.dt * (inflow - outflow) * k.inv_area);
    const float mean_depth = 0.5f * (d1 + d2);
    // Water passing through the cell per second along x and y (m³/s), over
    // the wetted cross-section: Mei's velocity.
    const float pass_x = 0.5f * ((from_w - fw) + (fe - from_e));
    const float pass_y = 0.5f * ((from_n - fn) + (fs - from_s));
    const float inv_raw = 1.0f / (std::max(mean_depth, 1e-6f) * k.l);
    const float inv = mean_depth > 1e-6f ? inv_raw : 0.0f;
    const float uu = pass_x * inv, vv = pass_y * inv;
    // The 4 axis neighbours' terrain (the cell itself past an edge).
    const float bc = b[i];
    const float bw = b[hw ? i - 1 : i], be = b[he ? i + 1 : i], bn = b[hn ? i - W : i], bs = b[hs ? i + W : i];
    // Local tilt of the terrain (central differences, one-sided at edges).
    const float gx = (be - bw) * gx_scale;
    const float gy = (bs - bn) * gy_scale;
    const float t2 = gx * gx + gy * gy;
    const float sin_tilt = std::sqrt(t2 / (1.0f + t2));
    // The speed that carries sediment: at most the shallow-water wave speed
    // √(g·d) (Froude number ≤ 1). The frictionless pipes let a film of rain
    // on a slope move about one cell per sub-step whatever its depth; counted
    // in full it would scour like a river. Capped, deep fast water carries and
    // thin films hardly do, so the flow gathers into channels.
    const float wave2 = std::min(k.speed_cap * k.speed_cap, k.gravity * mean_depth);
    const float speed = std::sqrt(std::min(uu * uu + vv * vv, wave2));
    const float ramp = std::min(mean_depth * k.inv_erosion_depth, 1.0f);
    const float cap = k.capacity * std::max(sin_tilt, k.min_slope) * speed * ramp;
    const float s0 = rescale ? float(double(a.s[i]) * scale) : a.s[i];
    const float deficit = cap - s0;
    float want = (deficit > 0.0f ? k.take : k.drop) * deficit;  // > 0 erode, < 0 deposit
    // Limiters against pits and mounds: erosion never takes a cell more than
    // half way down to its lowest neighbour, deposition never more than half
    // way up to its highest one. (Each cell eroding on its own otherwise digs
    // one-cell pits that trap water and deepen further: speckle.)
    const float lowest = std::min(std::min(bw, be), std::min(bn, bs));
    const float highest = std::max(std::max(bw, be), std::max(bn, bs));
    want = std::min(want, std::max(0.0f, 0.5f * (bc - lowest)));
    want = std::max(want, std::min(0.0f, 0.5f * (bc - highest)));
    // Creep (linear diffusion, κ = creep·dt/l²): damps the grid-scale ripples
    // that erosion alone amplifies. Pair terms κ·(b_j − b_i) cancel in the sum.
    const float crept = bc + k.kappa * (((bw + be) + (bn + bs)) - 4.0f * bc);
    // Exchange exactly what the terrain's float can represent, so terrain +
    // sediment is conserved even when `want` is below the height's resolution.
    const float b2 = crept - want;
    const float moved = crept - b2;
    const float s1 = s0 + moved;
    const float d3 = d2 * k.keep;
    a.b_next[i] = b2;
    a.s1[i] = s1;
    a.d[i] = d3;
    a.u[i] = uu;
    a.v[i] = vv;
}

// Eight lanes as GCC vector types: the row reductions below run in 8
// interleaved lanes combined in a fixed order, so they vectorise on every
// clone and give the same bits whatever the thread count.
typedef float F8 __attribute__((vector_size(32)));
typedef double D8 __attribute__((vector_size(64)));

inline F8 load8(const float* p) {
    F8 r;
    std::memcpy(&r, p, sizeof r);
    return r;
}
inline D8 widen(F8 v) { return __builtin_convertvector(v, D8); }
inline F8 max8(F8 a, F8 b) { return a < b ? b : a; }  // std::max per lane
inline double total8(D8 t) { return ((t[0] + t[1]) + (t[2] + t[3])) + ((t[4] + t[5]) + (t[6] + t[7])); }
inline float max_of8(F8 t) {
    return std::max(std::max(std::max(t[0], t[1]), std::max(t[2], t[3])),
                    std::max(std::max(t[4], t[5]), std::max(t[6], t[7])));
}

/// The row's sums and maxima, from what pass 2 wrote (a separate loop over
/// data still in cache, so the cell loop has no reductions).
OROGEN_PIPE_CLONES RowSums row_sums(const Arrays& a, std::size_t row, float gravity) {
    const std::size_t W = std::size_t(a.sum_w);
    row += std::size_t(a.sum_x0);
    const float* __restrict s1 = a.s1 + row;
    const float* __restrict d = a.d + row;
    const float* __restrict b = a.b_next + row;
    const float* __restrict u = a.u + row;
    const float* __restrict v = a.v + row;
    D8 ss = {}, ws = {}, cs = {};
    F8 vm = {}, dm = {};
    const F8 g = {gravity, gravity, gravity, gravity, gravity, gravity, gravity, gravity};
    std::size_t i = 0;
    for (; i + 8 <= W; i += 8) {
        const F8 dd = load8(d + i), uu = load8(u + i), vv = load8(v + i);
        ss += widen(load8(s1 + i));
        ws += widen(dd);
        cs += widen(load8(b + i));
        const F8 sp2 = uu * uu + vv * vv, wave2 = g * dd;
        const F8 lim = sp2 < wave2 ? sp2 : wave2;  // std::min per lane; sqrt after the max (monotonic)
        vm = max8(vm, lim);
        dm = max8(dm, dd);
    }
    RowSums sums;
    double s_tail = 0.0, w_tail = 0.0, c_tail = 0.0;
    float v_tail = 0.0f, d_tail = 0.0f;
    for (; i < W; ++i) {
        s_tail += double(s1[i]);
        w_tail += double(d[i]);
        c_tail += double(b[i]);
        v_tail = std::max(v_tail, std::min(u[i] * u[i] + v[i] * v[i], gravity * d[i]));
        d_tail = std::max(d_tail, d[i]);
    }
    sums.s1 = total8(ss) + s_tail;
    sums.water = total8(ws) + w_tail;
    sums.check = (total8(cs) + c_tail) + sums.water;  // NaN or infinity in terrain or water shows here
    sums.vmax = std::sqrt(std::max(max_of8(vm), v_tail));
    sums.dmax = std::max(max_of8(dm), d_tail);
    return sums;
}

/// Σ v[0..n) in double, 8 interleaved lanes combined in a fixed order.
OROGEN_PIPE_CLONES double sum_row(const float* __restrict v, std::size_t n) {
    D8 t = {};
    std::size_t i = 0;
    for (; i + 8 <= n; i += 8) t += widen(load8(v + i));
    double tail = 0.0;
    for (; i < n; ++i) tail += double(v[i]);
    return total8(t) + tail;
}

template <bool HasMask, bool Rescale>
OROGEN_PIPE_CLONES RowSums water_row_impl(const Arrays a, const Sub k, int y, double scale) {
    const int W = a.w;
    const std::size_t Ws = std::size_t(W), row = std::size_t(y) * Ws;
    const bool hn = y > 0, hs = y + 1 < a.h;
    const float gy_scale = (hn && hs) ? 0.5f * k.inv_l : ((hn || hs) ? k.inv_l : 0.0f);
    auto m = [&](std::size_t i) { return HasMask ? a.mask[i] : 1.0f; };
    auto edge = [&](int x) {
        const bool hw = x > 0, he = x + 1 < W;
        const float gx_scale = (hw && he) ? 0.5f * k.inv_l : ((hw || he) ? k.inv_l : 0.0f);
        const std::size_t i = row + std::size_t(x);
        water_cell(a, k, i, Ws, {hw, he, hn, hs}, {gx_scale, gy_scale}, m(i), {Rescale, scale});
    };
    if (!hn || !hs || W < 3) {
        for (int x = 0; x < W; ++x) edge(x);
        return row_sums(a, row, k.gravity);
    }
    edge(0);
    const float gx_scale = 0.5f * k.inv_l;
#pragma GCC ivdep
    for (std::size_t i = row + 1; i < row + Ws - 1; ++i)
        water_cell(a, k, i, Ws, {true, true, true, true}, {gx_scale, gy_scale}, m(i), {Rescale, scale});
    edge(W - 1);
    return row_sums(a, row, k.gravity);
}

/// Pass 2 for one row, and the row's sums and maxima over the columns
/// [sum_x0, sum_x0 + sum_w) (in a tiled run only the maxima and the
/// finiteness check are used: Solver::Impl::tile_reductions makes the sums).
RowSums water_row(const Arrays& a, const Sub& k, int y, bool rescale, double scale) {
    if (a.mask)
        return rescale ? water_row_impl<true, true>(a, k, y, scale) : water_row_impl<true, false>(a, k, y, scale);
    return rescale ? water_row_impl<false, true>(a, k, y, scale) : water_row_impl<false, false>(a, k, y, scale);
}

/// Pass 3 for one row: out[x] = s1 back-traced from (x, y) along (u, v) by
/// `step` cells per m/s, bilinear. The back-trace is clamped to one cell per
/// axis: in one sub-step water only reaches the 4 neighbours (pipes link
/// neighbours only, and the limiter K never sends more than a cell holds), so
/// the sediment it carries cannot come from farther. The source then lies in
/// the 3×3 block around the cell, and bilinear interpolation is a 3×3
/// stencil with tent weights: contiguous loads, no gathers, vectorises.
/// `up`/`dn` are the rows above/below (the row itself at the grid's edge,
/// whose weights are then folded onto it, as clamping the back-trace would).
OROGEN_PIPE_CLONES void transport_cells(const float* __restrict u, const float* __restrict v,
                                        const float* __restrict up, const float* __restrict mid,
                                        const float* __restrict dn, float* __restrict out, int W, float step) {
    auto cell = [&](int x, int xl, int xr) {
        const float bx = std::min(std::max(u[x] * step, -1.0f), 1.0f);  // cells back along x
        const float by = std::min(std::max(v[x] * step, -1.0f), 1.0f);
        const float wl = std::max(bx, 0.0f), wr = std::max(-bx, 0.0f), wc = (1.0f - wl) - wr;
        const float wu = std::max(by, 0.0f), wd = std::max(-by, 0.0f), wm = (1.0f - wu) - wd;
        const float ru = (wl * up[xl] + wc * up[x]) + wr * up[xr];
        const float rm = (wl * mid[xl] + wc * mid[x]) + wr * mid[xr];
        const float rd = (wl * dn[xl] + wc * dn[x]) + wr * dn[xr];
        out[x] = (wu * ru + wm * rm) + wd * rd;
    };
    if (W < 3) {
        for (int x = 0; x < W; ++x) cell(x, std::max(x - 1, 0), std::min(x + 1, W - 1));
        return;
    }
    cell(0, 0, 1);
    for (int x = 1; x < W - 1; ++x) cell(x, x - 1, x + 1);
    cell(W - 1, W - 2, W - 1);
}

/// Pass 3: sediment at each cell = s1 back-traced along the velocity; returns the row's sum (with `sums`).
double transport_row(const Arrays& a, const Sub& k, int y, bool sums = true) {
    const std::size_t row = std::size_t(y) * std::size_t(a.w);
    const std::size_t W = std::size_t(a.w);
    const float* mid = a.s1 + row;
    const float* up = y > 0 ? mid - W : mid;
    const float* dn = y + 1 < a.h ? mid + W : mid;
    transport_cells(a.u + row, a.v + row, up, mid, dn, a.s + row, a.w, k.dt * k.inv_l);
    return sums ? sum_row(a.s + row, std::size_t(a.w)) : 0.0;
}

}  // namespace

struct Solver::Impl {
    State st;
    Settings cfg;
    const float* mask = nullptr;
    int w = 0, h = 0;
    std::size_t n = 0;
    std::vector<float> b_other, s1, u, v;
    float* b_cur = nullptr;  ///< terrain of the current state (state's array or b_other)
    float* b_next = nullptr;
    double sediment_scale = 1.0;  ///< pending fix-up factor for the stored sediment
    double vmax = 0.0, dmax = 0.0;
    std::vector<double> row_s1, row_snew, row_check, row_water;
    std::vector<float> row_vmax, row_dmax;
    std::vector<std::uint8_t> water_done, transport_done;  ///< rows the fused sweep did (per sub-step)
    bool finished = false;

    // A tiled run: the grids are the grown tile; [ox, ox + ow) × [oy, oy + oh)
    // is the owned part, whose first column is column gx0 of the whole grid
    // (gw columns wide: the 8-lane row sums follow its columns).
    Tiling* tiles = nullptr;
    int ox = 0, oy = 0, ow = 0, oh = 0, gx0 = 0, gw = 0;
    std::vector<double> carry;  ///< per owned row: kCarry running sums (see tile_reductions)
    double exchanging = 0.0, reducing = 0.0;  ///< s, wall clock
    double cpu_exchanging = 0.0, cpu_reducing = 0.0;  ///< s of this process's CPU time (MPI waits by polling: counted)
    double tiled_total_new = 0.0;  ///< a tiled run's sediment total of the last sub-step (whole grid, m)

    void substep(double dt, std::int64_t step, std::int64_t sub);
    /// Refill the halo of every field a sub-step reads across a tile edge.
    void exchange();
    /// Sums and maxima of a tiled sub-step over the owned cells, combined
    /// across ranks exactly as a single process combines its rows.
    void tile_reductions(const Arrays& a, double& total_s1, double& total_new, bool& finite, float& vm, float& dm);
};

double process_cpu_seconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

namespace {
// Per row, for each of s1 and the new sediment: the 8 lanes and the tail of
// row_sums()/sum_row(), in that order.
constexpr int kCarry = 18;

/// Continue a row's lane sums (as row_sums/sum_row accumulate them) over the
/// values v[0..n), which are the whole grid's columns gx0.. of that row;
/// `full` = the columns the 8 lanes take (the rest go to the tail).
inline void continue_lanes(double* lanes, const float* __restrict v, int n, int gx0, int full) {
    int x = 0;
    // Up to the first column that is a multiple of 8, one by one.
    for (; x < n && gx0 + x < full && (gx0 + x) % 8 != 0; ++x) lanes[(gx0 + x) % 8] += double(v[x]);
    // Whole groups of 8 in registers (lane j gets column 8m + j, in order, as in row_sums).
    double acc[8];
    for (int j = 0; j < 8; ++j) acc[j] = lanes[j];
    for (; x + 8 <= n && gx0 + x + 8 <= full; x += 8)
        for (int j = 0; j < 8; ++j) acc[j] += double(v[x + j]);
    for (int j = 0; j < 8; ++j) lanes[j] = acc[j];
    for (; x < n; ++x) {
        const int gx = gx0 + x;
        if (gx < full) lanes[gx % 8] += double(v[x]);
        else lanes[8] += double(v[x]);
    }
}

inline double lanes_total(const double* l) {
    return (((l[0] + l[1]) + (l[2] + l[3])) + ((l[4] + l[5]) + (l[6] + l[7]))) + l[8];  // total8(t) + tail
}
}  // namespace

void Solver::Impl::exchange() {
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = process_cpu_seconds();
    const double cell = st.height.cell;
    const GridView grids[] = {{b_cur, w, h, cell}, st.water,      st.sediment,  st.flux_west,
                              st.flux_east,        st.flux_north, st.flux_south};
    tiles->exchange(grids);
    exchanging += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    cpu_exchanging += process_cpu_seconds() - c0;
}

void Solver::Impl::tile_reductions(const Arrays& a, double& total_s1, double& total_new, bool& finite, float& vm,
                                   float& dm) {
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = process_cpu_seconds();
    const std::size_t W = std::size_t(w);
    // Order-free parts first: the maxima and the finiteness check that the
    // sweep took over the owned columns of every row (row_sums, as one
    // process takes them over whole rows: a maximum is the same in any order;
    // the sum of terrain and water is finite exactly when every value is).
    float m[3] = {0.0f, 0.0f, 0.0f};  // vmax, dmax, 1 if a value is not finite
    for (int r = oy; r < oy + oh; ++r) {
        m[0] = std::max(m[0], row_vmax[std::size_t(r)]);
        m[1] = std::max(m[1], row_dmax[std::size_t(r)]);
        if (!std::isfinite(row_check[std::size_t(r)])) m[2] = 1.0f;
    }
    // The sediment totals: each row's 8 lanes carried west to east through
    // the tiles of its row, then the rows in order, as one process adds them.
    const int full = gw - gw % 8;
    carry.assign(std::size_t(oh) * kCarry, 0.0);
    tiles->carry(Tiling::Toward::east, carry, kCarry, [&](int first, int count) {
        parallel_for(first, first + count, 16, [&](std::int64_t r0, std::int64_t r1) {
            FlushDenormals ftz;  // as in the sweep: denormal inputs read as 0
            for (std::int64_t r = r0; r < r1; ++r) {
                const std::size_t row = std::size_t(oy + r) * W + std::size_t(ox);
                continue_lanes(carry.data() + std::size_t(r) * kCarry, a.s1 + row, ow, gx0, full);
                continue_lanes(carry.data() + std::size_t(r) * kCarry + 9, a.s + row, ow, gx0, full);
            }
        });
    });
    std::vector<double> mine;
    if (tiles->eastmost()) {
        mine.resize(std::size_t(oh) * 2);
        for (int r = 0; r < oh; ++r) {
            mine[2 * std::size_t(r)] = lanes_total(carry.data() + std::size_t(r) * kCarry);
            mine[2 * std::size_t(r) + 1] = lanes_total(carry.data() + std::size_t(r) * kCarry + 9);
        }
    }
    const std::vector<double> rows = tiles->gather_rows(mine, 2);
    total_s1 = 0.0;
    total_new = 0.0;
    for (std::size_t y = 0; y < rows.size() / 2; ++y) {
        total_s1 += rows[2 * y];
        total_new += rows[2 * y + 1];
    }
    tiles->reduce(std::span<float>(m), Tiling::Reduce::max);
    vm = m[0];
    dm = m[1];
    finite = m[2] == 0.0f;
    reducing += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    cpu_reducing += process_cpu_seconds() - c0;
}

Solver::Solver(const State& state, const Settings& settings, const float* rain_mask, Tiling* tiling) : impl_(new Impl) {
    Impl& m = *impl_;
    m.st = state;
    m.cfg = settings;
    m.mask = rain_mask;
    m.w = state.height.width;
    m.h = state.height.height;
    m.n = state.height.size();
    m.tiles = tiling;
    if (tiling) {
        const TileRect own = tiling->owned(), grown = tiling->ghosted();
        if (grown.width != m.w || grown.height != m.h)
            throw Error("pipe::Solver: a tiled run's state grids must cover the grown tile");
        m.ox = own.x0 - grown.x0;
        m.oy = own.y0 - grown.y0;
        m.ow = own.width;
        m.oh = own.height;
        m.gx0 = own.x0;
        m.gw = tiling->grid_width();
    } else {
        m.ow = m.w;
        m.oh = m.h;
    }
    for (const GridView& g : {state.water, state.sediment, state.flux_west, state.flux_east, state.flux_north,
                              state.flux_south, state.speed})
        if (g.width != m.w || g.height != m.h) throw Error("pipe::Solver: state grids differ in size");
    if (!(settings.pipe_area > 0.0) || !(settings.gravity > 0.0) || !(state.height.cell > 0.0))
        throw Error("pipe::Solver: pipe_area, gravity and cell size must be positive");
    m.b_other.resize(m.n);
    m.s1.resize(m.n);
    m.u.assign(m.n, 0.0f);
    m.v.assign(m.n, 0.0f);
    m.b_cur = state.height.data;
    m.b_next = m.b_other.data();
    m.row_s1.resize(std::size_t(m.h));
    m.row_snew.resize(std::size_t(m.h));
    m.row_check.resize(std::size_t(m.h));
    m.row_water.resize(std::size_t(m.h));
    m.row_vmax.resize(std::size_t(m.h));
    m.water_done.resize(std::size_t(m.h));
    m.transport_done.resize(std::size_t(m.h));
    m.row_dmax.resize(std::size_t(m.h));
    // The first sub-step's CFL limit comes from the state (speed and water of
    // the previous run's last sub-step), so a continued run schedules its
    // sub-steps exactly as one longer run would.
    // (Over the owned cells of a tiled run: the halo is not filled yet.)
    parallel_for(0, m.oh, 16, [&](std::int64_t y0, std::int64_t y1) {
        FlushDenormals ftz;
        for (std::int64_t y = y0; y < y1; ++y) {
            float vm = 0.0f, dm = 0.0f;
            const float* sp = state.speed.row(int(y) + m.oy) + m.ox;
            const float* wa = state.water.row(int(y) + m.oy) + m.ox;
            for (int x = 0; x < m.ow; ++x) {
                vm = std::max(vm, sp[x]);
                dm = std::max(dm, wa[x]);
            }
            m.row_vmax[std::size_t(y)] = vm;
            m.row_dmax[std::size_t(y)] = dm;
        }
    });
    float vd[2] = {0.0f, 0.0f};
    for (int y = 0; y < m.oh; ++y) {
        vd[0] = std::max(vd[0], m.row_vmax[std::size_t(y)]);
        vd[1] = std::max(vd[1], m.row_dmax[std::size_t(y)]);
    }
    if (tiling)
        tiling->reduce(std::span<float>(vd),
                       Tiling::Reduce::max);  // the whole grid's (a maximum is exact in any order)
    m.vmax = double(vd[0]);
    m.dmax = double(vd[1]);
}

Solver::~Solver() = default;

void Solver::advance(double dt, std::int64_t step) {
    Impl& m = *impl_;
    if (m.finished) throw Error("pipe::Solver::advance after finish");
    if (!(dt > 0.0)) return;
    const double l = m.st.height.cell;
    double remaining = dt;
    std::int64_t sub = 0;
    while (remaining > 0.0) {
        const double c = std::sqrt(m.cfg.gravity * std::max(m.dmax, m.cfg.pipe_area / l));
        const double limit = m.cfg.cfl * l / (std::min(m.vmax, c) + c);
        double dts = remaining;
        if (remaining > limit) {
            const double parts = std::ceil(remaining / limit);
            dts = remaining / parts;
        }
        m.substep(dts, step, ++sub);
        ++substeps_;
        remaining = (dts == remaining) ? 0.0 : remaining - dts;
        if (remaining <= 1e-12 * dt) remaining = 0.0;
    }
}

void Solver::Impl::substep(double dt, std::int64_t step, std::int64_t sub) {
    const double l = st.height.cell;
    const double c = std::sqrt(cfg.gravity * std::max(dmax, cfg.pipe_area / l));
    Sub k;
    k.dt = float(dt);
    k.rain_dt = float(cfg.rain * dt);
    k.flux_gain = float(dt * cfg.gravity * cfg.pipe_area / l);
    k.area = float(l * l);
    k.inv_area = float(1.0 / (l * l));
    k.l = float(l);
    k.inv_l = float(1.0 / l);
    k.capacity = float(cfg.capacity);
    k.min_slope = float(cfg.min_slope);
    k.take = float(-std::expm1(-cfg.dissolve * dt));
    k.drop = float(-std::expm1(-cfg.deposit * dt));
    k.keep = float(std::exp(-cfg.evaporation * dt));
    k.speed_cap = float(c);
    k.inv_erosion_depth = cfg.erosion_depth > 0.0 ? float(1.0 / cfg.erosion_depth) : 3.0e38f;
    k.open = cfg.boundary == Boundary::open;
    k.gravity = float(cfg.gravity);
    k.kappa = float(std::min(0.2, cfg.creep * dt / (l * l)));

    const int W = w, H = h;
    const bool tiled = tiles != nullptr;
    if (tiled) exchange();

    Arrays ar{b_cur,
              b_next,
              st.water.data,
              st.sediment.data,
              s1.data(),
              u.data(),
              v.data(),
              st.flux_west.data,
              st.flux_east.data,
              st.flux_north.data,
              st.flux_south.data,
              mask,
              W,
              H,
              ox,
              ow};
    // Chunks of rows: few and large, since each chunk leaves its edge rows
    // to the clean-up passes below.
    const std::int64_t grain = std::max<std::int64_t>(16, H / 16);
    const bool rescale = sediment_scale != 1.0;
    const double sed_scale_d = sediment_scale;
    auto water = [&](int y) {
        RowSums r = water_row(ar, k, y, rescale, sed_scale_d);
        row_s1[std::size_t(y)] = r.s1;
        row_water[std::size_t(y)] = r.water;
        row_check[std::size_t(y)] = r.check;
        row_vmax[std::size_t(y)] = r.vmax;
        row_dmax[std::size_t(y)] = r.dmax;
    };
    // One sweep per chunk [y0, y1) does all three passes with a lag, while
    // the rows are in cache:
    //   1. flux(y): rain, outflow flux, limiter K (each cell writes only its own fluxes);
    //   2. water(y − 1): depth, velocity, erosion/deposition, evaporation — once
    //      the fluxes of rows y − 2..y are final;
    //   3. transport(y − 2): semi-Lagrangian sediment — once s1 of rows y − 3..y − 1 is.
    // Water of a chunk's first and last rows waits (their neighbours' fluxes
    // belong to other chunks, and other chunks' flux passes still read their
    // old depth), and so does transport of its first and last two rows; the
    // clean-up passes do them. Every row is the same pure function of the
    // sub-step's inputs whoever computes it, so the split cannot change the result.
    std::fill(water_done.begin(), water_done.end(), std::uint8_t(0));
    std::fill(transport_done.begin(), transport_done.end(), std::uint8_t(0));
    parallel_for(0, H, grain, [&](std::int64_t y0, std::int64_t y1) {
        FlushDenormals ftz;
        for (std::int64_t y = y0; y < y1; ++y) {
            flux_row(ar, k, int(y));
            const std::int64_t yw = y - 1, yt = y - 2;
            if (yw > y0 && yw < y1 - 1) {
                water(int(yw));
                water_done[std::size_t(yw)] = 1;
            }
            if (yt > y0 + 1 && yt < y1 - 2) {
                row_snew[std::size_t(yt)] = transport_row(ar, k, int(yt), !tiled);
                transport_done[std::size_t(yt)] = 1;
            }
        }
    });
    parallel_for(0, H, grain, [&](std::int64_t y0, std::int64_t y1) {
        FlushDenormals ftz;
        for (std::int64_t y = y0; y < y1; ++y)
            if (!water_done[std::size_t(y)]) water(int(y));
    });
    parallel_for(0, H, grain, [&](std::int64_t y0, std::int64_t y1) {
        FlushDenormals ftz;
        for (std::int64_t y = y0; y < y1; ++y)
            if (!transport_done[std::size_t(y)]) row_snew[std::size_t(y)] = transport_row(ar, k, int(y), !tiled);
    });

    // ---- reductions, in row order
    double total_s1 = 0.0, total_new = 0.0, check = 0.0;
    float vm = 0.0f, dm = 0.0f;
    bool finite = true;
    if (tiled) {
        tile_reductions(ar, total_s1, total_new, finite, vm, dm);
        tiled_total_new = total_new;
    } else {
        for (int y = 0; y < H; ++y) {
            total_s1 += row_s1[std::size_t(y)];
            total_new += row_snew[std::size_t(y)];
            check += row_check[std::size_t(y)];
            vm = std::max(vm, row_vmax[std::size_t(y)]);
            dm = std::max(dm, row_dmax[std::size_t(y)]);
        }
        finite = std::isfinite(check);
    }
    if (!finite || !std::isfinite(total_new) || !std::isfinite(vm)) {
        std::ostringstream msg;
        msg << "non-finite terrain, water or sediment at step " << step << " (sub-step " << sub << ", dt " << dt
            << " s); the simulation became unstable";
        throw Error(msg.str());
    }
    vmax = vm;
    dmax = dm;
    // Semi-Lagrangian transport does not conserve: with closed walls, restore
    // the total (applied lazily when the sediment is next read).
    sediment_scale = (cfg.boundary == Boundary::closed && total_new > 0.0) ? total_s1 / total_new : 1.0;
    std::swap(b_cur, b_next);
}

void Solver::finish() {
    Impl& m = *impl_;
    if (m.finished) return;
    m.finished = true;
    float* s = m.st.sediment.data;
    const double scale = m.sediment_scale;
    float* speed = m.st.speed.data;
    const float* up = m.u.data();
    const float* vp = m.v.data();
    const float* dp = m.st.water.data;
    const float gravity = float(m.cfg.gravity);
    parallel_for(0, std::int64_t(m.n), 1 << 16, [&](std::int64_t i0, std::int64_t i1) {
        FlushDenormals ftz;
        for (std::int64_t i = i0; i < i1; ++i) {
            if (scale != 1.0) s[i] = float(double(s[i]) * scale);
            speed[i] = flow_speed(up[i], vp[i], dp[i], gravity);
        }
    });
    m.sediment_scale = 1.0;
    if (m.b_cur != m.st.height.data) std::memcpy(m.st.height.data, m.b_cur, m.n * sizeof(float));
    m.b_cur = m.st.height.data;
}

ConstGridView Solver::current_height() const {
    const Impl& m = *impl_;
    return {m.b_cur, m.st.height.width, m.st.height.height, m.st.height.cell};
}

double Solver::seconds_exchanging() const { return impl_->exchanging; }
double Solver::seconds_reducing() const { return impl_->reducing; }
double Solver::cpu_seconds_exchanging() const { return impl_->cpu_exchanging; }
double Solver::cpu_seconds_reducing() const { return impl_->cpu_reducing; }

double Solver::total_water() const {
    if (impl_->tiles) return std::numeric_limits<double>::quiet_NaN();
    double t = 0.0;
    for (double r : impl_->row_water) t += r;
    return t;
}

double Solver::total_sediment() const {
    if (impl_->tiles) return impl_->tiled_total_new * impl_->sediment_scale;
    double t = 0.0;
    for (double r : impl_->row_snew) t += r;
    return t * impl_->sediment_scale;
}

}  // namespace orogen::pipe
