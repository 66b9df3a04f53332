// stream_power.cpp — the implicit stream-power model (see stream_power.hpp).
#include "stream_power.hpp"

#include <orogen/parallel.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace orogen::stream_power {

namespace {

constexpr double kSqrt2 = 1.4142135623730951;
/// A^m for drainage areas of fewer than this many cells comes from a table:
/// areas are exact multiples of cell² (sums of integers), and most cells
/// drain few cells, so the per-cell pow() becomes a lookup.
constexpr std::int64_t kPowTable = 1 << 16;

}  // namespace

std::int64_t lowest_cell(const std::vector<double>& heights) {
    std::int64_t best = 0;
    for (std::size_t i = 1; i < heights.size(); ++i)
        if (heights[i] < heights[std::size_t(best)]) best = std::int64_t(i);
    return best;
}

Model::Model(int width, int height, double cell, std::vector<double> heights, std::vector<double> uplift,
             const Settings& settings)
    : width_(width),
      height_(height),
      cell_(cell),
      settings_(settings),
      h_(std::move(heights)),
      uplift_(std::move(uplift)),
      flow_(width, height, cell, settings.open, settings.open.any() ? 0 : lowest_cell(h_)) {
    if (h_.size() != flow_.size()) throw std::invalid_argument("stream_power::Model: heights are not width × height");
    if (settings.mfd_exponent > 0.0 && settings.depressions != Depressions::fill)
        throw std::invalid_argument("stream_power::Model: multiple flow directions need Depressions::fill");
    if (!uplift_.empty() && uplift_.size() != h_.size())
        throw std::invalid_argument("stream_power::Model: uplift is not width × height");
    pow_table_.resize(std::size_t(kPowTable));
    for (std::int64_t c = 0; c < kPowTable; ++c)
        pow_table_[std::size_t(c)] = std::pow(double(c) * (cell * cell), settings.area_exponent);
    if (settings.diffusivity > 0.0) {
        diffusion::Settings ds;
        ds.diffusivity = settings.diffusivity;
        ds.scheme = diffusion::Scheme::implicit;
        ds.fixed = {settings.open.north, settings.open.east, settings.open.south, settings.open.west};
        diffusion_ = std::make_unique<diffusion::Solver>(width, height, cell, ds);
    }
}

void Model::route_only() {
    std::vector<double> copy = h_;  // routing may fill lakes: keep the model's heights as they are
    flow_.route(copy.data(), settings_.depressions);
    accumulate(copy.data());
}

void Model::accumulate(const double* routed) {
    if (settings_.mfd_exponent > 0.0)
        flow_.accumulate_multiple(routed, settings_.mfd_exponent);
    else
        flow_.accumulate();
}

std::int64_t Model::step(double dt) {
    const std::size_t n = h_.size();
    double* h = h_.data();
    // 1. Uplift (outlets are base level: they stay).
    if (!uplift_.empty()) {
        parallel_for(0, std::int64_t(n), 1 << 15, [&](std::int64_t b, std::int64_t e) {
            for (std::int64_t i = b; i < e; ++i)
                if (!flow_.is_outlet(i)) h[i] += uplift_[std::size_t(i)] * dt;
        });
    }
    // 2. Routing, depressions, drainage area.
    flow_.route(h, settings_.depressions);
    accumulate(h);
    const std::int64_t pits = flow_.pits();
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
        diffusion_->step(h, dt);
        for (const auto& [i, v] : sink) h[i] = v;  // the declared sink stays at base level
    }
    // 4. Implicit incision.
    incise(dt);
    return pits;
}

void Model::incise(double dt) {
    const double K = settings_.erodibility, m = settings_.area_exponent, ns = settings_.slope_exponent;
    const double a0 = cell_ * cell_;
    const double* area = flow_.area().data();
    const std::int32_t* rcv = flow_.receivers().data();
    // F = K·dt·A^m / L^n, computed where it is used (one pass over the stack,
    // no per-cell array written and read back) and only for cells that erode.
    // A^m comes from a table when A is a whole number c of cells below 2^16
    // (c·cell² == A exactly, so the table's pow(c·cell², m) is pow(A, m)):
    // the pow is the costly part, and most cells drain few cells.
    const double* tab = pow_table_.data();
    const double inv_a0 = 1.0 / a0;
    const double kdt_l1 = K * dt / std::pow(cell_, ns), kdt_l2 = K * dt / std::pow(cell_ * kSqrt2, ns);
    const std::int64_t W = width_;
    double* h = h_.data();
    const std::int32_t* stack = flow_.stack().data();
    const auto& chunks = flow_.chunks();
    // Outlet basins exchange nothing: each group of them is solved by one thread, in stack order.
    parallel_for(0, std::int64_t(chunks.size()) - 1, 1, [&](std::int64_t g0, std::int64_t g1) {
        // Local copies: the stores to h must not make the compiler reload them.
        const double* __restrict const ar = area;
        const double* __restrict const tb = tab;
        const std::int32_t* __restrict const rv = rcv;
        const std::int32_t* __restrict const st = stack;
        double* __restrict const hh = h;
        const double c1 = kdt_l1, c2 = kdt_l2, ia0 = inv_a0, a00 = a0, mm = m;
        const std::int64_t w = W;
        auto factor = [=](std::int32_t i, std::int32_t r) {
            const double a = ar[i];
            const double c = a * ia0;
            double am;
            if (c < double(kPowTable - 1)) {
                const auto ci = std::int64_t(c + 0.5);
                am = double(ci) * a00 == a ? tb[ci] : std::pow(a, mm);
            } else {
                am = std::pow(a, mm);
            }
            const std::int64_t d = std::int64_t(r) - i;
            return am * ((d == 1 || d == -1 || d == w || d == -w) ? c1 : c2);
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
                const double F = factor(i, r), delta = hi - hr;
                // x − Δ + F·x^n = 0 for x = h_i' − h_r' in (0, Δ].
                double x = delta;
                for (int it = 0; it < 60; ++it) {
                    const double xn1 = std::pow(x, ns - 1.0);
                    const double gx = x - delta + F * xn1 * x;
                    const double dg = 1.0 + ns * F * xn1;
                    double next = x - gx / dg;
                    if (next <= 0.0) next = 0.5 * x;  // n < 1: the concave residual can overshoot past zero
                    if (next > delta) next = delta;
                    const bool done = std::abs(next - x) <= 1e-12 * delta;
                    x = next;
                    if (done) break;
                }
                hh[i] = hr + x;
            }
        }
    });
}

void Model::run(double years, double dt, const std::function<void(std::int64_t, std::int64_t)>& on_step) {
    if (!(years > 0.0) || !(dt > 0.0)) throw std::invalid_argument("stream_power::Model::run: years and dt must be > 0");
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

}  // namespace orogen::stream_power
