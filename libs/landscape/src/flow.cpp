// flow.cpp — D8 routing, pit resolution over the basin graph, stack, drainage area (see flow.hpp).
#include <orogen/landscape/flow.hpp>

#include <orogen/parallel.hpp>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

namespace orogen::landscape {

namespace {

/// i / W for 0 ≤ i < 2^31 by a multiplication (Granlund & Montgomery): M = ⌈2^k/W⌉ with
/// k = 31 + ⌈log2 W⌉, exact since (M·W − 2^k)·i < W·2^31 ≤ 2^k.
class RowOf {
public:
    explicit RowOf(int width) {
        int lg = 0;
        while ((std::int64_t(1) << lg) < width) ++lg;
        shift_ = 31 + lg;
        mul_ = ((std::uint64_t(1) << shift_) + std::uint64_t(width) - 1) / std::uint64_t(width);
    }
    int operator()(std::int32_t i) const { return int((std::uint64_t(i) * mul_) >> shift_); }

private:
    std::uint64_t mul_;
    int shift_;
};

/// Per thread: for each basin graph node, which pit basin's links last named it (a stamp unique to the
/// basin and the call) and where that link is among the group's links. Kept between calls.
struct NodeSlots {
    std::vector<std::uint64_t> stamp;
    std::vector<std::int32_t> at;
};
thread_local NodeSlots node_slots;
std::atomic<std::uint32_t> link_epoch{0};

/// std::sort by link_before, for many links by a radix sort on the pass first: four passes of
/// 16 bits over (key, index) pairs, then the links in that order, and link_before's own sort
/// within each run of equal passes. The same order as std::sort (link_before is a total order).
void sort_links(std::vector<Link>& links) {
    const std::size_t n = links.size();
    if (n < (std::size_t(1) << 14)) {
        std::sort(links.begin(), links.end(), link_before);
        return;
    }
    // The pass's bits turned into an unsigned key of the same order (−0 as +0, as == sees them).
    const auto key_of = [](double v) {
        const auto u = std::bit_cast<std::uint64_t>(v + 0.0);
        return (u >> 63) ? ~u : u | (std::uint64_t(1) << 63);
    };
    struct Keyed {
        std::uint64_t key;
        std::uint32_t index;
    };
    const std::unique_ptr<Keyed[]> a_own(new Keyed[n]), b_own(new Keyed[n]);  // not zeroed: all written
    Keyed* a = a_own.get();
    Keyed* b = b_own.get();
    std::vector<std::uint32_t> count(4 * 65536, 0);
    for (std::size_t e = 0; e < n; ++e) {
        const std::uint64_t k = key_of(links[e].pass);
        a[e] = {k, std::uint32_t(e)};
        for (int d = 0; d < 4; ++d) ++count[std::size_t(d) * 65536 + ((k >> (16 * d)) & 0xffff)];
    }
    for (int d = 0; d < 4; ++d) {
        std::uint32_t* c = count.data() + std::size_t(d) * 65536;
        if (std::find(c, c + 65536, std::uint32_t(n)) != c + 65536) continue;  // one digit for all: in order
        std::uint32_t sum = 0;
        for (int v = 0; v < 65536; ++v) {
            const std::uint32_t k = c[v];
            c[v] = sum;
            sum += k;
        }
        for (std::size_t e = 0; e < n; ++e) b[c[(a[e].key >> (16 * d)) & 0xffff]++] = a[e];
        std::swap(a, b);
    }
    std::vector<Link> sorted;
    sorted.reserve(n);
    for (std::size_t e = 0; e < n; ++e) sorted.push_back(links[a[e].index]);
    for (std::size_t e = 0; e < n;) {
        std::size_t f = e + 1;
        while (f < n && a[f].key == a[e].key) ++f;
        if (f - e > 1) std::sort(sorted.begin() + std::ptrdiff_t(e), sorted.begin() + std::ptrdiff_t(f), link_before);
        e = f;
    }
    links.swap(sorted);
}

}  // namespace

std::int32_t find_root(std::vector<std::int32_t>& parent, std::int32_t v) {
    while (parent[std::size_t(v)] != v) {
        parent[std::size_t(v)] = parent[std::size_t(parent[std::size_t(v)])];
        v = parent[std::size_t(v)];
    }
    return v;
}

BasinTree solve_basin_graph(std::vector<Link>& links, std::int32_t nodes) {
    // A total order, so the tree does not depend on the order the links were collected in.
    if (!std::is_sorted(links.begin(), links.end(), link_before)) sort_links(links);
    // Kruskal: the minimum spanning tree of the basin graph (its links in the order taken).
    std::vector<std::int32_t> parent(static_cast<std::size_t>(nodes));
    for (std::int32_t v = 0; v < nodes; ++v) parent[std::size_t(v)] = v;
    std::vector<std::int32_t> taken;
    taken.reserve(std::size_t(std::max(nodes - 1, 0)));
    std::vector<std::int32_t> degree(std::size_t(nodes) + 1, 0);
    for (std::size_t e = 0; e < links.size() && std::int32_t(taken.size()) < nodes - 1; ++e) {
        const std::int32_t ra = find_root(parent, std::int32_t(links[e].a)),
                           rb = find_root(parent, std::int32_t(links[e].b));
        if (ra == rb) continue;
        parent[std::size_t(ra)] = rb;
        taken.push_back(std::int32_t(e));
        ++degree[std::size_t(links[e].a) + 1];
        ++degree[std::size_t(links[e].b) + 1];
    }
    // Each node's tree links in the order taken (one array, not a vector per node).
    for (std::size_t v = 0; v < std::size_t(nodes); ++v) degree[v + 1] += degree[v];
    // static_cast, not std::size_t(...): that would declare a function (the vexing parse, which clang takes).
    std::vector<std::int32_t> adjacent(static_cast<std::size_t>(degree[std::size_t(nodes)]));
    {
        std::vector<std::int32_t> fill(degree.begin(), degree.end() - 1);
        for (const std::int32_t e : taken) {
            adjacent[std::size_t(fill[std::size_t(links[std::size_t(e)].a)]++)] = e;
            adjacent[std::size_t(fill[std::size_t(links[std::size_t(e)].b)]++)] = e;
        }
    }
    // Orient the tree from the sea: each pit basin's way out, and its lake level.
    BasinTree t;
    t.level.assign(std::size_t(nodes), -std::numeric_limits<double>::infinity());
    t.out_link.assign(std::size_t(nodes), -1);
    std::vector<std::uint8_t> seen(static_cast<std::size_t>(nodes), 0);
    t.order.reserve(std::size_t(nodes));
    t.order.assign(1, 0);
    seen[0] = 1;
    for (std::size_t q = 0; q < t.order.size(); ++q) {
        const std::int32_t v = t.order[q];
        for (std::int32_t k = degree[std::size_t(v)]; k < degree[std::size_t(v) + 1]; ++k) {
            const std::int32_t e = adjacent[std::size_t(k)];
            const Link& l = links[std::size_t(e)];
            const auto u = std::int32_t(l.a == v ? l.b : l.a);
            if (seen[std::size_t(u)]) continue;
            seen[std::size_t(u)] = 1;
            t.out_link[std::size_t(u)] = e;
            t.level[std::size_t(u)] = std::max(l.pass, t.level[std::size_t(v)]);
            t.order.push_back(u);
        }
    }
    if (std::int32_t(t.order.size()) != nodes)
        throw std::logic_error("FlowRouter: a pit basin has no way to an outlet");
    return t;
}

FlowRouter::FlowRouter(int width, int height, double cell, OpenSides open, std::int64_t outlet_cell)
    : width_(width), height_(height), size_(std::size_t(width) * std::size_t(height)), cell_(cell), open_(open) {
    if (width < 1 || height < 1 || !(cell > 0.0)) throw std::invalid_argument("FlowRouter: empty grid or cell <= 0");
    if (size_ >= std::size_t(std::numeric_limits<std::int32_t>::max()))
        throw std::invalid_argument("FlowRouter: more than 2^31 cells");
    outlet_.assign(size_, 0);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const bool o = (y == 0 && open.north) || (y == height - 1 && open.south) || (x == 0 && open.west) ||
                (x == width - 1 && open.east);
            outlet_[std::size_t(y) * std::size_t(width) + std::size_t(x)] = o ? 1 : 0;
        }
    if (!open.any()) {
        if (outlet_cell < 0 || std::size_t(outlet_cell) >= size_)
            throw std::invalid_argument("FlowRouter: outlet outside the grid");
        outlet_[std::size_t(outlet_cell)] = 1;
    }
    receiver_.resize(size_);
    donors_.resize(size_);
    stack_.resize(size_);
    basin_.resize(size_);
    area_.resize(size_);
}

double FlowRouter::distance(std::int64_t i) const {
    const std::int64_t r = receiver_[std::size_t(i)];
    if (r == i) return 0.0;
    const std::int64_t d = r - i;
    return (d == 1 || d == -1 || d == width_ || d == -width_) ? cell_ : cell_ * kSqrt2;
}

/// Steepest-descent direction (0–7, kDx/kDy order; −1: no lower neighbour) of
/// the inner cells x = 1 … W−2 of one inner row, as doubles: a loop without
/// branches or integer lanes, which the compiler turns into vector blends (the
/// comparisons are unpredictable on rough ground). Same arithmetic as the
/// scalar form, (h_i − h_k)·(1/distance) with ties to the lower k.
// With GCC on x86-64, built twice, for AVX2 and for the baseline, picked at load time: the same
// comparisons and products in wider lanes (no FMA), so the same directions.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define OROGEN_AVX2_CLONE __attribute__((target_clones("avx2", "default")))
#else
#define OROGEN_AVX2_CLONE
#endif
OROGEN_AVX2_CLONE void inner_row_directions(const double* __restrict c, const double* __restrict up,
                                            const double* __restrict dn, int W, double* __restrict dir_out) {
    const double d = 1.0 / kSqrt2;
    for (int x = 1; x < W - 1; ++x) {
        const double hi = c[x];
        double best = 0.0, dir = -1.0, s;
        s = (hi - c[x + 1]) * 1.0;
        dir = s > best ? 0.0 : dir;
        best = s > best ? s : best;
        s = (hi - dn[x + 1]) * d;
        dir = s > best ? 1.0 : dir;
        best = s > best ? s : best;
        s = (hi - dn[x]) * 1.0;
        dir = s > best ? 2.0 : dir;
        best = s > best ? s : best;
        s = (hi - dn[x - 1]) * d;
        dir = s > best ? 3.0 : dir;
        best = s > best ? s : best;
        s = (hi - c[x - 1]) * 1.0;
        dir = s > best ? 4.0 : dir;
        best = s > best ? s : best;
        s = (hi - up[x - 1]) * d;
        dir = s > best ? 5.0 : dir;
        best = s > best ? s : best;
        s = (hi - up[x]) * 1.0;
        dir = s > best ? 6.0 : dir;
        best = s > best ? s : best;
        s = (hi - up[x + 1]) * d;
        dir = s > best ? 7.0 : dir;
        dir_out[x] = dir;
    }
}

void FlowRouter::receivers_from(const double* h) {
    // Receivers and donor bits in one pass over rows: first the directions of
    // a row's inner cells (vectorised), then receivers and donor bits. A
    // cell's donor byte is written by the (up to 8) cells around it: inside a
    // band of rows only this band's iterations touch it, so the OR is plain;
    // in the two rows at each end of a band (shared with the neighbouring
    // bands) it is atomic. OR is commutative, so the bytes do not depend on
    // the split.
    const int W = width_, H = height_;
    std::fill(donors_.begin(), donors_.end(), std::uint8_t(0));
    std::int64_t off[8];
    for (int k = 0; k < 8; ++k) off[k] = std::int64_t(kDy[k]) * W + kDx[k];
    parallel_for(0, H, 8, [&](std::int64_t y0, std::int64_t y1) {
        std::vector<double> dirs(std::size_t(W), -1.0);
        for (std::int64_t y = y0; y < y1; ++y) {
            const bool inner_row = y > 0 && y < H - 1;
            const double* row = h + y * W;
            if (inner_row) inner_row_directions(row, row - W, row + W, W, dirs.data());
            const bool near_edge = y <= y0 + 1 || y >= y1 - 2;  // a receiver may lie in the rows shared with a band
            for (int x = 0; x < W; ++x) {
                const std::int64_t i = y * W + x;
                if (outlet_[std::size_t(i)]) {
                    receiver_[std::size_t(i)] = std::int32_t(i);
                    continue;
                }
                int dir = -1;
                if (inner_row && x > 0 && x < W - 1) {
                    dir = int(dirs[std::size_t(x)]);
                } else {
                    unsigned inside = 0;
                    for (int k = 0; k < 8; ++k) {
                        const int nx = x + kDx[k], ny = int(y) + kDy[k];
                        if (nx >= 0 && nx < W && ny >= 0 && ny < H) inside |= 1u << k;
                    }
                    dir = steepest(h[i], inside, [&](int k) { return h[i + off[k]]; });
                }
                if (dir < 0) {
                    receiver_[std::size_t(i)] = std::int32_t(i);
                    continue;
                }
                const std::int64_t to = i + off[dir];
                receiver_[std::size_t(i)] = std::int32_t(to);
                const auto bit = std::uint8_t(1u << ((dir + 4) & 7));  // seen from `to`, i is neighbour dir+4
                if (near_edge && (y + kDy[dir] <= y0 || y + kDy[dir] >= y1 - 1))
                    std::atomic_ref<std::uint8_t>(donors_[std::size_t(to)]).fetch_or(bit, std::memory_order_relaxed);
                else donors_[std::size_t(to)] = std::uint8_t(donors_[std::size_t(to)] | bit);
            }
        }
    });
}

void FlowRouter::find_roots() {
    // The cells that are their own receiver, in index order: counted and then written by fixed
    // blocks on every thread.
    constexpr std::int64_t kBlock = 1 << 16;
    const std::int64_t blocks = (std::int64_t(size_) + kBlock - 1) / kBlock;
    std::vector<std::int64_t> start(std::size_t(blocks) + 1, 0);
    const std::int32_t* rcv = receiver_.data();
    parallel_for(0, blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
        for (std::int64_t b = b0; b < b1; ++b) {
            std::int64_t count = 0;
            for (std::int64_t i = b * kBlock, e = std::min<std::int64_t>(std::int64_t(size_), i + kBlock); i < e; ++i)
                count += rcv[i] == i;
            start[std::size_t(b) + 1] = count;
        }
    });
    for (std::int64_t b = 0; b < blocks; ++b) start[std::size_t(b) + 1] += start[std::size_t(b)];
    roots_.resize(std::size_t(start[std::size_t(blocks)]));
    parallel_for(0, blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
        for (std::int64_t b = b0; b < b1; ++b) {
            std::int32_t* out = roots_.data() + start[std::size_t(b)];
            for (std::int64_t i = b * kBlock, e = std::min<std::int64_t>(std::int64_t(size_), i + kBlock); i < e; ++i)
                if (rcv[i] == i) *out++ = std::int32_t(i);
        }
    });
}

void FlowRouter::build_stack(bool label_basins) {
    const int W = width_;
    std::int64_t off[8];
    for (int k = 0; k < 8; ++k) off[k] = std::int64_t(kDy[k]) * W + kDx[k];
    basin_start_.assign(roots_.size() + 1, 0);
    // Depth-first walks from the roots, in root order. The roots are cut into
    // fixed groups; each group walks into its own buffer (in parallel), and
    // the buffers are joined in group order: the same stack as one walk over
    // all roots, whatever the thread count.
    const std::int64_t nr = std::int64_t(roots_.size());
    const std::int64_t groups = std::min<std::int64_t>(kChunks, nr);
    if (std::int64_t(walk_buffers_.size()) < groups) walk_buffers_.resize(std::size_t(groups));
    parallel_for(0, groups, 1, [&](std::int64_t g0, std::int64_t g1) {
        std::vector<std::int32_t> walk;
        walk.reserve(256);
        for (std::int64_t g = g0; g < g1; ++g) {
            auto& out = walk_buffers_[std::size_t(g)];
            out.clear();
            for (std::int64_t b = g * nr / groups; b < (g + 1) * nr / groups; ++b) {
                basin_start_[std::size_t(b)] = std::int64_t(out.size());  // within the group for now
                walk.push_back(roots_[std::size_t(b)]);
                while (!walk.empty()) {
                    const std::int32_t c = walk.back();
                    walk.pop_back();
                    out.push_back(c);
                    if (label_basins) basin_[std::size_t(c)] = std::int32_t(b);
                    unsigned m = donors_[std::size_t(c)];
                    while (m) {
                        const int k = std::countr_zero(m);
                        m &= m - 1;
                        walk.push_back(std::int32_t(c + off[k]));
                    }
                }
            }
        }
    });
    std::vector<std::int64_t> offset(std::size_t(groups) + 1, 0);
    for (std::int64_t g = 0; g < groups; ++g)
        offset[std::size_t(g + 1)] = offset[std::size_t(g)] + std::int64_t(walk_buffers_[std::size_t(g)].size());
    const std::size_t pos = std::size_t(offset[std::size_t(groups)]);
    if (pos != size_)
        throw std::logic_error("FlowRouter: the receivers hold a loop");  // cannot happen: drops are strict
    parallel_for(0, groups, 1, [&](std::int64_t g0, std::int64_t g1) {
        for (std::int64_t g = g0; g < g1; ++g) {
            const auto& buf = walk_buffers_[std::size_t(g)];
            std::copy(buf.begin(), buf.end(), stack_.begin() + offset[std::size_t(g)]);
            for (std::int64_t b = g * nr / groups; b < (g + 1) * nr / groups; ++b)
                basin_start_[std::size_t(b)] += offset[std::size_t(g)];
        }
    });
    basin_start_[roots_.size()] = std::int64_t(pos);
    // Groups of whole basins, about size/kChunks cells each: the work the
    // solver can share between threads (basins do not exchange water).
    chunks_.assign(1, 0);
    const std::int64_t target = std::max<std::int64_t>(1, std::int64_t(size_) / kChunks);
    for (std::size_t b = 1; b <= roots_.size(); ++b)
        if (basin_start_[b] - chunks_.back() >= target || b == roots_.size()) chunks_.push_back(basin_start_[b]);
}

void FlowRouter::route(double* h, Depressions mode) {
    receivers_from(h);
    find_roots();
    pits_ = 0;
    graph_pits_ = 0;
    for (const std::int32_t r : roots_) pits_ += outlet_[std::size_t(r)] ? 0 : 1;
    build_stack(pits_ > 0);
    if (pits_ > 0) resolve_pits(h, mode);
}

void FlowRouter::reroute(std::int32_t inside, std::int32_t across) {
    // Reverse the receivers from the pass cell down to the pit, send the pass
    // cell's water across, and keep the donor bits in step.
    const int W = width_;
    auto bit_from = [W](std::int32_t cell, std::int32_t to) {
        const int dx = cell % W - to % W, dy = cell / W - to / W;
        for (int k = 0; k < 8; ++k)
            if (kDx[k] == dx && kDy[k] == dy) return std::uint8_t(1u << k);
        return std::uint8_t(0);
    };
    std::int32_t prev = across, c = inside;
    for (;;) {
        const std::int32_t next = receiver_[std::size_t(c)];
        receiver_[std::size_t(c)] = prev;
        // Atomic: the first `prev` is another basin's cell, which its own reroute may change
        // at the same time (resolve_pits runs the basins in parallel).
        if (next != c)
            std::atomic_ref<std::uint8_t>(donors_[std::size_t(next)])
                .fetch_and(std::uint8_t(~bit_from(c, next)), std::memory_order_relaxed);
        std::atomic_ref<std::uint8_t>(donors_[std::size_t(prev)])
            .fetch_or(bit_from(c, prev), std::memory_order_relaxed);
        if (next == c) break;
        prev = c;
        c = next;
    }
}

void FlowRouter::resolve_pits(double* h, Depressions mode) {
    const int W = width_, H = height_;
    const std::size_t nb = roots_.size();
    // Nodes of the basin graph: 0 = the sea (every outlet basin), 1..P = the
    // pit basins in index order of their pits. Every pit goes to the graph:
    // its result is then a pure function of the heights (the minimum spanning
    // tree under link_before's total order), which a tiled run reproduces
    // from its tiles' links (tiled.hpp).
    std::vector<std::int32_t> pending;
    for (std::size_t b = 0; b < nb; ++b)
        if (!outlet_[std::size_t(roots_[b])]) pending.push_back(std::int32_t(b));
    graph_pits_ = std::int64_t(pending.size());
    std::vector<std::int32_t> node(nb, 0), node_basin{0};
    std::int32_t nodes = 1;
    for (const std::int32_t b : pending) {
        node[std::size_t(b)] = nodes++;
        node_basin.push_back(b);
    }

    // Links between a pit basin and each basin next to it, found from the pit
    // basins' own cells (their segments of the stack: basins are contiguous
    // there), all 8 neighbours. A pair of pit basins is taken by the lower
    // node, which sees every edge between the two (each has one end in it); a
    // pit basin and the sea by the pit basin. Each basin keeps only its lowest
    // link per pair (by the total order the global sort uses), found through a
    // per-thread table by node (NodeSlots), so every link is a pair's lowest and
    // comes once, whatever the grouping. The cost follows the lakes' size, not
    // the map's.
    const std::int64_t np = std::int64_t(pending.size());
    const std::int64_t link_groups = std::min<std::int64_t>(kChunks, np);
    std::vector<std::vector<Link>> per_block(static_cast<std::size_t>(link_groups));
    std::int64_t off[8];
    for (int k = 0; k < 8; ++k) off[k] = std::int64_t(kDy[k]) * W + kDx[k];
    const RowOf row_of(W);
    constexpr std::int64_t kAhead = 12;
    const std::uint64_t epoch = std::uint64_t(link_epoch.fetch_add(1, std::memory_order_relaxed) + 1u) << 32;
    parallel_for(0, link_groups, 1, [&](std::int64_t g0, std::int64_t g1) {
        NodeSlots& slots = node_slots;
        if (slots.stamp.size() < std::size_t(nodes)) {
            slots.stamp.assign(std::size_t(nodes), 0);  // 0: never a stamp (the epoch is ≥ 1)
            slots.at.resize(std::size_t(nodes));
        }
        std::uint64_t* const stamp = slots.stamp.data();
        std::int32_t* const at = slots.at.data();
        for (std::int64_t g = g0; g < g1; ++g) {
            auto& out = per_block[std::size_t(g)];
            for (std::int64_t p = g * np / link_groups; p < (g + 1) * np / link_groups; ++p) {
                const std::size_t b = std::size_t(pending[std::size_t(p)]);
                const std::int32_t ni = node[b];
                const std::uint64_t key = epoch | std::uint64_t(p + 1);
                const auto bi = std::int32_t(b);
                const std::int64_t s_end = basin_start_[b + 1];
                for (std::int64_t s = basin_start_[b]; s < s_end; ++s) {
                    const std::int32_t i = stack_[std::size_t(s)];
                    if (s + kAhead < s_end) {
                        // The stack jumps between rows: fetch the basin labels around a cell
                        // a few cells ahead (its row and the two next to it).
                        const std::int64_t a = stack_[std::size_t(s + kAhead)];
                        __builtin_prefetch(&basin_[std::size_t(a)]);
                        if (a >= W) __builtin_prefetch(&basin_[std::size_t(a - W)]);
                        if (a + W < std::int64_t(size_)) __builtin_prefetch(&basin_[std::size_t(a + W)]);
                    }
                    const double hi = h[i];
                    const auto visit = [&](std::int32_t j) __attribute__((always_inline)) {
                        const std::int32_t bj = basin_[std::size_t(j)];
                        if (bj == bi) return;  // most neighbours, in a large basin
                        const std::int32_t nj = node[std::size_t(bj)];
                        if (nj != 0 && nj < ni) return;
                        const double hj = h[j];
                        const Link l = nj == 0 ? Link{std::max(hi, hj), std::min(hi, hj), 0, ni, j, i}
                                               : Link{std::max(hi, hj), std::min(hi, hj), ni, nj, i, j};
                        if (stamp[nj] != key) {  // the first link of this basin to node nj
                            stamp[nj] = key;
                            at[nj] = std::int32_t(out.size());
                            out.push_back(l);
                        } else if (Link& kept = out[std::size_t(at[nj])]; link_before(l, kept)) {
                            kept = l;
                        }
                    };
                    const int y = row_of(i), x = i - y * W;
                    if (x > 0 && x < W - 1 && y > 0 && y < H - 1) {
                        for (int k = 0; k < 8; ++k) visit(std::int32_t(i + off[k]));
                        continue;
                    }
                    for (int k = 0; k < 8; ++k) {
                        const int nx = x + kDx[k], ny = y + kDy[k];
                        if (nx < 0 || nx >= W || ny < 0 || ny >= H) continue;
                        visit(std::int32_t(std::int64_t(ny) * W + nx));
                    }
                }
            }
        }
    });
    const auto& per_pit = per_block;
    std::vector<Link> links;
    std::size_t total = 0;
    for (const auto& v : per_pit) total += v.size();
    links.reserve(total);
    for (const auto& v : per_pit) links.insert(links.end(), v.begin(), v.end());
    per_block.clear();
    const BasinTree tree = solve_basin_graph(links, nodes);
    const auto& level = tree.level;
    const auto& out_link = tree.out_link;
    const auto& queue = tree.order;

    // Fill, then carve. Each pit basin's cells are its own (the fill, the
    // reversed path from its pass cell down to its pit); only the donor bits
    // of the cell across, in another basin, are shared, and they change by
    // atomic ORs and ANDs of distinct bits: the basins are done in parallel,
    // with the same bytes as one after the other. resolved_ keeps the order of
    // the walk from the sea (parents before children), which patch_stack needs.
    resolved_.resize(queue.empty() ? 0 : queue.size() - 1);
    parallel_for(1, std::int64_t(queue.size()), 256, [&](std::int64_t q0, std::int64_t q1) {
        for (std::int64_t q = q0; q < q1; ++q) {
            const std::int32_t v = queue[std::size_t(q)];
            const std::size_t b = std::size_t(node_basin[std::size_t(v)]);
            const Link& l = links[std::size_t(out_link[std::size_t(v)])];
            const auto in = std::int32_t(l.a == v ? l.i : l.j), across = std::int32_t(l.a == v ? l.j : l.i);
            if (mode == Depressions::fill) {
                const double lv = level[std::size_t(v)];
                for (std::int64_t s = basin_start_[b]; s < basin_start_[b + 1]; ++s) {
                    const std::int32_t c = stack_[std::size_t(s)];
                    if (h[c] < lv) h[c] = lv;
                }
            }
            reroute(in, across);
            resolved_[std::size_t(q - 1)] = {std::int32_t(b), in, across};
        }
    });

    patch_stack();
}

void FlowRouter::patch_stack() {
    // The stack through the passes, without walking the whole map again: an
    // outlet basin's cells keep their order (their receivers did not change),
    // and each pit basin, re-walked from its pass cell (the walk kept to the
    // basin's own cells), follows the outlet basin its water now reaches, in
    // the order the pits were resolved (a basin only spills into one that
    // already drains, so receivers still come first). Each outlet basin and
    // the pit basins behind it stay one contiguous block: the blocks are
    // what chunks() groups for the threads.
    const std::size_t nb = roots_.size();
    std::vector<std::int32_t> final_basin(nb, -1);  // the outlet basin each basin drains to
    for (std::size_t b = 0; b < nb; ++b)
        if (outlet_[std::size_t(roots_[b])]) final_basin[b] = std::int32_t(b);
    std::vector<std::int64_t> first(nb + 1, 0);  // resolved_ bucketed by outlet basin, resolution order kept
    for (const Resolved& r : resolved_) {
        const std::int32_t f = final_basin[std::size_t(basin_[std::size_t(r.across)])];
        final_basin[std::size_t(r.basin)] = f;
        ++first[std::size_t(f) + 1];
    }
    for (std::size_t b = 0; b < nb; ++b) first[b + 1] += first[b];
    std::vector<std::int32_t> attached(resolved_.size());
    {
        std::vector<std::int64_t> fill(first.begin(), first.end() - 1);
        for (std::size_t r = 0; r < resolved_.size(); ++r)
            attached[std::size_t(fill[std::size_t(final_basin[std::size_t(resolved_[r].basin)])]++)] = std::int32_t(r);
    }
    // Block of each outlet basin: where it starts in the new stack.
    std::vector<std::int32_t> outlets;
    std::vector<std::int64_t> block_start{0};
    for (std::size_t b = 0; b < nb; ++b) {
        if (final_basin[b] != std::int32_t(b)) continue;
        std::int64_t cells = basin_start_[b + 1] - basin_start_[b];
        for (std::int64_t a = first[b]; a < first[b + 1]; ++a) {
            const std::size_t pb = std::size_t(resolved_[std::size_t(attached[std::size_t(a)])].basin);
            cells += basin_start_[pb + 1] - basin_start_[pb];
        }
        outlets.push_back(std::int32_t(b));
        block_start.push_back(block_start.back() + cells);
    }
    if (std::size_t(block_start.back()) != size_) throw std::logic_error("FlowRouter: a pit basin was not resolved");
    next_stack_.resize(size_);
    std::int64_t off[8];
    for (int k = 0; k < 8; ++k) off[k] = std::int64_t(kDy[k]) * width_ + kDx[k];
    std::atomic<bool> bad_walk{false};
    parallel_for(0, std::int64_t(outlets.size()), 16, [&](std::int64_t o0, std::int64_t o1) {
        std::vector<std::int32_t> walk;
        for (std::int64_t o = o0; o < o1; ++o) {
            const std::size_t b = std::size_t(outlets[std::size_t(o)]);
            std::int32_t* out = next_stack_.data() + block_start[std::size_t(o)];
            out = std::copy(stack_.begin() + basin_start_[b], stack_.begin() + basin_start_[b + 1], out);
            for (std::int64_t a = first[b]; a < first[b + 1]; ++a) {
                const Resolved& r = resolved_[std::size_t(attached[std::size_t(a)])];
                const std::int64_t cells = basin_start_[std::size_t(r.basin) + 1] - basin_start_[std::size_t(r.basin)];
                std::int64_t written = 0;
                walk.push_back(r.inside);
                while (!walk.empty()) {
                    const std::int32_t c = walk.back();
                    walk.pop_back();
                    if (written++ == cells) break;  // cannot happen: the basin's cells form a tree under the pass
                    *out++ = c;
                    unsigned m = donors_[std::size_t(c)];
                    while (m) {
                        const int k = std::countr_zero(m);
                        m &= m - 1;
                        const std::int32_t d = std::int32_t(c + off[k]);
                        if (basin_[std::size_t(d)] == r.basin) walk.push_back(d);
                    }
                }
                walk.clear();
                if (written != cells) bad_walk.store(true, std::memory_order_relaxed);
            }
        }
    });
    if (bad_walk.load()) throw std::logic_error("FlowRouter: a re-routed pit basin is not a tree under its pass");
    stack_.swap(next_stack_);
    chunks_.assign(1, 0);
    const std::int64_t target = std::max<std::int64_t>(1, std::int64_t(size_) / kChunks);
    for (std::size_t o = 1; o < block_start.size(); ++o)
        if (block_start[o] - chunks_.back() >= target || o + 1 == block_start.size()) chunks_.push_back(block_start[o]);
}

void FlowRouter::accumulate(const double* weight) {
    const double a0 = cell_ * cell_;
    // Cells, not m²: every cell starts with 1, or its weight (a sequential fill, not one in stack order)...
    parallel_for(0, std::int64_t(size_), 1 << 16, [&](std::int64_t b, std::int64_t e) {
        if (weight) std::copy(weight + b, weight + e, area_.begin() + b);
        else std::fill(area_.begin() + b, area_.begin() + e, 1.0);
    });
    // ... and passes its total to its receiver, donors first (reverse stack order).
    // Whole numbers below 2^53 add exactly in any order, so a tiled run that adds
    // its tiles' partial counts gets these bits (floating-point m² would round).
    // Weights round, but each basin's sums run in one fixed order on one thread.
    const std::int64_t groups = std::int64_t(chunks_.size()) - 1;
    const std::int32_t* stack = stack_.data();
    const std::int32_t* rcv = receiver_.data();
    double* area = area_.data();
    parallel_for(0, groups, 1, [&](std::int64_t g0, std::int64_t g1) {
        for (std::int64_t g = g0; g < g1; ++g) {
            const std::int64_t b = chunks_[std::size_t(g)], e = chunks_[std::size_t(g + 1)];
            // A cell's count is whole once the walk reaches it (its donors come after it in the
            // stack): it goes on to the receiver and becomes m² in the same visit.
            for (std::int64_t s = e; s-- > b;) {
                const std::int32_t i = stack[s], r = rcv[i];
                const double c = area[i];
                if (r != i) area[r] += c;
                area[i] = c * a0;
            }
        }
    });
}

void FlowRouter::accumulate_multiple(const double* h, double exponent, const double* weight) {
    const int W = width_, H = height_;
    const double a0 = cell_ * cell_;
    const double inv[8] = {1.0, 1.0 / kSqrt2, 1.0, 1.0 / kSqrt2, 1.0, 1.0 / kSqrt2, 1.0, 1.0 / kSqrt2};
    std::int64_t off[8];
    for (int k = 0; k < 8; ++k) off[k] = std::int64_t(kDy[k]) * W + kDx[k];
    lower_.resize(size_);
    pending_.resize(size_);
    order_.resize(size_);
    // 1. Which neighbours each cell sends to (outlets send nothing).
    parallel_for(0, H, 8, [&](std::int64_t y0, std::int64_t y1) {
        for (std::int64_t y = y0; y < y1; ++y)
            for (int x = 0; x < W; ++x) {
                const std::int64_t i = y * W + x;
                unsigned m = 0;
                if (!outlet_[std::size_t(i)])
                    for (int k = 0; k < 8; ++k) {
                        const int nx = x + kDx[k], ny = int(y) + kDy[k];
                        if (nx < 0 || nx >= W || ny < 0 || ny >= H) continue;
                        if (h[i + off[k]] < h[i]) m |= 1u << k;
                    }
                lower_[std::size_t(i)] = std::uint8_t(m);
            }
    });
    // 2. How many donors each cell waits for, counted from the cell's side
    // (neighbour j sends here if this cell is in j's lower set, or j has no
    // lower neighbour and this is j's D8 receiver): no atomics.
    parallel_for(0, H, 8, [&](std::int64_t y0, std::int64_t y1) {
        for (std::int64_t y = y0; y < y1; ++y)
            for (int x = 0; x < W; ++x) {
                const std::int64_t i = y * W + x;
                int count = 0;
                for (int k = 0; k < 8; ++k) {
                    const int nx = x + kDx[k], ny = int(y) + kDy[k];
                    if (nx < 0 || nx >= W || ny < 0 || ny >= H) continue;
                    const std::int64_t j = i + off[k];
                    if (outlet_[std::size_t(j)]) continue;
                    const unsigned mj = lower_[std::size_t(j)];
                    // Seen from j, this cell is neighbour (k + 4) mod 8.
                    if (mj ? (mj >> ((k + 4) & 7)) & 1u : receiver_[std::size_t(j)] == i) ++count;
                }
                pending_[std::size_t(i)] = std::uint8_t(count);
                area_[std::size_t(i)] = weight ? a0 * weight[i] : a0;
            }
    });
    // 3. Kahn: a cell passes its area on once all its donors have added theirs.
    std::size_t tail = 0;
    for (std::size_t i = 0; i < size_; ++i)
        if (pending_[i] == 0) order_[tail++] = std::int32_t(i);
    double w[8];
    for (std::size_t q = 0; q < tail; ++q) {
        const std::int32_t i = order_[q];
        if (outlet_[std::size_t(i)]) continue;
        const double ai = area_[std::size_t(i)];
        const unsigned m = lower_[std::size_t(i)];
        auto give = [&](std::int64_t j, double amount) {
            area_[std::size_t(j)] += amount;
            if (--pending_[std::size_t(j)] == 0) order_[tail++] = std::int32_t(j);
        };
        if (m == 0) {
            const std::int32_t r = receiver_[std::size_t(i)];
            if (r != i) give(r, ai);
            continue;
        }
        if ((m & (m - 1)) == 0) {  // one lower neighbour: all of it (no pow)
            give(i + off[std::countr_zero(m)], ai);
            continue;
        }
        double sum = 0.0;
        for (int k = 0; k < 8; ++k) {
            if (!((m >> k) & 1u)) continue;
            const double slope = (h[i] - h[i + off[k]]) * inv[k];
            w[k] = exponent == 1.0 ? slope : std::pow(slope, exponent);
            sum += w[k];
        }
        for (int k = 0; k < 8; ++k)
            if ((m >> k) & 1u) give(i + off[k], ai * (w[k] / sum));
    }
    if (tail != size_) throw std::logic_error("FlowRouter: the multiple-flow graph holds a loop");
}

}  // namespace orogen::landscape
