#include "hydraulic.hpp"

#include <orogen/error.hpp>
#include <orogen/parallel.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <utility>
#include <vector>

// Row loops built for plain x86-64 and for AVX2, chosen at run time; same
// operations per lane in the same order (no FMA contraction), same bits.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define OROGEN_HYDRAULIC_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define OROGEN_HYDRAULIC_CLONES
#endif

namespace orogen::hydraulic {
namespace {

struct Rule {
    float rain, solubility, keep /* 1 − evaporation */, capacity;
    Hardness hardness;
    const float* hardness_layer;
    float inv_cell;
};

/// One row of the state after rain and dissolving (steps 1 and 2).
struct PrepRow {
    float *h, *w, *s, *a;  // terrain, water, sediment, altitude a = h + w (m)
};
/// One row of Olsen's flow factors: water moved to a lower neighbour = F·drop,
/// sediment = G·drop; and what each cell keeps after its total outflow of
/// water (wr = w − F·Σdrop) and sediment (sr = s − G·Σdrop), so the gather
/// needs no product per giving pipe.
struct FactorRow {
    float *f, *g, *wr, *sr;
};

/// The flow and output loops over a row's inner cells x = 1 … w − 2 run on to
/// a multiple of 16 cells (no scalar remainder loop in any clone); the cells
/// past w − 2 are junk in the rows' padding, never read for a real cell, and
/// x = w − 1 is recomputed after the loop. Rows hold at least padded_end(w) + 1
/// floats, the tails initialised.
constexpr int padded_end(int w) { return 1 + (w - 2 + 15) / 16 * 16; }

// ---------------------------------------------------------------- step 1 + 2

template <Hardness H>
inline float softness(float gx, float gy, const float* layer, int x) {
    if constexpr (H == Hardness::steepness) {
        // 1 − |n_y| of the unit normal, |n_y| = 1/√q, q = 1 + g²; written as
        // g²/(q + √q) (multiply 1 − 1/√q by √q(√q + 1)/(√q(√q + 1))): no
        // cancellation on gentle slopes, and still one root and one division.
        const float g2 = gx * gx + gy * gy;
        const float q = 1.0f + g2;
        const float t = g2 / (q + std::sqrt(q));
        return t * t * t;
    } else if constexpr (H == Hardness::constant) {
        return 1.0f;
    } else {
        return 1.0f - std::min(std::max(layer[x], 0.0f), 1.0f);
    }
}

/// The slope (metres per metre) at (x, y): central differences inside,
/// one-sided on the edges. The rain/dissolve stage's edge cells and the
/// `hardness` layer use it; the inner loop inlines the central case.
inline void slope_at(ConstGridView height, float inv_cell, int x, int y, float& gx, float& gy) {
    const int w = height.width, rows = height.height;
    const int xl = std::max(x - 1, 0), xr = std::min(x + 1, w - 1);
    const int yu = std::max(y - 1, 0), yd = std::min(y + 1, rows - 1);
    const float sx = xr > xl ? inv_cell / float(xr - xl) : 0.0f;
    const float sy = yd > yu ? inv_cell / float(yd - yu) : 0.0f;
    gx = (height.row(y)[xr] - height.row(y)[xl]) * sx;
    gy = (height.row(yd)[x] - height.row(yu)[x]) * sy;
}

/// One cell after rain and dissolving; `soft` is its softness<H> (1 − hardness).
inline void prep_cell(const Rule& r, float h, float w, float s, float soft, int x, const PrepRow& out) {
    const float w1 = w + r.rain;
    const float dissolved = r.solubility * w1 * soft;
    const float h1 = h - dissolved;
    out.h[x] = h1;
    out.w[x] = w1;
    out.s[x] = s + dissolved;
    out.a[x] = h1 + w1;
}

template <Hardness H>
OROGEN_HYDRAULIC_CLONES void prep_row(const ConstState& in, const Rule& r, int y, const PrepRow& out) {
    const int w = in.height.width, rows = in.height.height;
    const std::size_t base = std::size_t(y) * std::size_t(w);
    // Central differences inside, one-sided at the edges (metres per metre).
    const int yu = std::max(y - 1, 0), yd = std::min(y + 1, rows - 1);
    const float sy = yd > yu ? r.inv_cell / float(yd - yu) : 0.0f;
    const float* __restrict hu = in.height.row(yu);
    const float* __restrict hd = in.height.row(yd);
    const float* __restrict hc = in.height.row(y);
    const float* __restrict wc = in.water.data + base;
    const float* __restrict sc = in.sediment.data + base;
    const float* layer = r.hardness_layer ? r.hardness_layer + base : nullptr;
    auto edge = [&](int x) {
        float gx, gy;
        slope_at(in.height, r.inv_cell, x, y, gx, gy);
        prep_cell(r, hc[x], wc[x], sc[x], softness<H>(gx, gy, layer, x), x, out);
    };
    // Whole vectors (padded_end) where the grids hold that many floats past
    // the row start (they run on into the next row: junk in the padding);
    // the edges after the loop.
    const int xe = std::size_t(padded_end(w)) < std::size_t(rows - yd) * std::size_t(w) ? padded_end(w) : w - 1;
    const float sx = 0.5f * r.inv_cell;
#pragma GCC ivdep
    for (int x = 1; x < xe; ++x)
        prep_cell(r, hc[x], wc[x], sc[x], softness<H>((hc[x + 1] - hc[x - 1]) * sx, (hd[x] - hu[x]) * sy, layer, x), x,
                  out);
    edge(0);
    if (w > 1) edge(w - 1);
}

// -------------------------------------------------------------- step 3 flow

/// Olsen's flow factors for one cell from its altitude a, water w, sediment s
/// and its neighbours' altitudes (absent neighbours: `has` false).
struct Factors {
    float f, g, wr, sr;
};
inline Factors factor_cell(float a, float w, float s, const float (&an)[4], const bool (&has)[4]) {
    float drop_sum = 0.0f, lower_n = 0.0f;
    for (int k = 0; k < 4; ++k) {
        const float d = a - an[k];
        const bool lower = has[k] && d > 0.0f;
        drop_sum += lower ? d : 0.0f;
        lower_n += lower ? 1.0f : 0.0f;
    }
    // Olsen's two cases: level out (move a − ā, ā the mean altitude of the
    // cell and its n lower neighbours) or drain completely (move w). Since
    // a − ā = (n·a − Σ a_k)/(1 + n) = Σ (a − a_k)/(1 + n) = D/(1 + n)
    // (D = drop_sum), no sum of altitudes is needed. The water moved per
    // metre of drop is F = min(w, D/(1 + n))/D = w/max(D, w·(1 + n)) and the
    // sediment G = F·s/w = s/max(D, w·(1 + n)): one division per cell. Where
    // nothing flows (D = 0 or w = 0) F = G = 0.
    const float m = std::max(drop_sum, w * (1.0f + lower_n));
    const float inv = 1.0f / std::max(m, 1e-30f);
    const bool flows = drop_sum > 0.0f && w > 0.0f;
    const float f = flows ? w * inv : 0.0f;
    const float g = flows ? s * inv : 0.0f;
    return {f, g, w - f * drop_sum, s - g * drop_sum};
}

OROGEN_HYDRAULIC_CLONES void factor_row(const PrepRow* up, const PrepRow& c, const PrepRow* dn, int w,
                                        const FactorRow& out) {
    auto edge = [&](int x) {
        const float an[4] = {x > 0 ? c.a[x - 1] : 0.0f, x + 1 < w ? c.a[x + 1] : 0.0f, up ? up->a[x] : 0.0f,
                             dn ? dn->a[x] : 0.0f};
        const bool has[4] = {x > 0, x + 1 < w, up != nullptr, dn != nullptr};
        const Factors k = factor_cell(c.a[x], c.w[x], c.s[x], an, has);
        out.f[x] = k.f;
        out.g[x] = k.g;
        out.wr[x] = k.wr;
        out.sr[x] = k.sr;
    };
    if (!up || !dn || w < 3) {
        for (int x = 0; x < w; ++x) edge(x);
        return;
    }
    const float* __restrict a = c.a;
    const float* __restrict au = up->a;
    const float* __restrict ad = dn->a;
    const float* __restrict wc = c.w;
    const float* __restrict sc = c.s;
    float* __restrict f = out.f;
    float* __restrict g = out.g;
    float* __restrict wr = out.wr;
    float* __restrict sr = out.sr;
    constexpr bool all[4] = {true, true, true, true};
    // Whole vectors only (see padded_end); the edges after, over the junk.
    const int xe = padded_end(w);
#pragma GCC ivdep
    for (int x = 1; x < xe; ++x) {
        const float an[4] = {a[x - 1], a[x + 1], au[x], ad[x]};
        const Factors k = factor_cell(a[x], wc[x], sc[x], an, all);
        f[x] = k.f;
        g[x] = k.g;
        wr[x] = k.wr;
        sr[x] = k.sr;
    }
    edge(0);
    edge(w - 1);
}

// ----------------------------------------------- step 3 gather + step 4

/// A cell's four neighbours (left, right, up, down): altitudes and flow factors.
struct Neighbours {
    float a[4], f[4], g[4];
};
/// A cell's new terrain, water and sediment.
struct Cell {
    float h, w, s;
};

/// One cell's new state: what it kept after its own outflow (wr, sr), its
/// neighbours' inflow, then evaporation.
inline Cell output_cell(const Rule& r, float a, float h1, float wr, float sr, const Neighbours& n,
                        const bool (&has)[4]) {
    const float(&an)[4] = n.a;
    const float(&fn)[4] = n.f;
    const float(&gn)[4] = n.g;
    float w_in = 0.0f, s_in = 0.0f;
    for (int k = 0; k < 4; ++k) {
        const float e = an[k] - a;  // drop from neighbour k (receiving): the giver's own drop
        const bool take = has[k] && e > 0.0f;
        w_in += take ? fn[k] * e : 0.0f;
        s_in += take ? gn[k] * e : 0.0f;
    }
    // Round-off can leave a drained cell at −1e-9 m: clamp, so that capacity
    // never turns negative (the water lost is far below float resolution of the total).
    const float w2 = std::max((wr + w_in) * r.keep, 0.0f);
    const float s2 = sr + s_in;
    const float excess = std::max(s2 - r.capacity * w2, 0.0f);  // deposited where water cannot hold it
    return {h1 + excess, w2, s2 - excess};
}

/// Rows y − 1, y and y + 1 of both stages (up and down nullptr outside the grid).
struct Stencil {
    const PrepRow* up;
    const FactorRow* fup;
    const PrepRow* c;
    const FactorRow* fc;
    const PrepRow* dn;
    const FactorRow* fdn;
};
/// An output row: terrain, water, sediment.
struct OutRow {
    float *h, *w, *s;
};

OROGEN_HYDRAULIC_CLONES void output_row(const Rule& r, const Stencil& rows, int w, const OutRow& out) {
    const PrepRow* up = rows.up;
    const FactorRow* fup = rows.fup;
    const PrepRow& c = *rows.c;
    const FactorRow& fc = *rows.fc;
    const PrepRow* dn = rows.dn;
    const FactorRow* fdn = rows.fdn;
    float* __restrict ho = out.h;
    float* __restrict wo = out.w;
    float* __restrict so = out.s;
    auto edge = [&](int x) {
        const bool has[4] = {x > 0, x + 1 < w, up != nullptr, dn != nullptr};
        const int xl = has[0] ? x - 1 : x, xr = has[1] ? x + 1 : x;
        const Neighbours n = {{c.a[xl], c.a[xr], up ? up->a[x] : 0.0f, dn ? dn->a[x] : 0.0f},
                              {fc.f[xl], fc.f[xr], fup ? fup->f[x] : 0.0f, fdn ? fdn->f[x] : 0.0f},
                              {fc.g[xl], fc.g[xr], fup ? fup->g[x] : 0.0f, fdn ? fdn->g[x] : 0.0f}};
        const Cell k = output_cell(r, c.a[x], c.h[x], fc.wr[x], fc.sr[x], n, has);
        ho[x] = k.h;
        wo[x] = k.w;
        so[x] = k.s;
    };
    if (!up || !dn || w < 3) {
        for (int x = 0; x < w; ++x) edge(x);
        return;
    }
    const float* __restrict a = c.a;
    const float* __restrict au = up->a;
    const float* __restrict ad = dn->a;
    const float* __restrict f = fc.f;
    const float* __restrict fu = fup->f;
    const float* __restrict fd = fdn->f;
    const float* __restrict g = fc.g;
    const float* __restrict gu = fup->g;
    const float* __restrict gd = fdn->g;
    constexpr bool all[4] = {true, true, true, true};
    const int xe = padded_end(w);
#pragma GCC ivdep
    for (int x = 1; x < xe; ++x) {
        const Neighbours n = {
            {a[x - 1], a[x + 1], au[x], ad[x]}, {f[x - 1], f[x + 1], fu[x], fd[x]}, {g[x - 1], g[x + 1], gu[x], gd[x]}};
        const Cell k = output_cell(r, a[x], c.h[x], fc.wr[x], fc.sr[x], n, all);
        ho[x] = k.h;
        wo[x] = k.w;
        so[x] = k.s;
    }
    edge(0);
    edge(w - 1);
}

template <Hardness H>
void step_impl(const ConstState& in, const State& out, const Rule& r) {
    const int w = in.height.width, rows = in.height.height;
    // Rows in parallel; each chunk recomputes its halo rows (two rows of the
    // rain/dissolve stage, one of the flow factors). Every row is the same
    // pure function of `in` wherever it is computed: chunking cannot change
    // the result.
    const std::int64_t grain = std::max<std::int64_t>(32, rows / 8);
    parallel_for(0, rows, grain, [&](std::int64_t y0, std::int64_t y1) {
        FlushDenormals ftz;
        // Rings of rows: 4 of the rain/dissolve stage (output row y needs
        // y − 1 … y + 1 while the factors of y + 1 need y … y + 2) and 3 of
        // the factors; plus one row of output, copied to the grids whole (the
        // output loop then stores only to cache-resident, 4K-spaced rows; the
        // three grids are usually n floats apart and alias each other and the
        // input rows read next; memcpy also streams the copy fastest).
        constexpr int kPrep = 4, kFactor = 3, kArrays = 4 * kPrep + 4 * kFactor + 3;
        // Every slot is written before it is read, but for the padding past
        // w (zeroed once, then junk; see padded_end). Each row
        // array starts one float before a 64-byte boundary (the vector loops
        // run from x = 1, so their loads at x and their stores are aligned),
        // and the arrays are 128 bytes apart modulo 4 KiB, so no two of them
        // alias in the low 12 address bits (a load stalls behind an unrelated
        // store whose address matches there: "4K aliasing").
        std::size_t stride = (std::size_t(padded_end(w)) + 16) / 16 * 16;
        stride += (32 + 1024 - stride % 1024) % 1024;
        std::unique_ptr<float[]> storage(new float[stride * kArrays + 16]);
        float* p = storage.get();
        p += (64 - (reinterpret_cast<std::uintptr_t>(p + 1) & 63)) / sizeof(float) % 16;
        for (int k = 0; k < kArrays; ++k) std::fill(p + k * stride + w, p + (k + 1) * stride, 0.0f);
        PrepRow prep[kPrep];
        FactorRow fac[kFactor];
        for (auto& row : prep) {
            row = {p, p + stride, p + 2 * stride, p + 3 * stride};
            p += 4 * stride;
        }
        for (auto& row : fac) {
            row = {p, p + stride, p + 2 * stride, p + 3 * stride};
            p += 4 * stride;
        }
        float* const ho = p;
        float* const wo = p + stride;
        float* const so = p + 2 * stride;
        auto prep_at = [&](std::int64_t y) -> PrepRow& { return prep[y % kPrep]; };
        auto fac_at = [&](std::int64_t y) -> FactorRow& { return fac[y % kFactor]; };
        std::int64_t next_prep = std::max<std::int64_t>(0, y0 - 2);
        std::int64_t next_factor = std::max<std::int64_t>(0, y0 - 1);
        const std::size_t bytes = std::size_t(w) * sizeof(float);
        for (std::int64_t y = y0; y < y1; ++y) {
            const std::int64_t last_prep = std::min<std::int64_t>(rows - 1, y + 2);
            const std::int64_t last_factor = std::min<std::int64_t>(rows - 1, y + 1);
            while (next_prep <= last_prep || next_factor <= last_factor) {
                // The factors of row fy as soon as rows fy − 1 … fy + 1 are
                // ready (so that 4 rows of the first stage suffice).
                const std::int64_t fy = next_factor;
                if (fy <= last_factor && next_prep > std::min<std::int64_t>(rows - 1, fy + 1)) {
                    factor_row(fy > 0 ? &prep_at(fy - 1) : nullptr, prep_at(fy),
                               fy + 1 < rows ? &prep_at(fy + 1) : nullptr, w, fac_at(fy));
                    ++next_factor;
                } else {
                    prep_row<H>(in, r, int(next_prep), prep_at(next_prep));
                    ++next_prep;
                }
            }
            const bool has_up = y > 0, has_dn = y + 1 < rows;
            const Stencil rows3{
                has_up ? &prep_at(y - 1) : nullptr, has_up ? &fac_at(y - 1) : nullptr, &prep_at(y), &fac_at(y),
                has_dn ? &prep_at(y + 1) : nullptr, has_dn ? &fac_at(y + 1) : nullptr};
            output_row(r, rows3, w, {ho, wo, so});
            std::memcpy(out.height.row(int(y)), ho, bytes);
            std::memcpy(out.water.row(int(y)), wo, bytes);
            std::memcpy(out.sediment.row(int(y)), so, bytes);
        }
    });
}

Rule make_rule(const Settings& settings, const float* hardness, double cell) {
    return Rule{float(settings.rain),     float(settings.solubility), float(1.0 - settings.evaporation),
                float(settings.capacity), settings.hardness,          hardness,
                float(1.0 / cell)};
}

/// Calls f.template operator()<H>() with the hardness mode H fixed at compile time.
template <class F>
void with_hardness(Hardness hardness, F&& f) {
    switch (hardness) {
        case Hardness::steepness: f.template operator()<Hardness::steepness>(); break;
        case Hardness::constant: f.template operator()<Hardness::constant>(); break;
        case Hardness::layer: f.template operator()<Hardness::layer>(); break;
    }
}

template <Hardness H>
void outflow_impl(const ConstState& in, const Rule& r, GridView flow) {
    const int w = in.height.width, rows = in.height.height;
    parallel_for(0, rows, std::max<std::int64_t>(32, rows / 8), [&](std::int64_t y0, std::int64_t y1) {
        FlushDenormals ftz;
        // Rows as step_impl's (padded, tails zeroed): 3 of the first stage, 1 of factors.
        const std::size_t stride = (std::size_t(padded_end(w)) + 16) / 16 * 16 + 32;
        std::vector<float> storage(stride * (4 * 3 + 4), 0.0f);
        float* p = storage.data();
        PrepRow prep[3];
        for (auto& row : prep) {
            row = {p, p + stride, p + 2 * stride, p + 3 * stride};
            p += 4 * stride;
        }
        const FactorRow fac{p, p + stride, p + 2 * stride, p + 3 * stride};
        auto prep_at = [&](std::int64_t y) -> PrepRow& { return prep[y % 3]; };
        // Water leaving row c: what a cell has after rain and dissolving
        // minus what it keeps after its own outflow.
        auto emit = [&](std::int64_t c) {
            factor_row(c > 0 ? &prep_at(c - 1) : nullptr, prep_at(c), c + 1 < rows ? &prep_at(c + 1) : nullptr, w, fac);
            float* out = flow.row(int(c));
            for (int x = 0; x < w; ++x) out[x] = prep_at(c).w[x] - fac.wr[x];
        };
        for (std::int64_t y = std::max<std::int64_t>(0, y0 - 1); y < std::min<std::int64_t>(rows, y1 + 1); ++y) {
            prep_row<H>(in, r, int(y), prep_at(y));
            if (y - 1 >= y0 && y - 1 < y1) emit(y - 1);  // row y − 1 has both neighbours now
        }
        if (y1 == rows) emit(rows - 1);  // the last row has no lower neighbour
    });
}

}  // namespace

void outflow(const ConstState& in, const Settings& settings, const float* hardness, GridView flow) {
    const int w = in.height.width, h = in.height.height;
    for (ConstGridView v : {in.water, in.sediment, ConstGridView(flow)})
        if (v.width != w || v.height != h) throw Error("hydraulic::outflow: grids differ in size");
    if (settings.hardness == Hardness::layer && hardness == nullptr)
        throw Error("hydraulic::outflow: hardness layer mode needs a hardness layer");
    const Rule r = make_rule(settings, hardness, in.height.cell);
    with_hardness(settings.hardness, [&]<Hardness H>() { outflow_impl<H>(in, r, flow); });
}

void steepness_hardness(ConstGridView height, GridView out) {
    const float inv_cell = float(1.0 / height.cell);
    for (int y = 0; y < height.height; ++y)
        for (int x = 0; x < height.width; ++x) {
            float gx, gy;
            slope_at(height, inv_cell, x, y, gx, gy);
            out.row(y)[x] = 1.0f - softness<Hardness::steepness>(gx, gy, nullptr, x);
        }
}

void step(const ConstState& in, const State& out, const Settings& settings, const float* hardness) {
    const int w = in.height.width, h = in.height.height;
    for (ConstGridView v :
         {in.water, in.sediment, ConstGridView(out.height), ConstGridView(out.water), ConstGridView(out.sediment)})
        if (v.width != w || v.height != h) throw Error("hydraulic::step: state grids differ in size");
    if (settings.hardness == Hardness::layer && hardness == nullptr)
        throw Error("hydraulic::step: hardness layer mode needs a hardness layer");
    const Rule r = make_rule(settings, hardness, in.height.cell);
    with_hardness(settings.hardness, [&]<Hardness H>() { step_impl<H>(in, out, r); });
}

void erode(const State& state, std::int64_t iterations, const Settings& settings, const float* hardness,
           const std::function<void(std::int64_t, const ConstState&)>& on_step) {
    if (iterations <= 0) return;
    const std::size_t n = state.height.size();
    std::vector<float> scratch(3 * n);
    const int w = state.height.width, h = state.height.height;
    const double cell = state.height.cell;
    State a = state;
    State b{{scratch.data(), w, h, cell}, {scratch.data() + n, w, h, cell}, {scratch.data() + 2 * n, w, h, cell}};
    for (std::int64_t i = 1; i <= iterations; ++i) {
        step({a.height, a.water, a.sediment}, b, settings, hardness);
        std::swap(a, b);
        if (on_step) on_step(i, {a.height, a.water, a.sediment});
    }
    if (a.height.data != state.height.data) {
        std::memcpy(state.height.data, a.height.data, n * sizeof(float));
        std::memcpy(state.water.data, a.water.data, n * sizeof(float));
        std::memcpy(state.sediment.data, a.sediment.data, n * sizeof(float));
    }
}

}  // namespace orogen::hydraulic
