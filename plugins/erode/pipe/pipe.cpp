#include "pipe.hpp"

#include <orogen/error.hpp>
#include <orogen/parallel.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>
#include <utility>

// Row loops built for plain x86-64 and for AVX2, chosen at run time; the same
// operations per lane in the same order (no FMA contraction), so the same bits.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define OROGEN_PIPE_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define OROGEN_PIPE_CLONES
#endif

namespace orogen::pipe {
namespace {

/// Constants of one sub-step, in float for the row loops.
struct Sub {
    float dt;         ///< s
    float rain_dt;    ///< m of rain this sub-step (before the mask)
    float flux_gain;  ///< dt·g·A/l: m³/s of flux per metre of surface drop
    float area;       ///< l², m²
    float inv_area;   ///< 1/l²
    float l, inv_l;   ///< cell size, m
    float capacity, min_slope;
    float take, drop;  ///< 1 − e^(−Ks·dt), 1 − e^(−Kd·dt)
    float keep;        ///< e^(−Ke·dt)
    float speed_cap;   ///< m/s: capacity uses min(|v|, c)
    float inv_erosion_depth;  ///< 1/m
    bool open;
};

inline float speed_of(float u, float v) { return std::sqrt(u * u + v * v); }

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
    bool finished = false;

    void substep(double dt, std::int64_t step, std::int64_t sub);
};

Solver::Solver(const State& state, const Settings& settings, const float* rain_mask) : impl_(new Impl) {
    Impl& m = *impl_;
    m.st = state;
    m.cfg = settings;
    m.mask = rain_mask;
    m.w = state.height.width;
    m.h = state.height.height;
    m.n = state.height.size();
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
    m.row_dmax.resize(std::size_t(m.h));
    // The first sub-step's CFL limit comes from the state (speed and water of
    // the previous run's last sub-step), so a continued run schedules its
    // sub-steps exactly as one longer run would.
    parallel_for(0, m.h, 16, [&](std::int64_t y0, std::int64_t y1) {
        for (std::int64_t y = y0; y < y1; ++y) {
            float vm = 0.0f, dm = 0.0f;
            const float* sp = state.speed.row(int(y));
            const float* wa = state.water.row(int(y));
            for (int x = 0; x < m.w; ++x) {
                vm = std::max(vm, sp[x]);
                dm = std::max(dm, wa[x]);
            }
            m.row_vmax[std::size_t(y)] = vm;
            m.row_dmax[std::size_t(y)] = dm;
        }
    });
    for (int y = 0; y < m.h; ++y) {
        m.vmax = std::max(m.vmax, double(m.row_vmax[std::size_t(y)]));
        m.dmax = std::max(m.dmax, double(m.row_dmax[std::size_t(y)]));
    }
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

    const int W = w, H = h;
    const float* b = b_cur;
    float* d = st.water.data;
    float* fw = st.flux_west.data;
    float* fe = st.flux_east.data;
    float* fn = st.flux_north.data;
    float* fs = st.flux_south.data;
    const float* msk = mask;
    const std::int64_t grain = std::max<std::int64_t>(8, H / 64);

    // ---- pass 1: rain, outflow flux, limiter K (each cell writes only its own four fluxes)
    parallel_for(0, H, grain, [&](std::int64_t y0, std::int64_t y1) {
        auto d1_at = [&](std::size_t i) { return d[i] + k.rain_dt * (msk ? msk[i] : 1.0f); };
        auto cell = [&](std::size_t i, bool hw, bool he, bool hn, bool hs) {
            const float d1 = d1_at(i);
            const float surface = b[i] + d1;
            // Drop to each neighbour's surface; off the grid: closed → none,
            // open → onto dry ground at this cell's height (drop = d1).
            auto drop = [&](bool has, std::size_t j) { return has ? surface - (b[j] + d1_at(j)) : d1; };
            const float edge = k.open ? 1.0f : 0.0f;
            float a = std::max(0.0f, fw[i] + k.flux_gain * drop(hw, hw ? i - 1 : i)) * (hw ? 1.0f : edge);
            float e = std::max(0.0f, fe[i] + k.flux_gain * drop(he, he ? i + 1 : i)) * (he ? 1.0f : edge);
            float no = std::max(0.0f, fn[i] + k.flux_gain * drop(hn, hn ? i - W : i)) * (hn ? 1.0f : edge);
            float so = std::max(0.0f, fs[i] + k.flux_gain * drop(hs, hs ? i + W : i)) * (hs ? 1.0f : edge);
            // K: never send more than the cell holds (slightly less, so that
            // round-off cannot leave a negative depth to clamp).
            const float out = (a + e + no + so) * k.dt;
            const float volume = d1 * k.area;
            const float scale = out > volume ? volume / out * 0.99999f : 1.0f;
            fw[i] = a * scale;
            fe[i] = e * scale;
            fn[i] = no * scale;
            fs[i] = so * scale;
        };
        for (std::int64_t y = y0; y < y1; ++y) {
            const std::size_t row = std::size_t(y) * std::size_t(W);
            const bool hn = y > 0, hs = y + 1 < H;
            for (int x = 0; x < W; ++x) cell(row + std::size_t(x), x > 0, x + 1 < W, hn, hs);
        }
    });

    // ---- pass 2: water, velocity, erosion/deposition, evaporation
    const bool rescale = sediment_scale != 1.0;
    const double sed_scale_d = sediment_scale;
    float* bn = b_next;
    float* s = st.sediment.data;
    float* s1p = s1.data();
    float* up = u.data();
    float* vp = v.data();
    parallel_for(0, H, grain, [&](std::int64_t y0, std::int64_t y1) {
        for (std::int64_t y = y0; y < y1; ++y) {
            const std::size_t row = std::size_t(y) * std::size_t(W);
            const bool hn = y > 0, hs = y + 1 < H;
            const std::size_t yn = hn ? row - std::size_t(W) : row, ys = hs ? row + std::size_t(W) : row;
            const float gy_scale = (hn && hs) ? 0.5f * k.inv_l : ((hn || hs) ? k.inv_l : 0.0f);
            double sum_s1 = 0.0, check = 0.0, water = 0.0;
            float vm = 0.0f, dm = 0.0f;
            for (int x = 0; x < W; ++x) {
                const std::size_t i = row + std::size_t(x);
                const bool hw = x > 0, he = x + 1 < W;
                const float d1 = d[i] + k.rain_dt * (msk ? msk[i] : 1.0f);
                const float from_w = hw ? fe[i - 1] : 0.0f;
                const float from_e = he ? fw[i + 1] : 0.0f;
                const float from_n = hn ? fs[i - std::size_t(W)] : 0.0f;
                const float from_s = hs ? fn[i + std::size_t(W)] : 0.0f;
                const float inflow = (from_w + from_e) + (from_n + from_s);
                const float outflow = (fw[i] + fe[i]) + (fn[i] + fs[i]);
                const float d2 = std::max(0.0f, d1 + k.dt * (inflow - outflow) * k.inv_area);
                const float mean_depth = 0.5f * (d1 + d2);
                // Water passing through the cell per second, x and y (m³/s).
                const float pass_x = 0.5f * ((from_w - fw[i]) + (fe[i] - from_e));
                const float pass_y = 0.5f * ((from_n - fn[i]) + (fs[i] - from_s));
                const float inv = mean_depth > 1e-6f ? 1.0f / (mean_depth * k.l) : 0.0f;
                const float uu = pass_x * inv, vv = pass_y * inv;
                // Local tilt from the terrain (central differences, one-sided at edges).
                const std::size_t xl = hw ? i - 1 : i, xr = he ? i + 1 : i;
                const float gx_scale = (hw && he) ? 0.5f * k.inv_l : ((hw || he) ? k.inv_l : 0.0f);
                const float gx = (b[xr] - b[xl]) * gx_scale;
                const float gy = (b[ys + std::size_t(x)] - b[yn + std::size_t(x)]) * gy_scale;
                const float t2 = gx * gx + gy * gy;
                const float sin_tilt = std::sqrt(t2 / (1.0f + t2));
                const float speed = speed_of(uu, vv);
                // Mei's capacity, times a depth ramp (after Št'ava et al. 2008): a
                // film of rain shallower than erosion_depth carries in
                // proportion to its depth, so sheets do not scour like rivers
                // and the flow gathers into channels.
                const float ramp = std::min(mean_depth * k.inv_erosion_depth, 1.0f);
                const float cap =
                    k.capacity * std::max(sin_tilt, k.min_slope) * std::min(speed, k.speed_cap) * ramp;
                const float s0 = rescale ? float(double(s[i]) * sed_scale_d) : s[i];
                const float deficit = cap - s0;
                const float want = (deficit > 0.0f ? k.take : k.drop) * deficit;  // + erode, − deposit
                // Exchange exactly what the terrain's float can represent, so
                // terrain + sediment is conserved even when `want` is below
                // the resolution of the height.
                const float b2 = b[i] - want;
                const float moved = b[i] - b2;
                const float s1v = s0 + moved;
                const float d3 = d2 * k.keep;
                bn[i] = b2;
                s1p[i] = s1v;
                d[i] = d3;
                up[i] = uu;
                vp[i] = vv;
                sum_s1 += double(s1v);
                water += double(d3);
                check += double(b2) + double(d3);
                vm = std::max(vm, speed);
                dm = std::max(dm, d3);
            }
            row_s1[std::size_t(y)] = sum_s1;
            row_water[std::size_t(y)] = water;
            row_check[std::size_t(y)] = check;
            row_vmax[std::size_t(y)] = vm;
            row_dmax[std::size_t(y)] = dm;
        }
    });

    // ---- pass 3: semi-Lagrangian sediment transport (bilinear back-trace)
    const float* s1c = s1p;
    parallel_for(0, H, grain, [&](std::int64_t y0, std::int64_t y1) {
        const float xmax = float(W - 1), ymax = float(H - 1);
        for (std::int64_t y = y0; y < y1; ++y) {
            const std::size_t row = std::size_t(y) * std::size_t(W);
            double sum = 0.0;
            for (int x = 0; x < W; ++x) {
                const std::size_t i = row + std::size_t(x);
                const float px = std::min(std::max(float(x) - up[i] * k.dt * k.inv_l, 0.0f), xmax);
                const float py = std::min(std::max(float(y) - vp[i] * k.dt * k.inv_l, 0.0f), ymax);
                const int x0 = std::min(int(px), W - 1), y0i = std::min(int(py), H - 1);
                const int x1 = std::min(x0 + 1, W - 1), y1i = std::min(y0i + 1, H - 1);
                const float fx = px - float(x0), fy = py - float(y0i);
                const float* r0 = s1c + std::size_t(y0i) * std::size_t(W);
                const float* r1 = s1c + std::size_t(y1i) * std::size_t(W);
                const float top = r0[x0] + (r0[x1] - r0[x0]) * fx;
                const float bottom = r1[x0] + (r1[x1] - r1[x0]) * fx;
                const float value = top + (bottom - top) * fy;
                s[i] = value;
                sum += double(value);
            }
            row_snew[std::size_t(y)] = sum;
        }
    });

    // ---- reductions, in row order
    double total_s1 = 0.0, total_new = 0.0, check = 0.0;
    float vm = 0.0f, dm = 0.0f;
    for (int y = 0; y < H; ++y) {
        total_s1 += row_s1[std::size_t(y)];
        total_new += row_snew[std::size_t(y)];
        check += row_check[std::size_t(y)];
        vm = std::max(vm, row_vmax[std::size_t(y)]);
        dm = std::max(dm, row_dmax[std::size_t(y)]);
    }
    if (!std::isfinite(check) || !std::isfinite(total_new) || !std::isfinite(vm)) {
        std::ostringstream msg;
        msg << "non-finite terrain, water or sediment at step " << step << " (sub-step " << sub << ", dt "
            << dt << " s); the simulation became unstable";
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
    parallel_for(0, std::int64_t(m.n), 1 << 16, [&](std::int64_t i0, std::int64_t i1) {
        for (std::int64_t i = i0; i < i1; ++i) {
            if (scale != 1.0) s[i] = float(double(s[i]) * scale);
            speed[i] = speed_of(up[i], vp[i]);
        }
    });
    m.sediment_scale = 1.0;
    if (m.b_cur != m.st.height.data) std::memcpy(m.st.height.data, m.b_cur, m.n * sizeof(float));
    m.b_cur = m.st.height.data;
}

double Solver::total_water() const {
    double t = 0.0;
    for (double r : impl_->row_water) t += r;
    return t;
}

double Solver::total_sediment() const {
    double t = 0.0;
    for (double r : impl_->row_snew) t += r;
    return t * impl_->sediment_scale;
}

}  // namespace orogen::pipe
