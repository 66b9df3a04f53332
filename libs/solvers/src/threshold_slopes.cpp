// threshold_slopes.cpp — the threshold-slope limit (threshold_slopes.hpp): sweeps of
// h ← min(h, h(nb) + S_c·d) in four directions until a round changes nothing.
#include <orogen/parallel.hpp>
#include <orogen/solvers/threshold_slopes.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <span>
#include <utility>
#include <stdexcept>
#include <vector>

namespace orogen::solvers::threshold {
namespace {

constexpr double kSqrt2 = 1.4142135623730951;

/// The least bound a vertex's eight neighbours (n, s, w, e and the corners; +∞ where there is none) give it,
/// the threshold rising `step` per cell: edge_bound over the stencil's eight triangles. An edge's inner
/// points give more than min(axial, corner) + 1.03·step, and its axial end already gave axial + step ≥
/// best: only an edge whose corner is below best − step can lower the vertex further (the skipped ones
/// could not: the same value, in less time).
struct Stencil {
    double n, s, w, e, nw, ne, sw, se;  ///< the neighbours' heights, m (+∞ where there is none)
};
inline double stencil_bound(const Stencil& k, double step) {
    const auto [n, s, w, e, nw, ne, sw, se] = k;
    const double straight = std::min(std::min(n, s), std::min(w, e));
    const double corner = std::min(std::min(nw, ne), std::min(sw, se));
    double best = std::min(straight + step, corner + step * kSqrt2);
    auto edge = [&](double axial, double corner_h) {
        if (corner_h + step < best) best = std::min(best, edge_interior(axial, corner_h, step));
    };
    edge(n, nw), edge(n, ne), edge(s, sw), edge(s, se);
    edge(w, nw), edge(w, sw), edge(e, ne), edge(e, se);
    return best;
}

/// A grid the sweeps update in its rectangle [x0, x1) × [y0, y1), reading every
/// vertex of the grid (the rest: a tile's ghosts, which they never write).
struct Sweeps {
    double* g;
    int gw, gh;
    int x0, y0, x1, y1;
    const std::uint8_t* fixed;  // gw × gh, or null
    const double* slopes;  // gw × gh S_c per vertex (m/m), or null: `slope` everywhere
    double slope, cell;  // S_c (m/m), the vertex spacing (m)
    /// gw × gh: the pass in which each vertex was last lowered (0: not yet), or null. With it, a pass
    /// after the first takes only the vertices with a neighbour (or themselves) lowered in the pass
    /// before or in this one: a vertex none of whose neighbours moved since it was last taken already
    /// stands at or below its bound. That changes which updates run, not the fixed point they reach.
    std::int32_t* moved = nullptr;
    /// With `moved`: for each strip of columns (vertical_pass) and row, the pass in which a vertex of that
    /// strip's row was last lowered (the largest `moved` there), strips × gh. A row none of whose own,
    /// upper or lower strip rows (nor the edge columns beside them) moved since is skipped whole, without
    /// looking at its vertices one by one: in the later passes most rows are.
    std::int32_t* strip_rows = nullptr;
    mutable int pass = 0;  // the passes so far

    /// How far above a neighbour `cell` away vertex i may stand, straight (1) or diagonal (√2).
    double step(std::size_t i) const { return (slopes ? slopes[i] : slope) * cell; }

    /// Row r's vertices in the columns [a, b), taken east- or westward: each from its eight
    /// neighbours (edge_bound over the stencil's eight triangles); those in the columns just outside
    /// [a, b) read from `west` and `east` (a copy of those columns, by row, or null where the grid
    /// ends). Returns the vertices lowered.
    /// `west_moved`, `east_moved`: `moved` of the same columns, copied likewise (with `moved` only).
    /// `rows`: the strip's column of strip_rows (gh values), or null.
    /// A strip's edges, as row_update reads them.
    struct StripEdges {
        const double* west;
        const double* east;
        const std::int32_t* west_moved;
        const std::int32_t* east_moved;
        std::int32_t* rows;
    };
    std::int64_t row_update(int r, int a, int b, const StripEdges& edges, bool eastward) const {
        const double* const west = edges.west;
        const double* const east = edges.east;
        const std::int32_t* const west_moved = edges.west_moved;
        const std::int32_t* const east_moved = edges.east_moved;
        std::int32_t* const rows = edges.rows;
        constexpr double kNone = std::numeric_limits<double>::infinity();
        std::int64_t lowered = 0;
        const std::size_t base = std::size_t(r) * std::size_t(gw);
        double* row = g + base;
        const double* up = r > 0 ? row - gw : nullptr;
        const double* down = r + 1 < gh ? row + gw : nullptr;
        const std::uint8_t* fx = fixed ? fixed + base : nullptr;
        // The value of line `l` (up, row or down; row y of the edge copies) at column c, or none.
        auto at = [&](const double* l, int y, int c) {
            if (l == nullptr) return kNone;
            if (c < a) return west ? west[y] : kNone;
            if (c >= b) return east ? east[y] : kNone;
            return l[c];
        };
        const int since = pass - 1;  // lowered in the pass before or in this one
        const bool skip = moved != nullptr && pass > 1;
        if (skip && rows) {
            bool any = false;
            for (int y = std::max(r - 1, 0); y <= std::min(r + 1, gh - 1); ++y)
                any = any || rows[y] >= since || (west_moved && west_moved[y] >= since) ||
                    (east_moved && east_moved[y] >= since);
            if (!any) return 0;
        }
        auto moved_at = [&](int y, int c) {
            if (y < 0 || y >= gh) return false;
            if (c < a) return west_moved != nullptr && west_moved[y] >= since;
            if (c >= b) return east_moved != nullptr && east_moved[y] >= since;
            return moved[std::size_t(y) * std::size_t(gw) + std::size_t(c)] >= since;
        };
        for (int k = 0; k < b - a; ++k) {
            const int c = eastward ? a + k : b - 1 - k;
            if (fx && fx[c]) continue;
            if (skip) {
                bool any = false;
                if (r > 0 && r + 1 < gh && c > a && c + 1 < b) {
                    const std::int32_t* m = moved + base + std::size_t(c) - 1;
                    for (const std::int32_t* l : {m - gw, m, m + gw})
                        any = any || l[0] >= since || l[1] >= since || l[2] >= since;
                } else {
                    for (int dy = -1; dy <= 1; ++dy)
                        for (int dx = -1; dx <= 1; ++dx) any = any || moved_at(r + dy, c + dx);
                }
                if (!any) continue;
            }
            const double step = this->step(base + std::size_t(c));
            double n, s, w, e, nw, ne, sw, se;
            if (up && down && c > a && c + 1 < b) {  // inside the strip, between two rows: no test
                n = up[c], s = down[c], w = row[c - 1], e = row[c + 1];
                nw = up[c - 1], ne = up[c + 1], sw = down[c - 1], se = down[c + 1];
            } else {
                n = at(up, r - 1, c), s = at(down, r + 1, c), w = at(row, r, c - 1), e = at(row, r, c + 1);
                nw = at(up, r - 1, c - 1), ne = at(up, r - 1, c + 1);
                sw = at(down, r + 1, c - 1), se = at(down, r + 1, c + 1);
            }
            // Every bound is at least the lower of its two neighbours + step (√(1 + t²) ≥ 1): a vertex
            // no more than that above its lowest neighbour keeps its height.
            const double straight = std::min(std::min(n, s), std::min(w, e));
            const double corner = std::min(std::min(nw, ne), std::min(sw, se));
            if (!(std::min(straight, corner) + step < row[c])) continue;
            const double best = stencil_bound({n, s, w, e, nw, ne, sw, se}, step);
            if (best < row[c]) {
                row[c] = best;
                if (moved) moved[base + std::size_t(c)] = pass;
                if (rows) rows[r] = pass;
                ++lowered;
            }
        }
        return lowered;
    }

    /// The least bound vertex (r, c)'s neighbours give it now (none from beyond the grid): row_update's.
    double bound_of(int r, int c) const {
        constexpr double kNone = std::numeric_limits<double>::infinity();
        auto at = [&](int y, int x) {
            return y < 0 || y >= gh || x < 0 || x >= gw ? kNone : g[std::size_t(y) * std::size_t(gw) + std::size_t(x)];
        };
        const double step = this->step(std::size_t(r) * std::size_t(gw) + std::size_t(c));
        return stencil_bound({at(r - 1, c), at(r + 1, c), at(r, c - 1), at(r, c + 1), at(r - 1, c - 1),
                              at(r - 1, c + 1), at(r + 1, c - 1), at(r + 1, c + 1)},
                             step);
    }

    /// After a round of sweeps on the whole grid (x0 = y0 = 0, with `moved`): the rest of the way to the
    /// fixed point from a work list rather than by more rounds. The later rounds lower a few hundred
    /// vertices in a million, yet each of their passes looks at every row. Only a neighbour of a vertex
    /// lowered in the last pass can stand above its bound now (a vertex any earlier lowering could have
    /// left above it was taken again in a later pass: the skip rule in row_update); those go on the list,
    /// and a vertex lowered from it puts its neighbours on it. Monotone updates in any order reach the
    /// same greatest fixed point, so the same bits as more rounds. Returns the vertices lowered.
    std::int64_t settle(std::vector<std::int32_t>& list, std::vector<std::uint8_t>& listed) const {
        const std::size_t count = std::size_t(gw) * std::size_t(gh);
        listed.assign(count, 0);
        list.clear();
        auto put_around = [&](int r, int c) {
            for (int y = std::max(r - 1, 0); y <= std::min(r + 1, gh - 1); ++y)
                for (int x = std::max(c - 1, 0); x <= std::min(c + 1, gw - 1); ++x) {
                    const std::size_t i = std::size_t(y) * std::size_t(gw) + std::size_t(x);
                    if (listed[i] || (fixed && fixed[i])) continue;
                    listed[i] = 1;
                    list.push_back(std::int32_t(i));
                }
        };
        for (std::size_t i = 0; i < count; ++i)
            if (moved[i] == pass) put_around(int(i / std::size_t(gw)), int(i % std::size_t(gw)));
        std::int64_t lowered = 0;
        for (std::size_t head = 0; head < list.size(); ++head) {
            const std::size_t i = std::size_t(list[head]);
            listed[i] = 0;
            const int r = int(i / std::size_t(gw)), c = int(i % std::size_t(gw));
            const double best = bound_of(r, c);
            if (best < g[i]) {
                g[i] = best;
                ++lowered;
                put_around(r, c);
            }
            // A long list is compacted now and then (what was taken is done with).
            if (head > (std::size_t(1) << 20) && head * 2 > list.size()) {
                list.erase(list.begin(), list.begin() + std::ptrdiff_t(head + 1));
                head = std::size_t(-1);
            }
        }
        return lowered;
    }

    /// Down (or up) the rows, each from the one just finished, in strips of columns side by side: a
    /// strip reads its neighbours' edge columns as they were when the sweep began (values only fall, so
    /// a stale one lowers less, never wrongly; a round that changes nothing read none stale), so the
    /// strips run in parallel and never touch each other's memory.
    static constexpr int kStrip = 256;
    int strip_count() const { return (x1 - x0 + kStrip - 1) / kStrip; }

    std::int64_t vertical_pass(bool down, bool eastward) const {
        const int strips = strip_count();
        // First every strip's edge columns, before any strip moves: then no thread reads what another writes.
        std::vector<double> edges(std::size_t(strips) * 2 * std::size_t(gh));
        auto edge = [&](int s, int side) {
            return edges.data() + (std::size_t(s) * 2 + std::size_t(side)) * std::size_t(gh);
        };
        auto strip = [&](int s) { return std::pair{x0 + s * kStrip, std::min(x1, x0 + (s + 1) * kStrip)}; };
        ++pass;
        std::vector<std::int32_t> edge_moved(moved ? edges.size() : 0);
        auto edge_m = [&](int s, int side) {
            return moved ? edge_moved.data() + (std::size_t(s) * 2 + std::size_t(side)) * std::size_t(gh) : nullptr;
        };
        for (int s = 0; s < strips; ++s) {
            const auto [a, b] = strip(s);
            for (int r = 0; r < gh; ++r) {
                const std::size_t row = std::size_t(r) * std::size_t(gw);
                if (a > 0) edge(s, 0)[r] = g[row + std::size_t(a - 1)];
                if (b < gw) edge(s, 1)[r] = g[row + std::size_t(b)];
                if (moved && a > 0) edge_m(s, 0)[r] = moved[row + std::size_t(a - 1)];
                if (moved && b < gw) edge_m(s, 1)[r] = moved[row + std::size_t(b)];
            }
        }
        std::atomic<std::int64_t> lowered{0};
        parallel_for(0, strips, 1, [&](std::int64_t s0, std::int64_t s1) {
            for (std::int64_t s = s0; s < s1; ++s) {
                const auto [a, b] = strip(int(s));
                const double* w = a > 0 ? edge(int(s), 0) : nullptr;
                const double* e = b < gw ? edge(int(s), 1) : nullptr;
                const std::int32_t* wm = a > 0 ? edge_m(int(s), 0) : nullptr;
                const std::int32_t* em = b < gw ? edge_m(int(s), 1) : nullptr;
                std::int32_t* rows = strip_rows ? strip_rows + std::size_t(s) * std::size_t(gh) : nullptr;
                const StripEdges edges{w, e, wm, em, rows};
                std::int64_t mine = 0;
                if (down)
                    for (int r = y0; r < y1; ++r) mine += row_update(r, a, b, edges, eastward);
                else
                    for (int r = y1 - 1; r >= y0; --r) mine += row_update(r, a, b, edges, eastward);
                lowered += mine;
            }
        });
        return lowered.load();
    }

    /// One round: the four orders of fast sweeping (Zhao 2005), down and up the rows, east- and
    /// westward along them, so a slope facing any way is carried across the grid in one round.
    std::int64_t round() const {
        return vertical_pass(true, true) + vertical_pass(false, false) + vertical_pass(true, false) +
            vertical_pass(false, true);
    }
};

void check_slope(double cell, const Slopes& slopes) {
    if (!(cell > 0.0) || !std::isfinite(cell))
        throw std::invalid_argument("threshold slopes: the cell size must be a positive number of metres");
    if (!slopes.per_vertex && (!(slopes.uniform > 0.0) || !std::isfinite(slopes.uniform)))
        throw std::invalid_argument("threshold slopes: the threshold slope must be a positive finite tangent");
}

/// After the sweeps: what each vertex lost, into `removed` and the result. On every thread, by blocks of
/// a fixed size summed in their order: the same bits on any number of threads (a serial pass over the grid
/// was 2 % of a landslide-limited stream-power run).
void account(const double* before, const double* after, std::size_t count, double* removed, Result& result) {
    std::atomic<std::int64_t> lowered{0};  // a count: the same in any order
    result.removed += parallel_sum(0, std::int64_t(count), 1 << 16, [&](std::int64_t b, std::int64_t e) {
        std::int64_t n = 0;
        double sum = 0.0;
        for (auto i = std::size_t(b); i < std::size_t(e); ++i) {
            const double drop = before[i] - after[i];
            if (drop > 0.0) {
                ++n;
                sum += drop;
                if (removed) removed[i] += drop;
            }
        }
        lowered += n;
        return sum;
    });
    result.lowered += lowered.load();
}

}  // namespace

Result limit_slopes(double* heights, int width, int height, double cell, const Slopes& slopes,
                    const std::uint8_t* fixed, double* removed, Scratch* scratch) {
    check_slope(cell, slopes);
    const std::size_t n = std::size_t(width) * std::size_t(height);
    Scratch own;
    Scratch& mem = scratch ? *scratch : own;
    std::vector<double>& before = mem.before;
    std::vector<std::int32_t>& moved = mem.moved;
    before.assign(heights, heights + n);
    moved.assign(n, 0);
    Sweeps s{heights, width, height, 0, 0, width, height, fixed, slopes.per_vertex, slopes.uniform, cell, moved.data()};
    mem.strip_rows.assign(std::size_t(s.strip_count()) * std::size_t(height), 0);
    s.strip_rows = mem.strip_rows.data();
    Result result;
    // One round of sweeps carries each slope across the grid and does nearly all the lowering; a work
    // list finishes it (a second "round", the last one the list's emptying).
    result.rounds = 1;
    if (s.round() > 0) {
        s.settle(mem.list, mem.listed);
        result.rounds = 2;
    }
    account(before.data(), heights, n, removed, result);
    return result;
}

Result limit_slopes(Tiling& tiles, double* heights, double cell, const Slopes& slopes, const std::uint8_t* fixed,
                    double* removed, Scratch* scratch) {
    check_slope(cell, slopes);
    if (tiles.halo() < 1) throw std::logic_error("threshold slopes: a tiled limit needs a halo of at least 1");
    const TileRect own = tiles.owned(), ghost = tiles.ghosted();
    const std::size_t n = std::size_t(own.width) * std::size_t(own.height);
    Scratch mine_only;
    Scratch& mem = scratch ? *scratch : mine_only;
    std::vector<double>& g = mem.heights;
    tiles.ghosted_copy(heights, g);
    // The ghosts' flags and slopes are never read: only owned vertices are lowered, by their own slope.
    std::vector<std::uint8_t>& gfixed = mem.fixed;
    if (fixed) tiles.ghosted_copy(fixed, gfixed);
    std::vector<double>& gslopes = mem.slopes;
    if (slopes.per_vertex) tiles.ghosted_copy(slopes.per_vertex, gslopes);
    const Sweeps s{g.data(),
                   ghost.width,
                   ghost.height,
                   own.x0 - ghost.x0,
                   own.y0 - ghost.y0,
                   own.x1() - ghost.x0,
                   own.y1() - ghost.y0,
                   fixed ? gfixed.data() : nullptr,
                   slopes.per_vertex ? gslopes.data() : nullptr,
                   slopes.uniform,
                   cell};
    double* grids[] = {g.data()};
    Result result;
    for (;;) {
        tiles.exchange(std::span<double* const>(grids));
        ++result.rounds;
        const std::int64_t changed = tiles.reduce(s.round(), Tiling::Reduce::sum);
        if (changed == 0) break;
    }
    // The tile's part of the ghosted grid back into `heights`, and what it lost.
    std::vector<double>& before = mem.before;
    before.assign(heights, heights + n);
    for (int r = 0; r < own.height; ++r)
        std::copy_n(g.data() + std::size_t(r + s.y0) * std::size_t(ghost.width) + std::size_t(s.x0),
                    std::size_t(own.width), heights + std::size_t(r) * std::size_t(own.width));
    Result mine;
    account(before.data(), heights, n, removed, mine);
    result.lowered = tiles.reduce(mine.lowered, Tiling::Reduce::sum);
    result.removed = tiles.reduce(mine.removed, Tiling::Reduce::sum);
    return result;
}

}  // namespace orogen::solvers::threshold
