// banks.cpp — lateral erosion of river banks (banks.hpp).
#include <orogen/landscape/banks.hpp>

#include <orogen/landscape/flow.hpp>

#include <orogen/parallel.hpp>

#include <algorithm>
#include <cmath>
#include <type_traits>

namespace orogen::landscape {

namespace {

/// The turn (in 45° steps, 0–4) from direction code `in` to `out`.
constexpr int turn(int in, int out) {
    const int d = ((out - in) % 8 + 8) % 8;
    return std::min(d, 8 - d);
}

/// The share of a river cell's right and left pushes that falls on its edge neighbour at
/// direction 2·e from it, for each direction d it flows towards (row d + 1; row 0, a root, pushes
/// nothing): the whole push on the neighbour across an axis flow ((d + 2) mod 8 right, (d + 6) left),
/// half on each of the two edge neighbours flanking a diagonal flow on that side ((d + 1), (d + 3)
/// right; (d + 5), (d + 7) left).
struct Shares {
    double right[9][4] = {}, left[9][4] = {};
};
constexpr Shares make_shares() {
    Shares s;
    for (int d = 0; d < 8; ++d)
        for (int e = 0; e < 4; ++e) {
            const int back = 2 * e;
            if (d % 2 == 0) {
                s.right[d + 1][e] = back == (d + 2) % 8 ? 1.0 : 0.0;
                s.left[d + 1][e] = back == (d + 6) % 8 ? 1.0 : 0.0;
            } else {
                s.right[d + 1][e] = back == (d + 1) % 8 || back == (d + 3) % 8 ? 0.5 : 0.0;
                s.left[d + 1][e] = back == (d + 5) % 8 || back == (d + 7) % 8 ? 0.5 : 0.0;
            }
        }
    return s;
}
constexpr Shares kShares = make_shares();

/// The share of a river cell's push that falls on its right bank, by the direction its main donor's
/// water comes in (row in + 1; row 0: no donor) and the direction it leaves (`out`): ½ where it runs
/// straight on, else (1 ± b)/2 with b = min(1, ½ per 45° of turn), the outer bank (the one on the side
/// the water comes from: a positive dot product with the incoming direction) taking more. The right
/// bank lies at out + 90°, the left at out − 90° and takes the rest.
struct RightShare {
    double of[9][8] = {};
};
constexpr RightShare make_right_share() {
    RightShare r;
    for (int out = 0; out < 8; ++out) {
        r.of[0][out] = 0.5;
        for (int in = 0; in < 8; ++in) {
            const int t = turn(in, out);
            double w0 = 0.5;
            if (t > 0) {
                const double b = t >= 2 ? 1.0 : 0.5 * t;
                const int s0 = (out + 2) % 8;
                const bool outer0 = kDx[s0] * kDx[in] + kDy[s0] * kDy[in] > 0;
                w0 = outer0 ? 0.5 * (1.0 + b) : 0.5 * (1.0 - b);
            }
            r.of[in + 1][out] = w0;
        }
    }
    return r;
}
constexpr RightShare kRightShare = make_right_share();

/// What push_one reads and writes besides the cell: the window's arrays (bank_pushes).
struct PushInputs {
    double kappa;  // banks.erosion
    const BankAreaFactor& factor;
    int W, H;
    const std::int8_t* dir;
    const double *area, *incised;
    double *rp, *lp;  // the right and left pushes, written
};

/// One cell's right and left pushes (bank_pushes). `Inner`: the cell is not on the window's edge, so
/// its eight neighbours are read without bounds checks; the same arithmetic and ties either way.
template <bool Inner>
inline void push_one(const PushInputs& push, int x, std::int64_t y) {
    const int W = push.W, H = push.H;
    const std::int8_t* const dir = push.dir;
    const double *const area = push.area, *const incised = push.incised;
    double *const rp = push.rp, *const lp = push.lp;
    const std::size_t i = std::size_t(y) * std::size_t(W) + std::size_t(x);
    const int out = dir[i];
    rp[i] = lp[i] = 0.0;
    if (out < 0 || !(incised[i] > 0.0)) return;
    const double amount = push.kappa * push.factor(area[i]) * incised[i];
    // The main donor: the neighbour sending its water here that drains the most (ties: the lowest
    // neighbour code, the same on any tiling); `in` is its own direction code, (k + 4) mod 8.
    int in = -1;
    double best = -1.0;
    for (int k = 0; k < 8; ++k) {
        const int nx = x + kDx[k], ny = int(y) + kDy[k];
        if (!Inner && (nx < 0 || ny < 0 || nx >= W || ny >= H)) continue;
        const std::size_t d = std::size_t(ny) * std::size_t(W) + std::size_t(nx);
        const int back = (k + 4) % 8;
        const double a = dir[d] == back ? area[d] : -1.0;  // areas are positive: a non-donor never wins
        in = a > best ? back : in;
        best = a > best ? a : best;
    }
    const double w0 = kRightShare.of[in + 1][out];
    rp[i] = amount * w0;
    lp[i] = amount * (1.0 - w0);
}

/// What lower_one needs besides the cell: the window's arrays and the floor's rise over one cell.
struct LowerInputs {
    int W, H;
    const std::int8_t* dir;
    const double *right, *left, *area;
    const std::uint8_t* outlet;
    double wide_area;  // m²: rivers draining this much pass their push on
    int passes;  // banks.onward_passes()
    double onward_area[16];  // banks.onward_area(k + 1), k < passes: from a river draining this much, k + 1 more
    double rise;
    const double* heights;
    std::int64_t off[8];  // the neighbours by direction code
    BankRelay* relay;  // null: no relay
};

/// Whether neighbour (x + dx, y + dy) lies in the window.
inline bool inside(int W, int H, int x, std::int64_t y, int k) {
    const int nx = x + kDx[k];
    const std::int64_t ny = y + kDy[k];
    return nx >= 0 && ny >= 0 && nx < W && ny < H;
}

/// A bank this close to its floor (m) counts as down to it (the river lowers it again at each step).
constexpr double kAtFloor = 0.5;

/// The push a settled cell l (new height `h`) passes on to the cell beyond it (lower_banks with a relay):
/// each large river (area ≥ wide_area) that has l straight across its flow, on its right or left at
/// distance r (1 or √2 cells), and whose cell l is down to the floor there (h ≤ river + rise·r + kAtFloor),
/// passes its whole push on that side onward, to the cell 2·r from it, which it may lower to its own height
/// plus rise·2r. The strongest such push goes on (ties: the lowest direction code).
template <bool Inner>
inline void relay_one(const LowerInputs& in, int x, std::int64_t y, std::size_t l, double h) {
    double best = 0.0, floor = 0.0;
    int out = -1;
    int onward = 0;
    for (int k = 0; k < 8; ++k) {
        if (!Inner && !inside(in.W, in.H, x, y, k)) continue;
        const std::size_t i = std::size_t(std::int64_t(l) + in.off[k]);
        const int d = in.dir[i];
        const int from_river = (k + 4) % 8;  // the direction from river i to this cell
        // Few neighbours are large rivers: that test first (it seldom passes, so it is well predicted).
        if (!(in.area[i] >= in.wide_area) || d < 0) continue;
        const double push = from_river == (d + 2) % 8 ? in.right[i] : from_river == (d + 6) % 8 ? in.left[i] : 0.0;
        const double r = (k & 1) ? kSqrt2 : 1.0;
        if (push > best && h <= in.heights[i] + in.rise * r + kAtFloor) {
            best = push;
            floor = in.heights[i] + 2.0 * in.rise * r;
            out = from_river;
            onward = 0;
            while (onward < in.passes && in.area[i] >= in.onward_area[onward]) ++onward;
        }
    }
    in.relay->out[l] = std::int8_t(out);
    if (out >= 0) {  // lower_relayed reads the rest only where out points somewhere
        in.relay->push[l] = best;
        in.relay->floor[l] = floor;
        in.relay->onward[l] = std::int8_t(onward);
    }
}

/// One cell's new height (lower_banks). `Inner` as in push_one: its neighbours are read without bounds
/// checks; a root's row of shares is zero (a neighbour off the window pushes nothing, and adding a zero
/// changes no sum). `Relay`: also what this cell passes on (relay_one).
template <bool Inner, bool Relay>
inline double lower_one(const LowerInputs& in, int x, std::int64_t y) {
    const std::size_t l = std::size_t(y) * std::size_t(in.W) + std::size_t(x);
    const double hl = in.heights[l];
    if (in.outlet && in.outlet[l]) {
        if constexpr (Relay) in.relay->out[l] = -1;
        return hl;
    }
    // Written so that nothing waits on a comparison (which neighbour pushes hardest is unpredictable): the
    // strongest push is the maximum, its river the first (lowest e) that pushes that much.
    double p[4] = {}, f[4] = {};
    for (int e = 0; e < 4; ++e) {  // banks are the rivers' edge neighbours
        if (!Inner && !inside(in.W, in.H, x, y, 2 * e)) continue;
        const std::size_t i = std::size_t(std::int64_t(l) + in.off[2 * e]);
        const int d = in.dir[i] + 1;
        const int back = (e + 2) % 4;  // the direction from the river cell i to this bank, halved
        p[e] = in.right[i] * kShares.right[d][back] + in.left[i] * kShares.left[d][back];
        f[e] = in.heights[i] + in.rise;
    }
    const double drop = ((p[0] + p[1]) + p[2]) + p[3];
    const double strongest = std::max(std::max(std::max(p[0], p[1]), p[2]), p[3]);
    double floor = f[3];
    floor = p[2] == strongest ? f[2] : floor;
    floor = p[1] == strongest ? f[1] : floor;
    floor = p[0] == strongest ? f[0] : floor;
    const double h = drop > 0.0 && hl > floor ? std::max(floor, hl - drop) : hl;
    if constexpr (Relay) relay_one<Inner>(in, x, y, l, h);
    return h;
}

/// What relayed_one reads besides the cell (lower_relayed): the relay, the window's outlets and heights,
/// the neighbours' offsets by direction code, the floor's rise over one cell (m), and the next relay or null.
struct RelayInputs {
    const BankRelay& relay;
    const std::uint8_t* outlet;
    int W, H;
    const double* heights;
    const std::int64_t* off;
    double rise;
    BankRelay* next;
};

/// One cell's new height (lower_relayed): the lowest that any neighbour passing a push on towards it
/// brings it to, not below that push's floor. With `next`, a cell so lowered to within kAtFloor of that
/// floor by a push with passes onward left passes it on once more, straight on (its floor rising by the
/// floor slope over one more step, `rise` over one cell), with one pass fewer left.
template <bool Inner, bool Next>
inline double relayed_one(const RelayInputs& in, int x, std::int64_t y) {
    const BankRelay& relay = in.relay;
    const int W = in.W, H = in.H;
    const double* const heights = in.heights;
    const std::int64_t* const off = in.off;
    BankRelay* const next = in.next;
    const std::size_t l = std::size_t(y) * std::size_t(W) + std::size_t(x);
    const double hl = heights[l];
    if constexpr (Next) next->out[l] = -1;
    if (in.outlet && in.outlet[l]) return hl;
    double h = hl;
    std::int64_t from = -1;  // the neighbour whose push brought the cell lowest (ties: the lowest code)
    for (int k = 0; k < 8; ++k) {
        if (!Inner && !inside(W, H, x, y, k)) continue;
        const std::size_t j = std::size_t(std::int64_t(l) + off[k]);
        if (relay.out[j] != (k + 4) % 8) continue;
        const double v = std::max(relay.floor[j], hl - relay.push[j]);
        if (v < h) {
            h = v;
            from = std::int64_t(j);
        }
    }
    if constexpr (Next) {
        const auto j = std::size_t(from);
        if (from >= 0 && relay.onward[j] > 0 && h <= relay.floor[j] + kAtFloor) {
            const int out = relay.out[j];
            next->out[l] = std::int8_t(out);
            next->push[l] = relay.push[j];
            next->floor[l] = relay.floor[j] + in.rise * ((out & 1) ? kSqrt2 : 1.0);
            next->onward[l] = std::int8_t(relay.onward[j] - 1);
        }
    }
    return h;
}

/// Calls fn(x, inner) for each computed cell x of row y of the window, `inner` a std::bool_constant: true
/// for the cells off the window's edge (all eight neighbours inside it), false for the edge ones.
template <class Fn>
inline void each_cell_of_row(const BankWindow& w, std::int64_t y, Fn&& fn) {
    if (y == 0 || y + 1 == w.height) {
        for (int x = w.x0; x < w.x1; ++x) fn(x, std::false_type{});
        return;
    }
    const int xb = std::max(w.x0, 1), xe = std::min(w.x1, w.width - 1);
    for (int x = w.x0; x < std::min(xb, w.x1); ++x) fn(x, std::false_type{});
    for (int x = xb; x < xe; ++x) fn(x, std::true_type{});
    for (int x = std::max(xe, w.x0); x < w.x1; ++x) fn(x, std::false_type{});
}

}  // namespace

BankAreaFactor::BankAreaFactor(const Banks& banks, double cell)
    : a0_(cell * cell), inv_a0_(1.0 / (cell * cell)), inv_ab_(1.0 / banks.area) {
    table_.resize(1 << 16);
    for (std::size_t c = 0; c < table_.size(); ++c) table_[c] = -std::expm1(-double(c) * a0_ * inv_ab_);
}

void bank_pushes(const Banks& banks, const BankAreaFactor& factor, const BankWindow& w, const std::int8_t* dir,
                 const double* area, const double* incised, std::vector<double>& right, std::vector<double>& left) {
    const std::size_t n = std::size_t(w.width) * std::size_t(w.height);
    if (right.size() != n || left.size() != n) {  // the cells outside the computed ones stay 0 (or a halo's)
        right.assign(n, 0.0);
        left.assign(n, 0.0);
    }
    const PushInputs in{banks.erosion, factor, w.width, w.height, dir, area, incised, right.data(), left.data()};
    parallel_for(w.y0, w.y1, 16, [&in, &w](std::int64_t yb, std::int64_t ye) {
        for (std::int64_t y = yb; y < ye; ++y)
            each_cell_of_row(w, y, [&](int x, auto inner) { push_one<decltype(inner)::value>(in, x, y); });
    });
}

namespace {

/// Computes each computed cell's new height into `scratch` with cell(x, y, inner), then writes them back
/// and returns the volume removed (m³): each row's sum in a fixed order, then the rows in order.
template <class Cell>
double lower_rows(const BankWindow& w, double cell, double* heights, std::vector<double>& scratch, Cell&& cell_at) {
    const int W = w.width, cw = w.x1 - w.x0, ch = std::max(0, w.y1 - w.y0);
    scratch.resize(std::size_t(cw) * std::size_t(ch) + std::size_t(ch));  // new heights, then each row's volume
    double* const out = scratch.data();
    double* const row_volume = out + std::size_t(cw) * std::size_t(ch);
    parallel_for(w.y0, w.y1, 16, [=, &w, &cell_at](std::int64_t yb, std::int64_t ye) {
        for (std::int64_t y = yb; y < ye; ++y) {
            double* const o = out + std::size_t(y - w.y0) * std::size_t(cw);  // o[x - w.x0]: cell x of row y
            each_cell_of_row(w, y, [&](int x, auto inner) { o[x - w.x0] = cell_at(x, y, inner); });
        }
    });
    parallel_for(w.y0, w.y1, 16, [=](std::int64_t yb, std::int64_t ye) {
        for (std::int64_t y = yb; y < ye; ++y) {
            double v = 0.0;
            for (int x = w.x0; x < w.x1; ++x) {
                const std::size_t l = std::size_t(y) * std::size_t(W) + std::size_t(x);
                const double o = out[std::size_t(y - w.y0) * std::size_t(cw) + std::size_t(x - w.x0)];
                v += heights[l] - o;
                heights[l] = o;
            }
            row_volume[y - w.y0] = v;
        }
    });
    double removed = 0.0;
    for (int r = 0; r < ch; ++r) removed += row_volume[r];
    return removed * cell * cell;
}

}  // namespace

double lower_banks(const Banks& banks, const BankWindow& w, const D8Flow& flow, const BankPushes& pushes, double cell,
                   double* heights, std::vector<double>& scratch, BankRelay* relay) {
    const std::int64_t W = w.width;
    LowerInputs in{w.width,
                   w.height,
                   flow.dir,
                   pushes.right,
                   pushes.left,
                   flow.area,
                   flow.outlet,
                   banks.wide_area,
                   std::min(banks.onward_passes(), 16),
                   {},
                   cell * banks.floor_slope,
                   heights,
                   {1, W + 1, W, W - 1, -1, -W - 1, -W, -W + 1},
                   banks.wide() ? relay : nullptr};
    for (int k = 0; k < in.passes; ++k) in.onward_area[k] = banks.onward_area(k + 1);
    if (!in.relay)
        return lower_rows(w, cell, heights, scratch, [&in](int x, std::int64_t y, auto inner) {
            return lower_one<decltype(inner)::value, false>(in, x, y);
        });
    in.relay->size_to(std::size_t(w.width) * std::size_t(w.height));
    return lower_rows(w, cell, heights, scratch, [&in](int x, std::int64_t y, auto inner) {
        return lower_one<decltype(inner)::value, true>(in, x, y);
    });
}

double lower_relayed(const Banks& banks, const BankWindow& w, const BankRelay& relay, const std::uint8_t* outlet,
                     double cell, double* heights, BankRelay* next) {
    const std::int64_t W = w.width;
    const std::int64_t off[8] = {1, W + 1, W, W - 1, -1, -W - 1, -W, -W + 1};
    const double rise = cell * banks.floor_slope;
    if (next) {
        next->size_to(std::size_t(w.width) * std::size_t(w.height));
        std::fill(next->out.begin(), next->out.end(), std::int8_t(-1));  // what no cell passes on
    }
    // Only the cells a relay points at can change (few: the large rivers' banks, fewer each pass), so they
    // are found from the relay rather than by visiting every cell: each cell of the window and its
    // one-cell ring (a tile's halo) that passes something on names its target, kept if it is computed
    // here. Row by row in parallel, then in index order, each target once; each reads only its own height
    // and the relay, so the targets are independent and the heights the same bits as a visit of every cell.
    const int ya = std::max(0, w.y0 - 1), yb = std::min(w.height, w.y1 + 1);
    const int xa = std::max(0, w.x0 - 1), xb = std::min(w.width, w.x1 + 1);
    std::vector<std::vector<std::size_t>> rows(std::size_t(std::max(0, yb - ya)));
    parallel_for(ya, yb, 16, [&](std::int64_t y0, std::int64_t y1) {
        for (std::int64_t y = y0; y < y1; ++y) {
            auto& list = rows[std::size_t(y - ya)];
            for (int x = xa; x < xb; ++x) {
                const std::size_t j = std::size_t(y) * std::size_t(W) + std::size_t(x);
                const int out = relay.out[j];
                if (out < 0) continue;
                const int tx = x + kDx[out];
                const std::int64_t ty = y + kDy[out];
                if (tx < w.x0 || tx >= w.x1 || ty < w.y0 || ty >= w.y1) continue;
                list.push_back(std::size_t(std::int64_t(j) + off[out]));
            }
        }
    });
    const RelayInputs in{relay, outlet, w.width, w.height, heights, off, rise, next};
    std::vector<std::size_t> targets;
    for (const auto& list : rows) targets.insert(targets.end(), list.begin(), list.end());
    std::sort(targets.begin(), targets.end());
    targets.erase(std::unique(targets.begin(), targets.end()), targets.end());
    double removed = 0.0;
    for (const std::size_t l : targets) {
        const int x = int(l % std::size_t(W));
        const std::int64_t y = std::int64_t(l / std::size_t(W));
        const bool inner = x > 0 && y > 0 && x + 1 < w.width && y + 1 < w.height;
        const double before = heights[l];
        const double h = inner ? (next ? relayed_one<true, true>(in, x, y) : relayed_one<true, false>(in, x, y))
                               : (next ? relayed_one<false, true>(in, x, y) : relayed_one<false, false>(in, x, y));
        heights[l] = h;
        removed += before - h;
    }
    return removed * cell * cell;
}

void BankEroder::erode(const Banks& banks, int width, int height, double cell, const D8Flow& flow,
                       const double* lowering, double* heights) {
    if (!factor_) factor_.emplace(banks, cell);
    const BankWindow w{width, height, 0, 0, width, height};
    const std::uint8_t* const outlets = flow.outlet;
    bank_pushes(banks, *factor_, w, flow.dir, flow.area, lowering, right_, left_);
    lower_banks(banks, w, flow, {right_.data(), left_.data()}, cell, heights, scratch_, &relay_);
    if (!banks.wide()) return;
    // Each pass lowers the cells the last one pushes on to and, but for the last, fills the other relay
    // with what they pass on in turn.
    BankRelay *relay = &relay_, *next = &relay2_;
    for (int pass = 0; pass <= banks.onward_passes(); ++pass, std::swap(relay, next))
        lower_relayed(banks, w, *relay, outlets, cell, heights, pass < banks.onward_passes() ? next : nullptr);
}

}  // namespace orogen::landscape
