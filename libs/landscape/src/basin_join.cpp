// basin_join.cpp — the basin graph of a tiled run, solved mostly on the tiles (see basin_join.hpp).
#include <orogen/landscape/basin_join.hpp>

#include <algorithm>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <unordered_set>

namespace orogen::landscape {

namespace {

constexpr double kNoLevel = -std::numeric_limits<double>::infinity();

/// The cells of link `l` seen from basin `from`: {its cell in `from`, the cell across}.
std::pair<std::int64_t, std::int64_t> cells_from(const Link& l, std::int64_t from) {
    return l.a == from ? std::pair{l.i, l.j} : std::pair{l.j, l.i};
}

}  // namespace

TileForest contract_tile(std::vector<Link> links, const std::function<bool(std::int64_t)>& closed) {
    std::sort(links.begin(), links.end(), link_before);
    TileForest f;
    f.node.reserve(links.size());
    auto node_of = [&](std::int64_t b) {
        const auto [it, fresh] = f.node.try_emplace(b, std::int32_t(f.basin.size()));
        if (fresh) {
            f.basin.push_back(b);
            f.closed.push_back(b >= 0 && closed(b) ? 1 : 0);
        }
        return it->second;
    };
    std::vector<std::int32_t> ends(2 * links.size());
    for (std::size_t e = 0; e < links.size(); ++e) {
        ends[2 * e] = node_of(links[e].a);
        ends[2 * e + 1] = node_of(links[e].b);
    }
    const std::size_t n = f.basin.size();

    // Kruskal, taking a link at once when one side holds closed basins only.
    std::vector<std::int32_t> parent(n);
    std::iota(parent.begin(), parent.end(), 0);
    std::vector<std::uint8_t> only_closed(f.closed);  // per root
    std::vector<std::size_t> later;  // deferred, in the total order
    for (std::size_t e = 0; e < links.size(); ++e) {
        const std::int32_t ra = find_root(parent, ends[2 * e]), rb = find_root(parent, ends[2 * e + 1]);
        if (ra == rb) continue;
        if (!only_closed[std::size_t(ra)] && !only_closed[std::size_t(rb)]) {
            later.push_back(e);
            continue;
        }
        parent[std::size_t(ra)] = rb;
        only_closed[std::size_t(rb)] = only_closed[std::size_t(ra)] && only_closed[std::size_t(rb)];
        f.taken.push_back(links[e]);
        f.taken_ends.push_back(ends[2 * e]);
        f.taken_ends.push_back(ends[2 * e + 1]);
    }
    f.adjacent_start.assign(n + 1, 0);
    for (const std::int32_t v : f.taken_ends) ++f.adjacent_start[std::size_t(v) + 1];
    for (std::size_t v = 0; v < n; ++v) f.adjacent_start[v + 1] += f.adjacent_start[v];
    f.adjacent.resize(f.taken_ends.size());
    {
        std::vector<std::int64_t> at(f.adjacent_start.begin(), f.adjacent_start.end() - 1);
        for (std::size_t t = 0; t < f.taken.size(); ++t) {
            f.adjacent[std::size_t(at[std::size_t(f.taken_ends[2 * t])]++)] = std::int32_t(t);
            f.adjacent[std::size_t(at[std::size_t(f.taken_ends[2 * t + 1])]++)] = std::int32_t(t);
        }
    }

    // Each component from its anchor: the walk's order, each node's parent and the link to it.
    f.anchor.assign(n, -1);
    std::vector<std::int32_t> order, up(n, -1), up_link(n, -1);
    order.reserve(n);
    for (std::size_t r = 0; r < n; ++r) {
        if (f.closed[r]) continue;
        f.anchors.push_back(f.basin[r]);
        f.anchor[r] = std::int32_t(r);
        order.push_back(std::int32_t(r));
        for (std::size_t q = order.size() - 1; q < order.size(); ++q) {
            const std::int32_t v = order[q];
            for (std::int64_t a = f.adjacent_start[std::size_t(v)]; a < f.adjacent_start[std::size_t(v) + 1]; ++a) {
                const std::int32_t t = f.adjacent[std::size_t(a)];
                const std::int32_t u = f.taken_ends[2 * std::size_t(t)] == v ? f.taken_ends[2 * std::size_t(t) + 1]
                                                                             : f.taken_ends[2 * std::size_t(t)];
                if (f.anchor[std::size_t(u)] >= 0) continue;
                f.anchor[std::size_t(u)] = std::int32_t(r);
                up[std::size_t(u)] = v;
                up_link[std::size_t(u)] = t;
                order.push_back(u);
            }
        }
    }
    if (order.size() != n) throw std::logic_error("stream-power: closed basins of a tile with no way out of it");

    // The deferred links, the lowest per pair of components; their ends and the anchors are terminals.
    std::vector<std::uint8_t> terminal(n, 0);
    for (std::size_t r = 0; r < n; ++r) terminal[r] = f.closed[r] ? 0 : 1;
    {
        std::unordered_set<std::uint64_t> pairs;
        for (const std::size_t e : later) {
            const std::int32_t x = f.anchor[std::size_t(ends[2 * e])], y = f.anchor[std::size_t(ends[2 * e + 1])];
            const std::uint64_t key =
                (std::uint64_t(std::uint32_t(std::min(x, y))) << 32) | std::uint32_t(std::max(x, y));
            if (!pairs.insert(key).second) continue;
            f.deferred.push_back(links[e]);
            terminal[std::size_t(ends[2 * e])] = terminal[std::size_t(ends[2 * e + 1])] = 1;
        }
    }

    // The forest reduced to the terminals: the nodes with a terminal at or
    // below them, of which the keys are the terminals and the forks; between
    // a key and the nearest key above it, the highest pass on the way.
    std::vector<std::int32_t> below(n, 0), branches(n, 0);
    for (std::size_t q = n; q-- > 0;) {
        const auto v = std::size_t(order[q]);
        below[v] += terminal[v];
        if (up[v] >= 0 && below[v] > 0) {
            below[std::size_t(up[v])] += below[v];
            ++branches[std::size_t(up[v])];
        }
    }
    std::vector<std::int32_t> up_key(n, -1), first(n, -1);
    std::vector<double> highest(n, kNoLevel);
    for (const std::int32_t vi : order) {
        const auto v = std::size_t(vi);
        if (up[v] < 0 || below[v] == 0) continue;
        const auto p = std::size_t(up[v]);
        const bool p_key = terminal[p] || branches[p] >= 2;
        const double pass = f.taken[std::size_t(up_link[v])].pass;
        up_key[v] = p_key ? std::int32_t(p) : up_key[p];
        highest[v] = p_key ? pass : std::max(pass, highest[p]);
        first[v] = p_key ? up_link[v] : first[p];
        if (terminal[v] || branches[v] >= 2)
            f.edges.push_back(
                {f.basin[v], f.basin[std::size_t(up_key[v])], highest[v], f.taken[std::size_t(first[v])]});
    }
    return f;
}

std::vector<KeyExit> join_tiles(std::vector<Link> deferred, const std::vector<ForestEdge>& edges,
                                const std::vector<std::int64_t>& anchors) {
    std::vector<std::int64_t> ids{-1};
    ids.insert(ids.end(), anchors.begin(), anchors.end());
    for (const Link& l : deferred) ids.insert(ids.end(), {l.a, l.b});
    for (const ForestEdge& e : edges) ids.insert(ids.end(), {e.lower, e.upper});
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    auto index = [&](std::int64_t b) {
        return std::int32_t(std::lower_bound(ids.begin(), ids.end(), b) - ids.begin());
    };
    const std::size_t n = ids.size();
    std::vector<std::int32_t> parent(n);
    std::iota(parent.begin(), parent.end(), 0);
    struct Way {
        std::int32_t to;
        bool forest;
        std::int32_t item;  // index into edges or deferred
    };
    std::vector<std::vector<Way>> adjacent(n);
    // The forests' edges are all in the tree; the deferred links by Kruskal in the total order.
    for (std::size_t k = 0; k < edges.size(); ++k) {
        const std::int32_t u = index(edges[k].lower), v = index(edges[k].upper);
        const std::int32_t ru = find_root(parent, u), rv = find_root(parent, v);
        if (ru == rv) throw std::logic_error("stream-power: the tiles' basin forests hold a loop");
        parent[std::size_t(ru)] = rv;
        adjacent[std::size_t(u)].push_back({v, true, std::int32_t(k)});
        adjacent[std::size_t(v)].push_back({u, true, std::int32_t(k)});
    }
    std::sort(deferred.begin(), deferred.end(), link_before);
    for (std::size_t k = 0; k < deferred.size(); ++k) {
        const std::int32_t u = index(deferred[k].a), v = index(deferred[k].b);
        const std::int32_t ru = find_root(parent, u), rv = find_root(parent, v);
        if (ru == rv) continue;
        parent[std::size_t(ru)] = rv;
        adjacent[std::size_t(u)].push_back({v, false, std::int32_t(k)});
        adjacent[std::size_t(v)].push_back({u, false, std::int32_t(k)});
    }
    // Oriented from the sea (node 0): levels are the highest pass on the way out.
    std::vector<KeyExit> out;
    out.reserve(n);
    std::vector<double> level(n, kNoLevel);
    std::vector<std::uint8_t> seen(n, 0);
    std::vector<std::int32_t> queue{0};
    seen[0] = 1;
    out.push_back({-1, kNoLevel, -2, -1, -1});
    for (std::size_t q = 0; q < queue.size(); ++q) {
        const auto v = std::size_t(queue[q]);
        for (const Way& w : adjacent[v]) {
            const auto u = std::size_t(w.to);
            if (seen[u]) continue;
            seen[u] = 1;
            queue.push_back(w.to);
            KeyExit k{ids[u], kNoLevel, ids[v], -1, -1};
            if (w.forest) {
                const ForestEdge& e = edges[std::size_t(w.item)];
                level[u] = std::max(e.pass, level[v]);
                if (e.upper == ids[u]) std::tie(k.in, k.across) = cells_from(e.first, ids[u]);
            } else {
                const Link& l = deferred[std::size_t(w.item)];
                level[u] = std::max(l.pass, level[v]);
                std::tie(k.in, k.across) = cells_from(l, ids[u]);
            }
            k.level = level[u];
            out.push_back(k);
        }
    }
    if (queue.size() != n) throw std::logic_error("FlowRouter: a pit basin has no way to an outlet");
    return out;
}

std::vector<BasinExit> orient_tile(const TileForest& f, const std::unordered_map<std::int64_t, KeyExit>& keys) {
    const std::size_t n = f.basin.size();
    std::vector<BasinExit> out;
    std::vector<double> level(n, kNoLevel);
    std::vector<std::uint8_t> seen(n, 0);
    std::vector<std::int32_t> queue;
    std::size_t reached = 0;
    for (std::size_t v = 0; v < n; ++v) {
        const auto it = keys.find(f.basin[v]);
        if (it == keys.end()) continue;
        const KeyExit& k = it->second;
        // The component's top: the key whose way out leaves the component.
        if (k.parent != -2) {
            const auto p = f.node.find(k.parent);
            if (p != f.node.end() && f.anchor[std::size_t(p->second)] == f.anchor[v]) continue;
        }
        if (seen[v]) throw std::logic_error("stream-power: a component of a tile's basin forest has two ways out");
        seen[v] = 1;
        level[v] = k.level;
        if (f.closed[v]) {
            if (k.in < 0) throw std::logic_error("stream-power: a closed basin's way out is not a link");
            out.push_back({f.basin[v], k.level, k.in, k.across});
        }
        queue.assign(1, std::int32_t(v));
        for (std::size_t q = 0; q < queue.size(); ++q) {
            const auto x = std::size_t(queue[q]);
            for (std::int64_t a = f.adjacent_start[x]; a < f.adjacent_start[x + 1]; ++a) {
                const auto t = std::size_t(f.adjacent[std::size_t(a)]);
                const auto u =
                    std::size_t(f.taken_ends[2 * t] == std::int32_t(x) ? f.taken_ends[2 * t + 1] : f.taken_ends[2 * t]);
                if (seen[u]) continue;
                seen[u] = 1;
                const Link& l = f.taken[t];
                level[u] = std::max(l.pass, level[x]);
                if (f.closed[u]) {
                    const auto [in, across] = cells_from(l, f.basin[u]);
                    out.push_back({f.basin[u], level[u], in, across});
                }
                queue.push_back(std::int32_t(u));
            }
        }
        reached += queue.size();
    }
    if (reached != n) throw std::logic_error("stream-power: a component of a tile's basin forest has no way out");
    return out;
}

}  // namespace orogen::landscape
