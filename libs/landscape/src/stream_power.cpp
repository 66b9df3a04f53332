// stream_power.cpp — the implicit stream-power model (see stream_power.hpp).
#include <orogen/landscape/stream_power.hpp>

#include <orogen/solvers/threshold_slopes.hpp>

#include <orogen/parallel.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>

namespace orogen::landscape {

namespace {

/// Deposition: iterations in which a cell may start incising again; after them the set of
/// incising cells only shrinks, so the solve ends.
constexpr int kFlips = 20;

}  // namespace

std::int64_t lowest_cell(const std::vector<double>& heights) {
    std::int64_t best = 0;
    for (std::size_t i = 1; i < heights.size(); ++i)
        if (heights[i] < heights[std::size_t(best)]) best = std::int64_t(i);
    return best;
}

Model::Model(int width, int height, double cell, std::vector<double> heights, std::vector<double> uplift,
             const Settings& settings)
    : width_(width), height_(height), cell_(cell), settings_(settings), h_(std::move(heights)),
      uplift_(std::move(uplift)), flow_(width, height, cell, settings.open, settings.open.any() ? 0 : lowest_cell(h_)) {
    if (h_.size() != flow_.size()) throw std::invalid_argument("landscape::Model: heights are not width × height");
    if (settings.orographic_rain && !(settings.rain.background > 0.0))
        throw std::invalid_argument("landscape::Model: orographic rain needs a background rain > 0");
    if (settings.mfd_exponent > 0.0 && settings.depressions != Depressions::fill)
        throw std::invalid_argument("landscape::Model: multiple flow directions need Depressions::fill");
    if (!uplift_.empty() && uplift_.size() != h_.size())
        throw std::invalid_argument("landscape::Model: uplift is not width × height");
    pow_table_ = area_power_table(cell, settings.area_exponent, inverse_channel_area(settings));
    uplifted_.assign(h_.size(), 0.0);
    if (settings.diffusivity > 0.0)
        diffusion_ = std::make_unique<solvers::diffusion::Solver>(width, height, cell, hillslope_settings(settings));
}

std::vector<double> area_power_table(double cell, double m, double inv_ac) {
    std::vector<double> t(static_cast<std::size_t>(kPowTable));
    for (std::int64_t c = 0; c < kPowTable; ++c)
        t[std::size_t(c)] = channel_area_power(double(c) * (cell * cell), m, inv_ac);
    return t;
}

solvers::diffusion::Settings hillslope_settings(const Settings& settings) {
    solvers::diffusion::Settings ds;
    ds.diffusivity = settings.diffusivity;
    ds.scheme = solvers::diffusion::Scheme::implicit;
    ds.fixed = {settings.open.north, settings.open.east, settings.open.south, settings.open.west};
    return ds;
}

void check_history(const UpliftHistory& history) {
    for (std::size_t k = 1; k < history.times.size(); ++k)
        if (!(history.times[k] > history.times[k - 1]))
            throw std::invalid_argument("stream_power: uplift history times must increase");
}

void Model::set_uplift_history(UpliftHistory history) {
    check_history(history);
    history_ = std::move(history);
    history_k_ = std::size_t(-1);
}

void add_uplift(const double* rate, const std::uint8_t* outlets, double years, double* h, double* uplifted,
                std::int64_t n) {
    parallel_for(0, n, 1 << 15, [&](std::int64_t b, std::int64_t e) {
        // A select, not a branch: the compiler can vectorise it (an outlet keeps its bits).
        const double* __restrict const r = rate;
        const std::uint8_t* __restrict const o = outlets;
        double* __restrict const hh = h;
        double* __restrict const up = uplifted;
        for (std::int64_t i = b; i < e; ++i) {
            const double add = r[i] * years;
            const std::uint64_t lift = std::uint64_t(0) - std::uint64_t(o[i] == 0);  // all ones: not an outlet
            const auto pick = [lift](double lifted, double kept) {
                return std::bit_cast<double>((std::bit_cast<std::uint64_t>(lifted) & lift) |
                                             (std::bit_cast<std::uint64_t>(kept) & ~lift));
            };
            hh[i] = pick(hh[i] + add, hh[i]);
            up[i] = pick(up[i] + add, up[i]);
        }
    });
}

void Model::add_history_uplift(double t0, double t1) {
    for_history_intervals(
        history_, history_k_, history_rate_, h_.size(), t0, t1, [&](const double* rate, double overlap) {
            add_uplift(rate, flow_.outlets().data(), overlap, h_.data(), uplifted_.data(), std::int64_t(h_.size()));
        });
}

void Model::route_only() {
    if (settings_.orographic_rain && rain_weight_.empty()) update_rain();
    std::vector<double> copy = h_;  // routing may fill lakes: keep the model's heights as they are
    flow_.route(copy.data(), settings_.depressions);
    accumulate(copy.data());
}

void Model::accumulate(const double* routed) {
    const double* weight = rain_weight_.empty() ? nullptr : rain_weight_.data();
    if (settings_.mfd_exponent > 0.0) flow_.accumulate_multiple(routed, settings_.mfd_exponent, weight);
    else flow_.accumulate(weight);
}

void Model::update_rain() {
    // Only the weights are kept (rain() multiplies back): one array of the grid's size, reused each step.
    climate::orographic_rain_coarse(h_.data(), width_, height_, cell_, settings_.rain, settings_.rain_resolution,
                                    rain_weight_, &rain_transfer_);
    rain_to_weights(rain_weight_, settings_.rain.background);
}

std::vector<double> Model::rain() const { return weights_to_rain(rain_weight_, settings_.rain.background); }

std::int64_t Model::step(double dt) {
    const std::size_t n = h_.size();
    double* h = h_.data();
    const int subs = std::max(1, settings_.substeps);
    const double sub = dt / subs;  // yr: each sub-step's uplift, creep, incision and landslides
    // 1. Uplift (outlets are base level: they stay): the first sub-step's, then the rest between incisions.
    // The constant rate's share is rate·length (for one sub-step, dt / 1 = dt exactly: the same bits as ever).
    auto uplift = [&](double t0, double t1, double length) {
        if (!uplift_.empty())
            add_uplift(uplift_.data(), flow_.outlets().data(), length, h, uplifted_.data(), std::int64_t(n));
        if (history_.rate) add_history_uplift(t0, t1);
    };
    uplift(time_, time_ + sub, sub);
    // 2. The rain on the uplifted relief; routing, depressions, drainage area (weighted by the rain).
    if (settings_.orographic_rain) update_rain();
    flow_.route(h, settings_.depressions);
    accumulate(h);
    const std::int64_t pits = flow_.pits();
    for (int k = 0; k < subs; ++k) {
        if (k > 0) uplift(time_ + k * sub, k + 1 == subs ? time_ + dt : time_ + (k + 1) * sub, sub);
        // 3. Hillslope diffusion, before the incision and after the routing: the
        // implicit incision then leaves every eroded cell strictly above its
        // receiver, so the next step's routing finds (almost) no pits. Diffusion
        // after the incision raises valley floors unevenly and left 450–700 pits a
        // step at 1025² (20,000 at 4097²), each paid for by a local flood, the
        // basin graph and a second stack walk. Both orders are first-order
        // splittings of the same equation; this one uses the step's flow graph
        // for the diffused heights, as the incision uses it for the uplifted ones.
        if (diffusion_) {
            std::vector<std::pair<std::int64_t, double>> sink;
            if (!settings_.open.any())
                for (std::size_t i = 0; i < n; ++i)
                    if (flow_.is_outlet(std::int64_t(i))) sink.emplace_back(std::int64_t(i), h[i]);
            diffusion_->step(h, sub);
            for (const auto& [i, v] : sink) h[i] = v;  // the declared sink stays at base level
        }
        // 4. Implicit incision (and deposition), in the rock each cell shows now, by rivers and glaciers.
        const CellBlock grid{n, width_, 0, 0, cell_};
        if (bed_offset_.empty()) bed_offsets(settings_.rock, grid, bed_offset_);
        rock_at(settings_.rock, grid, {h, uplifted_.data(), bed_offset_.data()}, rock_slopes_, rock_k_, &rock_memo_);
        if (settings_.glaciers.any()) glacial_factors(sub);
        if (settings_.banks.any()) bank_before_.assign(h_.begin(), h_.end());
        if (settings_.deposition > 0.0) incise_with_deposition(sub);
        else incise(sub);
        if (settings_.banks.any()) erode_banks();
        if (settings_.floodplain.any()) {
            if (!settings_.banks.any()) {  // erode_banks fills the directions when the banks run
                bank_dir_.resize(n);
                for (std::size_t i = 0; i < n; ++i) bank_dir_[i] = std::int8_t(flow_.direction(std::int64_t(i)));
            }
            carve_floodplains(settings_.floodplain, width_, height_, cell_,
                              {bank_dir_.data(), flow_.area().data(), flow_.outlets().data()}, h, floodplain_nearest_,
                              floodplain_floor_);
        }
        if (settings_.glaciers.any())
            carve_troughs(settings_.glaciers, h, ice_, flow_.receivers().data(), width_, height_, cell_);
        // 5. Landslides: what the incision left steeper than the threshold slides away (outlets stay).
        if (settings_.rock.angle > 0.0)
            solvers::threshold::limit_slopes(
                h, width_, height_, cell_,
                {settings_.rock.landslide_slope(0.5), rock_slopes_.empty() ? nullptr : rock_slopes_.data()},
                flow_.outlets().data(), nullptr, &slope_scratch_);
    }
    time_ += dt;
    return pits;
}

void Model::erode_banks() {
    const std::size_t n = h_.size();
    bank_dir_.resize(n);
    // The lowering by this incision goes into bank_before_ (no more use for the old heights).
    parallel_for(0, std::int64_t(n), 1 << 15, [&](std::int64_t b, std::int64_t e) {
        for (std::int64_t i = b; i < e; ++i) {
            bank_before_[std::size_t(i)] = std::max(0.0, bank_before_[std::size_t(i)] - h_[std::size_t(i)]);
            bank_dir_[std::size_t(i)] = std::int8_t(flow_.direction(i));
        }
    });
    banks_.erode(settings_.banks, width_, height_, cell_,
                 {bank_dir_.data(), flow_.area().data(), flow_.outlets().data()}, bank_before_.data(), h_.data());
}

void Model::glacial_factors(double dt) {
    const Glaciers& g = settings_.glaciers;
    const std::size_t n = h_.size();
    landscape::ice_flux(g, h_.data(), flow_.stack().data(), flow_.receivers().data(), n, cell_, ice_);
    ice_f_.assign(n, 0.0);
    const double ns = settings_.slope_exponent;
    parallel_for(0, std::int64_t(n), 1 << 14, [&](std::int64_t b, std::int64_t e) {
        for (std::int64_t i = b; i < e; ++i)
            if (ice_[std::size_t(i)] >= g.glacier_flux && flow_.receivers()[std::size_t(i)] != std::int32_t(i))
                ice_f_[std::size_t(i)] = g.erodibility * dt * std::pow(ice_[std::size_t(i)], g.flux_exponent) /
                    std::pow(flow_.distance(i), ns);  // a glacier, not at an outlet or pit
    });
}

void incise(const Incision& in, double dt, double* h) {
    const double K = in.erodibility, m = in.area_exponent, ns = in.slope_exponent;
    const double cell = in.cell;
    const double a0 = cell * cell;
    const double* area = in.area;
    const std::int32_t* rcv = in.receivers;
    // F = K·dt·A^m / L^n, computed where it is used (one pass over the stack,
    // no per-cell array written and read back) and only for cells that erode.
    // A^m comes from a table when A is a whole number c of cells below 2^16
    // (c·cell² == A exactly, so the table's pow(c·cell², m) is pow(A, m)):
    // the pow is the costly part, and most cells drain few cells.
    const double* tab = in.pow_table;
    const double inv_a0 = 1.0 / a0;
    const double kdt_l1 = K * dt / std::pow(cell, ns), kdt_l2 = K * dt / std::pow(cell * kSqrt2, ns);
    const std::int64_t W = in.width;
    const std::int32_t* stack = in.stack;
    const std::span<const std::int64_t> chunks = in.chunks;
    // Outlet basins exchange nothing: each group of them is solved by one thread, in stack order.
    parallel_for(0, std::int64_t(chunks.size()) - 1, 1, [&](std::int64_t g0, std::int64_t g1) {
        // Local copies: the stores to h must not make the compiler reload them.
        const double* __restrict const ar = area;
        const double* __restrict const tb = tab;
        const std::int32_t* __restrict const rv = rcv;
        const std::int32_t* __restrict const st = stack;
        double* __restrict const hh = h;
        const double* __restrict const kf = in.rock_k;
        const double* __restrict const gf = in.ice_f;
        const double c1 = kdt_l1, c2 = kdt_l2, ia0 = inv_a0, a00 = a0, mm = m, iac = in.inv_channel_area;
        const std::int64_t w = W;
        auto factor = [=](std::int32_t i, std::int32_t r) {
            const double am = area_power(ar[i], tb, ia0, a00, mm, iac);
            const std::int64_t d = std::int64_t(r) - i;
            const double f = am * ((d == 1 || d == -1 || d == w || d == -w) ? c1 : c2);
            const double fk = kf ? f * kf[i] : f;
            return gf ? fk + gf[i] : fk;
        };
        for (std::int64_t g = g0; g < g1; ++g) {
            const std::int64_t b = chunks[std::size_t(g)], e = chunks[std::size_t(g + 1)];
            if (ns == 1.0) {
                for (std::int64_t s = b; s < e; ++s) {
                    const std::int32_t i = st[s], r = rv[i];
                    const double hr = hh[r], hi = hh[i];
                    if (r == i || hi <= hr) continue;
                    // h' = (h + F·h_r')/(1 + F), written as h_r' + (h − h_r')·w with
                    // w = 1/(1 + F): the division does not wait for the receiver's new
                    // height, so the chain from one cell to its donor (the next cell,
                    // mostly) is a subtraction, a product and a sum.
                    const double wt = 1.0 / (1.0 + factor(i, r));
                    hh[i] = hr + (hi - hr) * wt;
                }
                continue;
            }
            for (std::int64_t s = b; s < e; ++s) {
                const std::int32_t i = st[s], r = rv[i];
                const double hr = hh[r], hi = hh[i];
                if (r == i || hi <= hr) continue;
                hh[i] = hr + incised_drop(hi - hr, factor(i, r), ns);
            }
        }
    });
}

void Model::incise(double dt) { landscape::incise(incision(), dt, h_.data()); }

Incision Model::incision() const {
    Incision in;
    in.width = width_;
    in.cell = cell_;
    in.erodibility = settings_.erodibility;
    in.area_exponent = settings_.area_exponent;
    in.slope_exponent = settings_.slope_exponent;
    in.inv_channel_area = inverse_channel_area(settings_);
    in.pow_table = pow_table_.data();
    in.area = flow_.area().data();
    in.receivers = flow_.receivers().data();
    in.stack = flow_.stack().data();
    in.chunks = flow_.chunks();
    in.rock_k = rock_k_.empty() ? nullptr : rock_k_.data();
    in.ice_f = ice_f_.empty() ? nullptr : ice_f_.data();
    return in;
}

// Incision with deposition (Yuan et al. 2019), each cell i with receiver r:
//
//     h_i' = h_i* − e_i,   e_i = K·dt·A_i^m·((h_i' − h_r')/L)^n − (G/A_i)·V_i,
//     V_i = a·e_i + Σ_donors d V_d                         (m³ over the step)
//
// h* the uplifted, diffused height, e the net lowering (m), a = cell² the
// cell's own area and A_i = a + Σ A_d its area over the receiver tree (the
// D8 area; with routing=mfd the tree's area, so that V/A is the tree's mean
// lowering). For n = 1 the system is linear and, on a tree, solved exactly in
// two passes: upstream first (reverse stack), every subtree's sediment flux is
// an affine function of its receiver's new height, V_d = α_d + β_d·h_r'
// (induction: a cell's donors give Σα + Σβ·h_i', which with its own equation
// gives h_i' = p_i + q_i·h_r' and then α_i, β_i); then downstream first
// (stack order) h_i' = p_i + q_i·h_r'. With D = 1 + F + (G/A)(a − Σβ):
//
//     p = (h*(1 + G·a/A) + (G/A)·Σα − c)/D,  q = F/D,  α = a·h* + Σα + (Σβ − a)·p,  β = (Σβ − a)·q,
//
// F = K·dt·A^m/L (c = 0). Σβ ≤ 0, so D > 1 + F: the elimination cannot
// divide by zero and is stable at any dt, as the detachment-limited scheme.
// For n ≠ 1 the erosion term is linearised about the last iterate x₀ of
// h_i' − h_r' (n > 1: Newton's method on the whole tree, F → F·n·x₀^(n−1),
// c = F·(1 − n)·x₀^n; n < 1: the chord, F → F·x₀^(n−1), c = 0, a contraction
// that keeps x > 0) and the two passes repeat until no height moves by
// more than 1e-12 of the relief. A cell incises only if it ends above its
// receiver (a lake, a dammed reach still receives deposition): one whose
// solution falls to or below its receiver stops incising, one that rises
// above starts, and the chunk is solved again; after kFlips passes cells may
// only stop, so the solve ends. What reaches
// an outlet leaves the map: sediment_out(). Each outlet basin is solved on
// its own, in a fixed order, so the result does not depend on the threads.
Deposited incise_with_deposition(const Incision& in, double deposition, bool d8, double dt, double* h, std::size_t n,
                                 DepositionScratch& scratch) {
    const double K = in.erodibility, m = in.area_exponent, ns = in.slope_exponent;
    const double G = deposition;
    const double cell = in.cell;
    const double a0 = cell * cell;
    // (References, not a structured binding: lambdas capture these, which clang 14 refuses for bindings.)
    std::vector<double>&dep_hs = scratch.hs, &dep_p = scratch.pq, &dep_sa = scratch.sums, &dep_tree = scratch.tree,
    &dep_x = scratch.x, &chunk_out = scratch.chunk_out;
    std::vector<std::int32_t>& dep_pos = scratch.pos;
    std::vector<std::uint8_t>& dep_active = scratch.active;
    std::vector<int>& chunk_passes = scratch.chunk_passes;
    if (dep_hs.size() != n) {
        for (auto* v : {&dep_hs, &dep_tree, &dep_x}) v->assign(n, 0.0);
        dep_pos.assign(n, 0);
        dep_p.assign(2 * n, 0.0);  // p, q pairs
        dep_sa.assign(2 * n, 0.0);  // Σα, Σβ pairs
        dep_active.assign(n, 0);
    }
    const double* area = in.area;
    const std::int32_t* rcv = in.receivers;
    const std::int32_t* stack = in.stack;
    const std::span<const std::int64_t> chunks = in.chunks;
    const std::int64_t W = in.width;
    const double kdt_l1 = K * dt / std::pow(cell, ns), kdt_l2 = K * dt / std::pow(cell * kSqrt2, ns);
    const std::int64_t groups = std::int64_t(chunks.size()) - 1;
    // A^m from the table for whole numbers of cells (as incise() does: the pow is the costly part).
    const double* tab = in.pow_table;
    const double inv_a0 = 1.0 / a0;
    const double inv_ac = in.inv_channel_area;
    auto area_pow = [=](double a) { return area_power(a, tab, inv_a0, a0, m, inv_ac); };
    const double* rock_k = in.rock_k;
    // With D8 the tree's area is the drainage area; with MFD it is summed over the tree.
    chunk_out.assign(std::size_t(std::max<std::int64_t>(groups, 0)), 0.0);
    chunk_passes.assign(chunk_out.size(), 0);
    parallel_for(0, groups, 1, [&](std::int64_t g0, std::int64_t g1) {
        // Scratch indexed by stack position, so that the passes read and write it in order; only
        // the receiver's sums (and its position) are reached by a jump.
        double* hs = dep_hs.data();
        auto* pq = reinterpret_cast<double(*)[2]>(dep_p.data());  // p, q
        auto* sum = reinterpret_cast<double(*)[2]>(dep_sa.data());  // Σα, Σβ of the donors
        double* tree = dep_tree.data();
        double* xp = dep_x.data();
        std::int32_t* pos = dep_pos.data();  // stack position of each cell
        std::uint8_t* act = dep_active.data();
        for (std::int64_t g = g0; g < g1; ++g) {
            const std::int64_t b = chunks[std::size_t(g)], e = chunks[std::size_t(g + 1)];
            double lo = 0.0, hi = 0.0;
            for (std::int64_t s = b; s < e; ++s) {
                const std::int32_t i = stack[s], r = rcv[i];
                pos[i] = std::int32_t(s);
                hs[s] = h[i];
                // Every cell but a root starts incising, as in the detachment-limited solver, which
                // skips a cell only once it is at or below its receiver's new height: one that
                // ends there stops incising and the chunk is solved again.
                act[s] = r != i;
                xp[s] = h[i] - h[r];
                sum[s][0] = sum[s][1] = 0.0;
                if (!d8) tree[s] = a0;
                lo = s == b ? h[i] : std::min(lo, h[i]);
                hi = s == b ? h[i] : std::max(hi, h[i]);
            }
            const double tol = 1e-12 * std::max(1.0, hi - lo);
            double out = 0.0;
            int passes = 0;
            for (int iter = 0; iter < 200; ++iter) {
                ++passes;
                if (iter > 0)
                    for (std::int64_t s = b; s < e; ++s) {
                        sum[s][0] = sum[s][1] = 0.0;
                        if (!d8) tree[s] = a0;
                    }
                // Upstream first: p, q of each cell and its flux's α, β handed to its receiver.
                for (std::int64_t s = e - 1; s >= b; --s) {
                    const std::int32_t i = stack[s], r = rcv[i];
                    if (r == i) continue;
                    double F = 0.0, c = 0.0;
                    if (act[s]) {
                        const std::int64_t d = std::int64_t(r) - i;
                        double lin = area_pow(area[i]) * ((d == 1 || d == -1 || d == W || d == -W) ? kdt_l1 : kdt_l2);
                        if (rock_k) lin *= rock_k[std::size_t(i)];  // the bed it cuts
                        if (ns == 1.0) {
                            F = lin;
                        } else if (ns > 1.0) {  // Newton: the tangent of x^n at x0
                            const double x0 = std::max(xp[s], 1e-9 * tol);
                            const double xn1 = std::pow(x0, ns - 1.0);
                            F = lin * ns * xn1;
                            c = lin * (1.0 - ns) * xn1 * x0;
                        } else {
                            // n < 1: x^n is concave with an infinite slope at 0, where Newton's
                            // tangent overshoots past the receiver. The chord from 0 instead
                            // (Picard: F·x0^(n−1)·x) keeps x > 0 and contracts by < 1 − n a pass.
                            F = lin * std::pow(std::max(xp[s], 1e-9 * tol), ns - 1.0);
                        }
                    }
                    const double T = d8 ? area[i] : tree[s], gA = G / T, Sa = sum[s][0], Sb = sum[s][1];
                    const double D = 1.0 + F + gA * (a0 - Sb);
                    const double p = (hs[s] * (1.0 + gA * a0) + gA * Sa - c) / D, q = F / D;
                    pq[s][0] = p;
                    pq[s][1] = q;
                    const std::int32_t rs = pos[r];
                    sum[rs][0] += a0 * hs[s] + Sa + (Sb - a0) * p;
                    sum[rs][1] += (Sb - a0) * q;
                    if (!d8) tree[rs] += T;
                }
                // Downstream first: the new heights; the roots keep theirs and take what flows in.
                out = 0.0;
                bool changed = false;
                double moved = 0.0;
                for (std::int64_t s = b; s < e; ++s) {
                    const std::int32_t i = stack[s], r = rcv[i];
                    if (r == i) {
                        out += sum[s][0] + sum[s][1] * h[i];
                        continue;
                    }
                    h[i] = pq[s][0] + pq[s][1] * h[r];
                    const double x = h[i] - h[r];
                    if (act[s]) {
                        moved = std::max(moved, std::abs(x - xp[s]));
                        xp[s] = x;
                        if (!(x > 0.0)) {
                            act[s] = 0;  // would incise below its receiver: it stops incising
                            changed = true;
                        }
                    } else if (x > 0.0 && iter < kFlips) {
                        act[s] = 1;  // raised above its receiver (deposition, an iterate): it incises
                        xp[s] = x;
                        changed = true;
                    }
                }
                if (!changed && (ns == 1.0 || moved <= tol)) break;
            }
            chunk_out[std::size_t(g)] = out;
            chunk_passes[std::size_t(g)] = passes;
        }
    });
    Deposited result;
    for (double v : chunk_out) result.sediment_out += v;  // chunk order: the same sum on any number of threads
    for (int p : chunk_passes) result.passes = std::max(result.passes, p);
    return result;
}

void Model::incise_with_deposition(double dt) {
    const Deposited d = landscape::incise_with_deposition(
        incision(), settings_.deposition, settings_.mfd_exponent <= 0.0, dt, h_.data(), h_.size(), deposition_);
    sediment_out_ = d.sediment_out;
    deposition_passes_ = d.passes;
}

void Model::run(double years, double dt, const std::function<void(std::int64_t, std::int64_t)>& on_step) {
    if (!(years > 0.0) || !(dt > 0.0)) throw std::invalid_argument("landscape::Model::run: years and dt must be > 0");
    const auto steps = std::int64_t(std::ceil(years / dt * (1.0 - 1e-12)));
    for (std::int64_t s = 1; s <= steps; ++s) {
        const double this_dt = s < steps ? dt : years - dt * double(steps - 1);
        step(this_dt);
        if (on_step) on_step(s, steps);
    }
}

std::vector<double> Model::chi(double a0) const {
    const std::size_t n = h_.size();
    std::vector<double> out(n, 0.0);
    const double p = settings_.area_exponent / settings_.slope_exponent;
    const auto& stack = flow_.stack();
    const auto& rcv = flow_.receivers();
    const auto& area = flow_.area();
    for (std::size_t s = 0; s < n; ++s) {
        const std::int32_t i = stack[s], r = rcv[std::size_t(i)];
        if (r == i) continue;
        out[std::size_t(i)] = out[std::size_t(r)] + std::pow(a0 / area[std::size_t(i)], p) * flow_.distance(i);
    }
    return out;
}

std::int64_t Model::first_non_finite() const {
    for (std::size_t i = 0; i < h_.size(); ++i)
        if (!std::isfinite(h_[i])) return std::int64_t(i);
    return -1;
}

}  // namespace orogen::landscape
