// tiled.cpp — the stream-power model on one rank's tile (see tiled.hpp).
#include <orogen/landscape/tiled.hpp>

#include <orogen/solvers/threshold_slopes.hpp>

#include <orogen/landscape/basin_join.hpp>

#include <orogen/climate/orographic_rain.hpp>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <stdexcept>
#include <type_traits>
#include <unordered_map>
#include <unordered_set>

namespace orogen::landscape {

namespace {

// Messages between the ranks: arrays of plain records, back to back.
template <typename T>
void put(std::string& out, const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    const std::uint64_t n = v.size();
    out.append(reinterpret_cast<const char*>(&n), sizeof n);
    out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}

template <typename T>
std::vector<T> take(const std::string& in, std::size_t& at) {
    std::uint64_t n = 0;
    if (at + sizeof n > in.size()) throw std::logic_error("stream-power: a short message between ranks");
    std::memcpy(&n, in.data() + at, sizeof n);
    at += sizeof n;
    if (at + n * sizeof(T) > in.size()) throw std::logic_error("stream-power: a short message between ranks");
    std::vector<T> v(static_cast<std::size_t>(n));
    if (n) std::memcpy(v.data(), in.data() + at, std::size_t(n) * sizeof(T));
    at += std::size_t(n) * sizeof(T);
    return v;
}

struct EdgeRecord {  // an edge cell and the end of its local tree
    std::int64_t cell, tree, next;
};

struct ExitRecord {  // an exit: the cells it drains (its tile's count) and where they go
    std::int64_t cell;
    double count;
    std::int64_t next;
};

struct Piece {  // a piece of a path reversed from a pass to its pit: from `start`, which now drains to `prev`
    std::int64_t start, prev;
};

struct ExitBasin {  // an exit and the basin (pit or outlet) its water reaches
    std::int64_t exit, basin;
};

struct Lowest {  // a tile's lowest cell
    double h;
    std::int64_t cell;
};

struct Inflow {
    std::int64_t cell;
    double count;
};

/// Whole-grid position (x, y) of neighbour k of (x, y) exists.
bool inside(int x, int y, int k, int W, int H) {
    const int nx = x + kDx[k], ny = y + kDy[k];
    return nx >= 0 && nx < W && ny >= 0 && ny < H;
}

int direction_to(std::int64_t from, std::int64_t to, int W) {
    const auto dx = int(to % W - from % W), dy = int(to / W - from / W);
    for (int k = 0; k < 8; ++k)
        if (kDx[k] == dx && kDy[k] == dy) return k;
    throw std::logic_error("stream-power: a re-routed cell's new receiver is not its neighbour");
}

}  // namespace

std::string untiled_because(const Settings& s) {
    if (s.mfd_exponent > 0.0) return "routing=mfd is not tiled yet";
    if (s.deposition > 0.0) return "deposition > 0 is not tiled yet";
    if (s.glaciers.any()) return "glaciers are not tiled yet";
    return "";
}

TiledModel::TiledModel(Tiling& tiles, double cell, std::vector<double> heights, std::vector<double> uplift,
                       const Settings& settings)
    : tiles_(tiles), own_(tiles.owned()), grown_(tiles.ghosted()), W_(tiles.grid_width()), H_(tiles.grid_height()),
      cell_(cell), settings_(settings), h_(std::move(heights)), uplift_(std::move(uplift)) {
    const std::size_t n = std::size_t(own_.width) * std::size_t(own_.height);
    if (h_.size() != n) throw std::invalid_argument("landscape::TiledModel: heights are not the tile's size");
    if (!uplift_.empty() && uplift_.size() != n)
        throw std::invalid_argument("landscape::TiledModel: uplift is not the tile's size");
    if (!untiled_because(settings).empty())
        throw std::invalid_argument("landscape::TiledModel: " + untiled_because(settings));
    if (!settings.open.any()) {
        // The lowest cell of the whole grid (lowest index among equals), as lowest_cell().
        Lowest mine{std::numeric_limits<double>::infinity(), -1};
        for (std::size_t l = 0; l < n; ++l)
            if (mine.cell < 0 || h_[l] < mine.h) mine = {h_[l], global(l)};
        std::string bytes;
        put(bytes, std::vector<Lowest>{mine});
        const auto all = joined([&] { return tiles_.gather(bytes, Tiling::Gather::to_rank0); });
        std::string answer;
        if (tiles_.rank() == 0) {
            Lowest best{0.0, -1};
            for (const auto& b : all) {
                std::size_t at = 0;
                for (const Lowest& p : take<Lowest>(b, at))
                    if (best.cell < 0 || p.h < best.h || (p.h == best.h && p.cell < best.cell)) best = p;
            }
            put(answer, std::vector<std::int64_t>{best.cell});
        }
        joined([&] { return tiles_.share_from_rank0(answer); });
        std::size_t at = 0;
        sink_ = take<std::int64_t>(answer, at).at(0);
    }
    outlet_.resize(n);
    for (std::size_t l = 0; l < n; ++l) outlet_[l] = outlet_at(global(l)) ? 1 : 0;
    dir_.resize(n);
    donors_.resize(n);
    tree_of_.resize(n);
    stack_.resize(n);
    count_.resize(n);
    area_.resize(n);
    grown_h_.resize(std::size_t(grown_.width) * std::size_t(grown_.height));
    for (int y = 0; y < own_.height; ++y)
        for (int x = 0; x < own_.width; ++x)
            if (y == 0 || y == own_.height - 1 || x == 0 || x == own_.width - 1)
                edge_.push_back(std::int32_t(std::int64_t(y) * own_.width + x));
    pow_table_ = area_power_table(cell, settings.area_exponent, inverse_channel_area(settings));
    uplifted_.assign(n, 0.0);
    if (settings.diffusivity > 0.0)
        diffusion_ = std::make_unique<solvers::diffusion::Solver>(tiles, cell, hillslope_settings(settings));
}

std::int64_t TiledModel::global(std::size_t l) const {
    const auto x = std::int64_t(l % std::size_t(own_.width)), y = std::int64_t(l / std::size_t(own_.width));
    return (own_.y0 + y) * W_ + own_.x0 + x;
}

bool TiledModel::outlet_at(std::int64_t g) const {
    if (!settings_.open.any()) return g == sink_;
    const auto x = int(g % W_), y = int(g / W_);
    const OpenSides& o = settings_.open;
    return (y == 0 && o.north) || (y == H_ - 1 && o.south) || (x == 0 && o.west) || (x == W_ - 1 && o.east);
}

std::int64_t TiledModel::local_of(std::int64_t g) const {
    const int x = int(g % W_) - own_.x0, y = int(g / W_) - own_.y0;
    if (x < 0 || x >= own_.width || y < 0 || y >= own_.height) return -1;
    return std::int64_t(y) * own_.width + x;
}

std::size_t TiledModel::grown_index(std::size_t l) const {
    const auto x = std::size_t(l % std::size_t(own_.width)), y = std::size_t(l / std::size_t(own_.width));
    return (y + std::size_t(own_.y0 - grown_.y0)) * std::size_t(grown_.width) + x + std::size_t(own_.x0 - grown_.x0);
}

std::int64_t TiledModel::owned_neighbour(std::size_t l, int k) const {
    const int x = int(l % std::size_t(own_.width)) + kDx[k], y = int(l / std::size_t(own_.width)) + kDy[k];
    if (x < 0 || x >= own_.width || y < 0 || y >= own_.height) return -1;
    return std::int64_t(y) * own_.width + x;
}

std::int64_t TiledModel::receiver_global(std::size_t l) const {
    const int k = dir_[l];
    if (k < 0) return -1;
    return global(l) + std::int64_t(kDy[k]) * W_ + kDx[k];
}

std::int64_t TiledModel::first_non_finite() const {
    for (std::size_t l = 0; l < h_.size(); ++l)
        if (!std::isfinite(h_[l])) return std::int64_t(l);
    return -1;
}

// ------------------------------------------------------------------ routing

void TiledModel::directions() {
    // The tile's heights with their halo are in grown_h_. Inner cells of the
    // whole grid take the vectorised row form, the others the scalar one, as
    // FlowRouter::receivers_from does (the same arithmetic either way).
    const int w = own_.width, gw = grown_.width;
    const int ox = own_.x0 - grown_.x0, oy = own_.y0 - grown_.y0;
    std::vector<double> dirs(std::size_t(gw), -1.0);
    for (int y = 0; y < own_.height; ++y) {
        const int gy = own_.y0 + y;
        const bool inner_row = gy > 0 && gy < H_ - 1;
        const double* row = grown_h_.data() + std::size_t(y + oy) * std::size_t(gw);
        if (inner_row) inner_row_directions(row, row - gw, row + gw, gw, dirs.data());
        for (int x = 0; x < w; ++x) {
            const std::size_t l = std::size_t(y) * std::size_t(w) + std::size_t(x);
            const int gx = own_.x0 + x;
            if (outlet_[l]) {
                dir_[l] = -1;
                continue;
            }
            if (inner_row && gx > 0 && gx < W_ - 1) {
                dir_[l] = std::int8_t(dirs[std::size_t(x + ox)]);
                continue;
            }
            unsigned in = 0;
            for (int k = 0; k < 8; ++k)
                if (inside(gx, gy, k, W_, H_)) in |= 1u << k;
            const double* c = row + x + ox;
            dir_[l] = std::int8_t(steepest(*c, in, [&](int k) { return c[std::int64_t(kDy[k]) * gw + kDx[k]]; }));
        }
    }
}

void TiledModel::build_trees() {
    // Donors inside the tile, then a depth-first walk up from each local root
    // (pit, outlet or exit) in index order: receivers before donors.
    const std::size_t n = h_.size();
    std::fill(donors_.begin(), donors_.end(), std::uint8_t(0));
    trees_.clear();
    for (std::size_t l = 0; l < n; ++l) {
        const int k = dir_[l];
        const std::int64_t r = k < 0 ? -1 : owned_neighbour(l, k);
        if (r < 0) trees_.push_back(std::int32_t(l));
        else donors_[std::size_t(r)] |= std::uint8_t(1u << ((k + 4) & 7));
    }
    tree_start_.assign(trees_.size() + 1, 0);
    std::size_t pos = 0;
    std::vector<std::int32_t> walk;
    for (std::size_t t = 0; t < trees_.size(); ++t) {
        tree_start_[t] = std::int64_t(pos);
        walk.push_back(trees_[t]);
        while (!walk.empty()) {
            const std::int32_t c = walk.back();
            walk.pop_back();
            if (pos == n) throw std::logic_error("stream-power: the receivers hold a loop");
            stack_[pos++] = c;
            tree_of_[std::size_t(c)] = std::int32_t(t);
            unsigned m = donors_[std::size_t(c)];
            while (m) {
                const int k = std::countr_zero(m);
                m &= m - 1;
                walk.push_back(std::int32_t(owned_neighbour(std::size_t(c), k)));
            }
        }
    }
    tree_start_[trees_.size()] = std::int64_t(pos);
    if (pos != n) throw std::logic_error("stream-power: the receivers hold a loop");
}

TiledModel::Hop TiledModel::hop(std::size_t l) const {
    const auto t = std::size_t(trees_[std::size_t(tree_of_[l])]);
    return {global(t), receiver_global(t)};
}

std::string TiledModel::edge_hops() const {
    std::vector<EdgeRecord> rec;
    rec.reserve(edge_.size());
    for (const std::int32_t l : edge_) {
        const Hop hp = hop(std::size_t(l));
        rec.push_back({global(std::size_t(l)), hp.tree, hp.next});
    }
    std::string out;
    put(out, rec);
    return out;
}

namespace {

/// Rank 0: every tile's edge cells and the ends of their local trees.
using EdgeMap = std::unordered_map<std::int64_t, std::pair<std::int64_t, std::int64_t>>;

void read_edges(const std::string& msg, std::size_t& at, EdgeMap& edges) {
    for (const EdgeRecord& e : take<EdgeRecord>(msg, at)) edges[e.cell] = {e.tree, e.next};
}

std::pair<std::int64_t, std::int64_t> edge_of(const EdgeMap& edges, std::int64_t cell) {
    const auto it = edges.find(cell);
    if (it == edges.end()) throw std::logic_error("stream-power: an exit drains into a cell no tile has on its edge");
    return it->second;
}

}  // namespace

void TiledModel::route(double* h) {
    const std::size_t gw = std::size_t(grown_.width);
    const int ox = own_.x0 - grown_.x0, oy = own_.y0 - grown_.y0;
    for (int y = 0; y < own_.height; ++y)
        std::copy(h + std::size_t(y) * std::size_t(own_.width), h + std::size_t(y + 1) * std::size_t(own_.width),
                  grown_h_.begin() + std::ptrdiff_t(std::size_t(y + oy) * gw + std::size_t(ox)));
    double* grids[] = {grown_h_.data()};
    joined([&] { return tiles_.exchange(std::span<double* const>(grids)); });
    directions();
    build_trees();
    std::int64_t pits = 0;
    for (const std::int32_t t : trees_)
        if (dir_[std::size_t(t)] < 0 && !outlet_[std::size_t(t)]) ++pits;
    pits_ = std::int64_t(joined([&] { return tiles_.reduce(double(pits), Tiling::Reduce::sum); }));
    if (pits_ > 0) resolve_pits(h);
}

/// What resolve_pits' steps pass on: rank 0's map of exits over the tiles' edges, the messages gathered
/// to rank 0 and the answer it shares, and this tile's contracted forest of basins.
struct TiledModel::ResolveState {
    EdgeMap edges;
    std::vector<std::string> all;
    std::string answer;
    TileForest forest;
};

void TiledModel::resolve_pits(double* h) {
    ResolveState st;
    label_basins(st);
    settle_tile_lakes(st, links_between_basins());
    join_on_rank0(st);
    apply_joined(st, h);
}

void TiledModel::label_basins(ResolveState& st) {
    const std::size_t n = h_.size();
    // 1. Basins: rank 0 follows every exit over the tiles' edges to its pit or outlet.
    st.all = joined([&] { return tiles_.gather(edge_hops(), Tiling::Gather::to_rank0); });
    if (tiles_.rank() == 0) {
        for (const auto& m : st.all) {
            std::size_t at = 0;
            read_edges(m, at, st.edges);
        }
        std::vector<ExitBasin> exit_basin;
        std::unordered_map<std::int64_t, std::int64_t> basin_of;  // exit → basin
        for (const auto& [cell, end] : st.edges) {
            if (end.second < 0 || basin_of.count(end.first)) continue;
            // Follow the exit's water; every exit met on the way gets the same basin.
            std::vector<std::int64_t> path;
            std::pair<std::int64_t, std::int64_t> at = end;
            std::int64_t basin = -1;
            while (at.second >= 0) {
                if (auto it = basin_of.find(at.first); it != basin_of.end()) {
                    basin = it->second;
                    break;
                }
                path.push_back(at.first);
                if (path.size() > st.edges.size())
                    throw std::logic_error("stream-power: the tiles' rivers hold a loop");
                at = edge_of(st.edges, at.second);
            }
            if (basin < 0) basin = at.first;
            for (const std::int64_t e : path) basin_of[e] = basin;
        }
        for (const auto& [e, b] : basin_of) exit_basin.push_back({e, b});
        put(st.answer, exit_basin);
    }
    joined([&] { return tiles_.share_from_rank0(st.answer); });
    {
        std::size_t at = 0;
        std::unordered_map<std::int64_t, std::int64_t> basin_of;
        for (const ExitBasin& e : take<ExitBasin>(st.answer, at)) basin_of[e.exit] = e.basin;
        std::vector<std::int64_t> tree_basin(trees_.size());
        for (std::size_t t = 0; t < trees_.size(); ++t) {
            const auto l = std::size_t(trees_[t]);
            tree_basin[t] = dir_[l] < 0 ? global(l) : basin_of.at(global(l));
        }
        label_.resize(n);
        for (std::size_t l = 0; l < n; ++l) label_[l] = tree_basin[std::size_t(tree_of_[l])];
    }
}

std::vector<Link> TiledModel::links_between_basins() {
    const std::size_t n = h_.size();
    // 2. Every tile's lowest link per pair of basins, from its cells in pit basins
    // (an edge between two pit basins from its lower-index cell only, as FlowRouter).
    grown_label_.assign(grown_h_.size(), -1.0);
    for (std::size_t l = 0; l < n; ++l) grown_label_[grown_index(l)] = double(label_[l]);  // exact below 2^53
    double* grids[] = {grown_label_.data()};
    joined([&] { return tiles_.exchange(std::span<double* const>(grids)); });
    const std::int64_t gw = grown_.width;
    // Collected tree by tree (a tree lies in one basin), each tree keeping its
    // lowest link per neighbouring basin (Link's i, j, a, b here: whole-grid
    // cells and basins, −1 the sea, which comes first), then the tile's lowest per pair.
    auto lowest_per_pair = [](std::vector<Link>& v) {
        std::sort(v.begin(), v.end(), pair_then_order);
        std::size_t kept = 0;
        for (std::size_t e = 0; e < v.size(); ++e)
            if (kept == 0 || v[e].a != v[kept - 1].a || v[e].b != v[kept - 1].b) v[kept++] = v[e];
        v.resize(kept);
    };
    std::vector<Link> links, tree_links;
    for (std::size_t t = 0; t < trees_.size(); ++t) {
        const std::int64_t li = label_[std::size_t(trees_[t])];
        if (outlet_at(li)) continue;
        tree_links.clear();
        for (std::int64_t s = tree_start_[t]; s < tree_start_[t + 1]; ++s) {
            const auto l = std::size_t(stack_[std::size_t(s)]);
            const std::int64_t i = global(l);
            const int x = int(i % W_), y = int(i / W_);
            const std::size_t gl = grown_index(l);
            for (int k = 0; k < 8; ++k) {
                if (!inside(x, y, k, W_, H_)) continue;
                const std::size_t gj = std::size_t(std::int64_t(gl) + std::int64_t(kDy[k]) * gw + kDx[k]);
                const auto lj = std::int64_t(grown_label_[gj]);
                if (lj == li) continue;
                const std::int64_t j = i + std::int64_t(kDy[k]) * W_ + kDx[k];
                const bool pit_j = !outlet_at(lj);
                if (pit_j && j < i) continue;
                const double pass = std::max(grown_h_[gl], grown_h_[gj]), low = std::min(grown_h_[gl], grown_h_[gj]);
                const std::int64_t bj = pit_j ? lj : -1;  // the sea comes first, then pits by index
                if (bj < li) tree_links.push_back({pass, low, bj, li, j, i});
                else tree_links.push_back({pass, low, li, bj, i, j});
            }
        }
        if (tree_links.size() > 1) lowest_per_pair(tree_links);
        links.insert(links.end(), tree_links.begin(), tree_links.end());
    }
    lowest_per_pair(links);
    return links;
}

void TiledModel::settle_tile_lakes(ResolveState& st, std::vector<Link> links) {
    // 3. The lakes settled here: the basins with their pit in this tile and no
    // cell on its edge have all their links among the tile's (basin_join.hpp).
    std::unordered_set<std::int64_t> on_edge;
    for (const std::int32_t l : edge_) on_edge.insert(label_[std::size_t(l)]);
    st.forest = contract_tile(std::move(links),
                              [&](std::int64_t basin) { return local_of(basin) >= 0 && on_edge.count(basin) == 0; });
    // Rank 0 gets the rest, with the ends of the local trees of the cells it may cut paths from.
    std::vector<EdgeRecord> hops;
    auto hop_of = [&](std::int64_t cell) {
        if (const std::int64_t l = local_of(cell); l >= 0) {
            const Hop hp = hop(std::size_t(l));
            hops.push_back({cell, hp.tree, hp.next});
        }
    };
    for (const Link& l : st.forest.deferred) hop_of(l.i), hop_of(l.j);
    for (const ForestEdge& e : st.forest.edges) hop_of(e.first.i), hop_of(e.first.j);
    std::string mine;
    put(mine, st.forest.anchors);
    put(mine, st.forest.deferred);
    put(mine, st.forest.edges);
    put(mine, hops);
    st.all = joined([&] { return tiles_.gather(mine, Tiling::Gather::to_rank0); });
}

void TiledModel::join_on_rank0(ResolveState& st) {
    // 4. Rank 0: the joined tree's key basins, and the pieces of each anchor's path from its pass down to its pit.
    st.answer.clear();
    if (tiles_.rank() == 0) {
        std::vector<std::int64_t> anchors;
        std::vector<Link> deferred;
        std::vector<ForestEdge> forest_edges;
        for (const auto& m : st.all) {
            std::size_t at = 0;
            const auto a = take<std::int64_t>(m, at);
            const auto d = take<Link>(m, at);
            const auto e = take<ForestEdge>(m, at);
            for (const EdgeRecord& r : take<EdgeRecord>(m, at)) st.edges.emplace(r.cell, std::pair{r.tree, r.next});
            anchors.insert(anchors.end(), a.begin(), a.end());
            deferred.insert(deferred.end(), d.begin(), d.end());
            forest_edges.insert(forest_edges.end(), e.begin(), e.end());
        }
        std::sort(anchors.begin(), anchors.end());
        anchors.erase(std::unique(anchors.begin(), anchors.end()), anchors.end());
        const std::vector<KeyExit> keys = join_tiles(std::move(deferred), forest_edges, anchors);
        std::vector<Piece> pieces;
        for (const KeyExit& k : keys) {
            if (k.basin < 0 || !std::binary_search(anchors.begin(), anchors.end(), k.basin)) continue;
            if (k.in < 0) throw std::logic_error("stream-power: an anchor basin's way out is not a link");
            pieces.push_back({k.in, k.across});
            std::pair<std::int64_t, std::int64_t> end = edge_of(st.edges, k.in);
            std::size_t guard = 0;
            while (end.second >= 0) {
                pieces.push_back({end.second, end.first});  // the exit's receiver now drains back to the exit
                end = edge_of(st.edges, end.second);
                if (++guard > st.edges.size()) throw std::logic_error("stream-power: the tiles' rivers hold a loop");
            }
            if (end.first != k.basin) throw std::logic_error("stream-power: a pass's path does not reach its pit");
        }
        put(st.answer, keys);
        put(st.answer, pieces);
    }
    joined([&] { return tiles_.share_from_rank0(st.answer); });
}

void TiledModel::apply_joined(ResolveState& st, double* h) {
    // 5. Every rank: orient its closed basins, fill its lakes, reverse its pieces of the paths.
    std::size_t at = 0;
    std::unordered_map<std::int64_t, KeyExit> keys;
    for (const KeyExit& k : take<KeyExit>(st.answer, at)) keys.emplace(k.basin, k);
    const auto pieces = take<Piece>(st.answer, at);
    const std::vector<BasinExit> closed = orient_tile(st.forest, keys);
    if (settings_.depressions == Depressions::fill) {
        std::unordered_map<std::int64_t, double> level;
        level.reserve(closed.size() + keys.size());
        for (const BasinExit& e : closed) level.emplace(e.basin, e.level);
        for (const auto& [basin, k] : keys) level.emplace(basin, k.level);
        for (std::size_t t = 0; t < trees_.size(); ++t) {  // a tree lies in one basin: one lookup a tree
            const std::int64_t basin = label_[std::size_t(trees_[t])];
            if (outlet_at(basin)) continue;
            const auto it = level.find(basin);
            if (it == level.end()) throw std::logic_error("stream-power: a lake's level did not come");
            const double lv = it->second;
            for (std::int64_t p = tree_start_[t]; p < tree_start_[t + 1]; ++p) {
                const auto l = std::size_t(stack_[std::size_t(p)]);
                if (h[l] < lv) h[l] = lv;
            }
        }
    }
    // Reverse the receivers from `start` (which now drains to `prev`) down to the pit or out of the tile.
    auto reverse = [&](std::int64_t start, std::int64_t prev) {
        auto c = std::size_t(start);
        for (;;) {
            const int old = dir_[c];
            dir_[c] = std::int8_t(direction_to(global(c), prev, W_));
            if (old < 0) break;  // the pit
            const std::int64_t next = owned_neighbour(c, old);
            if (next < 0) break;  // on into the next tile: another piece
            prev = global(c);
            c = std::size_t(next);
        }
    };
    for (const BasinExit& e : closed) reverse(local_of(e.in), e.across);
    for (const Piece& p : pieces)
        if (const std::int64_t start = local_of(p.start); start >= 0) reverse(start, p.prev);
    build_trees();
}

void TiledModel::accumulate() {
    // Cells upstream, as whole numbers, or sums of whole 2^-20 with the rain's weights (exact in any
    // order: the whole grid's bits).
    std::vector<Inflow> inflows;
    auto count = [&] {
        if (rain_weight_.empty()) std::fill(count_.begin(), count_.end(), 1.0);
        else std::copy(rain_weight_.begin(), rain_weight_.end(), count_.begin());
        for (const Inflow& f : inflows) {
            if (const std::int64_t l = local_of(f.cell); l >= 0) count_[std::size_t(l)] += f.count;
        }
        for (std::size_t s = stack_.size(); s-- > 0;) {
            const auto l = std::size_t(stack_[s]);
            const int k = dir_[l];
            if (k < 0) continue;
            const std::int64_t r = owned_neighbour(l, k);
            if (r >= 0) count_[std::size_t(r)] += count_[l];
        }
    };
    count();
    if (tiles_.ranks() > 1) {
        std::vector<ExitRecord> exits;
        for (const std::int32_t t : trees_)
            if (dir_[std::size_t(t)] >= 0)
                exits.push_back({global(std::size_t(t)), count_[std::size_t(t)], receiver_global(std::size_t(t))});
        std::string mine = edge_hops();
        put(mine, exits);
        const auto all = joined([&] { return tiles_.gather(mine, Tiling::Gather::to_rank0); });
        std::string answer;
        if (tiles_.rank() == 0) {
            // Each exit's count goes to the edge cell it drains into, and with the
            // count of that cell's tree on to the tree's own exit (Kahn's order).
            EdgeMap edges;
            std::vector<ExitRecord> every;
            for (const auto& m : all) {
                std::size_t at = 0;
                read_edges(m, at, edges);
                const auto e = take<ExitRecord>(m, at);
                every.insert(every.end(), e.begin(), e.end());
            }
            std::unordered_map<std::int64_t, std::size_t> index;
            for (std::size_t e = 0; e < every.size(); ++e) index[every[e].cell] = e;
            std::vector<std::int64_t> downstream(every.size(), -1);
            std::vector<int> waiting(every.size(), 0);
            for (std::size_t e = 0; e < every.size(); ++e) {
                const auto end = edge_of(edges, every[e].next);
                if (end.second >= 0) {
                    downstream[e] = std::int64_t(index.at(end.first));
                    ++waiting[std::size_t(downstream[e])];
                }
            }
            std::vector<std::size_t> ready;
            for (std::size_t e = 0; e < every.size(); ++e)
                if (waiting[e] == 0) ready.push_back(e);
            std::unordered_map<std::int64_t, double> into;
            for (std::size_t q = 0; q < ready.size(); ++q) {
                const ExitRecord& e = every[ready[q]];
                into[e.next] += e.count;
                const std::int64_t d = downstream[ready[q]];
                if (d < 0) continue;
                every[std::size_t(d)].count += e.count;
                if (--waiting[std::size_t(d)] == 0) ready.push_back(std::size_t(d));
            }
            if (ready.size() != every.size()) throw std::logic_error("stream-power: the tiles' rivers hold a loop");
            std::vector<Inflow> list;
            for (const auto& [cell, c] : into) list.push_back({cell, c});
            put(answer, list);
        }
        joined([&] { return tiles_.share_from_rank0(answer); });
        std::size_t at = 0;
        inflows = take<Inflow>(answer, at);
        count();
    }
    const double a0 = cell_ * cell_;
    for (std::size_t l = 0; l < count_.size(); ++l) area_[l] = count_[l] * a0;
}

// ------------------------------------------------------------ down the rivers

void TiledModel::propagate(std::vector<double>& v, const std::function<void(std::size_t, double)>& f) {
    std::vector<std::uint8_t> done(trees_.size(), 0);
    auto solve_tree = [&](std::size_t t, double from_outside) {
        const std::int64_t b = tree_start_[t], e = tree_start_[t + 1];
        for (std::int64_t s = b; s < e; ++s) {
            const auto l = std::size_t(stack_[std::size_t(s)]);
            const int k = dir_[l];
            if (k < 0) continue;  // a pit or outlet keeps its value
            f(l, s == b ? from_outside : v[std::size_t(owned_neighbour(l, k))]);
        }
        done[t] = 1;
    };
    std::vector<std::size_t> waiting;
    for (std::size_t t = 0; t < trees_.size(); ++t) {
        if (dir_[std::size_t(trees_[t])] < 0) solve_tree(t, 0.0);
        else waiting.push_back(t);
    }
    rounds_ = 1;
    double left =
        tiles_.ranks() > 1 ? joined([&] { return tiles_.reduce(double(waiting.size()), Tiling::Reduce::sum); }) : 0.0;
    if (left > 0.0) {
        grown_v_.assign(grown_h_.size(), 0.0);
        grown_done_.assign(grown_h_.size(), 0.0);
    }
    const std::int64_t gw = grown_.width;
    while (left > 0.0) {
        ++rounds_;
        for (const std::int32_t l : edge_) {
            grown_v_[grown_index(std::size_t(l))] = v[std::size_t(l)];
            grown_done_[grown_index(std::size_t(l))] = done[std::size_t(tree_of_[std::size_t(l)])];
        }
        double* grids[] = {grown_v_.data(), grown_done_.data()};
        joined([&] { return tiles_.exchange(std::span<double* const>(grids)); });
        std::vector<std::size_t> still;
        for (const std::size_t t : waiting) {
            const auto l = std::size_t(trees_[t]);
            const int k = dir_[l];
            const auto r = std::size_t(std::int64_t(grown_index(l)) + std::int64_t(kDy[k]) * gw + kDx[k]);
            if (grown_done_[r] != 0.0) solve_tree(t, grown_v_[r]);
            else still.push_back(t);
        }
        waiting.swap(still);
        const double now = joined([&] { return tiles_.reduce(double(waiting.size()), Tiling::Reduce::sum); });
        if (now >= left) throw std::logic_error("stream-power: the solve down the rivers made no progress");
        left = now;
    }
}

void TiledModel::run(double years, double dt, const std::function<void(std::int64_t, std::int64_t)>& on_step) {
    if (!(years > 0.0) || !(dt > 0.0))
        throw std::invalid_argument("landscape::TiledModel::run: years and dt must be > 0");
    const auto steps = std::int64_t(std::ceil(years / dt * (1.0 - 1e-12)));
    for (std::int64_t s = 1; s <= steps; ++s) {
        step(s < steps ? dt : years - dt * double(steps - 1));
        if (on_step) on_step(s, steps);
    }
}

void TiledModel::update_rain() {
    // Model::update_rain over the tiles: each adds its heights to the blocks' whole sums, the ranks' sums
    // are added (exactly: whole numbers), and each takes the coarse rain and interpolates its own cells.
    const climate::CoarseRainGrid g =
        climate::coarse_rain_grid(W_, H_, cell_, settings_.rain, settings_.rain_resolution);
    std::vector<double> sums(std::size_t(g.coarse_width) * std::size_t(g.coarse_height), 0.0);
    climate::add_block_sums(g, h_.data(), own_.x0, own_.y0, own_.width, own_.height, sums);
    joined([&] { tiles_.reduce(std::span<double>(sums), Tiling::Reduce::sum); });
    const std::vector<double> coarse = climate::coarse_rain(g, settings_.rain, std::move(sums), &rain_transfer_);
    climate::interpolate_rain(g, coarse, own_.x0, own_.y0, own_.width, own_.height, rain_weight_);
    rain_to_weights(rain_weight_, settings_.rain.background);
}

std::vector<double> TiledModel::rain() const { return weights_to_rain(rain_weight_, settings_.rain.background); }

void TiledModel::route_only() {
    if (settings_.orographic_rain && rain_weight_.empty()) update_rain();
    std::vector<double> copy = h_;  // routing may fill lakes: keep the model's heights as they are
    route(copy.data());
    accumulate();
}

void TiledModel::set_uplift_history(UpliftHistory history) {
    check_history(history);
    history_ = std::move(history);
    history_k_ = std::size_t(-1);
}

std::int64_t TiledModel::step(double dt) {
    const std::size_t n = h_.size();
    const int subs = std::max(1, settings_.substeps);
    const double sub = dt / subs;  // yr (Model::step: the step's routing serves every sub-step)
    // 1. Uplift (outlets are base level: they stay); for one sub-step, rate·dt exactly.
    auto uplift = [&](double t0, double t1, double length) {
        if (!uplift_.empty())
            for (std::size_t l = 0; l < n; ++l)
                if (!outlet_[l]) {
                    h_[l] += uplift_[l] * length;
                    uplifted_[l] += uplift_[l] * length;
                }
        if (history_.rate)
            for_history_intervals(history_, history_k_, history_rate_, n, t0, t1,
                                  [&](const double* rate, double overlap) {
                                      for (std::size_t l = 0; l < n; ++l)
                                          if (!outlet_[l]) {
                                              h_[l] += rate[l] * overlap;
                                              uplifted_[l] += rate[l] * overlap;
                                          }
                                  });
    };
    const double t_start = time_;
    uplift(t_start, t_start + sub, sub);
    time_ += dt;
    // 2. The rain on the uplifted relief; routing, depressions, drainage area (weighted by the rain).
    if (settings_.orographic_rain) update_rain();
    route(h_.data());
    accumulate();
    const std::int64_t pits = pits_;
    for (int k = 0; k < subs; ++k) {
        if (k > 0) uplift(t_start + k * sub, k + 1 == subs ? t_start + dt : t_start + (k + 1) * sub, sub);
        // 3. Hillslope diffusion across the tiles (the declared sink stays at base level).
        if (diffusion_) {
            const std::int64_t sink = settings_.open.any() ? -1 : local_of(sink_);
            const double sink_h = sink >= 0 ? h_[std::size_t(sink)] : 0.0;
            diffusion_->step(h_.data(), sub);
            if (sink >= 0) h_[std::size_t(sink)] = sink_h;
        }
        // 4. Implicit incision, receivers first (Model::incise, the same arithmetic), in the rock each cell
        // shows.
        const CellBlock own{n, own_.width, own_.x0, own_.y0, cell_};
        if (bed_offset_.empty()) bed_offsets(settings_.rock, own, bed_offset_);
        rock_at(settings_.rock, own, {h_.data(), uplifted_.data(), bed_offset_.data()}, rock_slopes_, rock_k_,
                &rock_memo_);
        const double K = settings_.erodibility, m = settings_.area_exponent, ns = settings_.slope_exponent;
        const double a0 = cell_ * cell_, inv_a0 = 1.0 / a0;
        const double c1 = K * sub / std::pow(cell_, ns), c2 = K * sub / std::pow(cell_ * kSqrt2, ns);
        const double* tab = pow_table_.data();
        const double inv_ac = inverse_channel_area(settings_);
        if (settings_.banks.any()) bank_before_ = h_;
        propagate(h_, [&](std::size_t l, double hr) {
            const double hi = h_[l];
            if (hi <= hr) return;
            const int d = dir_[l];
            double F = area_power(area_[l], tab, inv_a0, a0, m, inv_ac) * ((d & 1) ? c2 : c1);
            if (!rock_k_.empty()) F *= rock_k_[l];
            if (ns == 1.0) {
                const double wt = 1.0 / (1.0 + F);
                h_[l] = hr + (hi - hr) * wt;
            } else {
                h_[l] = hr + incised_drop(hi - hr, F, ns);
            }
        });
        if (settings_.banks.any()) erode_banks(bank_before_);
        if (settings_.floodplain.any()) plane_floodplains();
        // 5. Landslides across the tiles (Model::step): the same greatest fixed point, so the same bits.
        if (settings_.rock.angle > 0.0)
            solvers::threshold::limit_slopes(
                tiles_, h_.data(), cell_,
                {settings_.rock.landslide_slope(0.5), rock_slopes_.empty() ? nullptr : rock_slopes_.data()},
                outlet_.data(), nullptr, &slope_scratch_);
    }
    return pits;
}

void TiledModel::relay_across(BankRelay& relay, std::size_t gn) {
    // The direction and the passes onward left in one double each cell: out + 8·onward, or −1.
    bank_relay_out_.resize(gn);
    for (std::size_t g = 0; g < gn; ++g)
        bank_relay_out_[g] = relay.out[g] < 0 ? -1.0 : double(relay.out[g] + 8 * relay.onward[g]);
    double* arrays[] = {relay.push.data(), relay.floor.data(), bank_relay_out_.data()};
    joined([&] { return tiles_.exchange(std::span<double* const>(arrays)); });
    for (std::size_t g = 0; g < gn; ++g) {
        const int v = int(bank_relay_out_[g]);
        relay.out[g] = std::int8_t(v < 0 ? -1 : v % 8);
        relay.onward[g] = std::int8_t(v < 0 ? 0 : v / 8);
    }
}

void TiledModel::erode_banks(const std::vector<double>& before) {
    const int gw = grown_.width, gh = grown_.height;
    const int ox = own_.x0 - grown_.x0, oy = own_.y0 - grown_.y0;
    const std::size_t gn = std::size_t(gw) * std::size_t(gh);
    bank_area_.assign(gn, 0.0);
    bank_dir_.assign(gn, -1.0);
    bank_e_.assign(gn, 0.0);
    bank_h_.assign(gn, 0.0);
    bank_outlet_.assign(gn, 0);
    for (int y = 0; y < own_.height; ++y)
        for (int x = 0; x < own_.width; ++x) {
            const std::size_t l = std::size_t(y) * std::size_t(own_.width) + std::size_t(x);
            const std::size_t g = std::size_t(y + oy) * std::size_t(gw) + std::size_t(x + ox);
            bank_area_[g] = area_[l];
            bank_dir_[g] = dir_[l];
            bank_e_[g] = std::max(0.0, before[l] - h_[l]);  // as Model::erode_banks
            bank_h_[g] = h_[l];
            bank_outlet_[g] = outlet_[l];
        }
    double* first[] = {bank_area_.data(), bank_dir_.data(), bank_e_.data(), bank_h_.data()};
    joined([&] { return tiles_.exchange(std::span<double* const>(first)); });
    bank_code_.resize(gn);
    for (std::size_t g = 0; g < gn; ++g) bank_code_[g] = std::int8_t(bank_dir_[g]);
    const BankWindow w{gw, gh, ox, oy, ox + own_.width, oy + own_.height};
    if (!bank_factor_) bank_factor_.emplace(settings_.banks, cell_);
    bank_pushes(settings_.banks, *bank_factor_, w, bank_code_.data(), bank_area_.data(), bank_e_.data(), bank_right_,
                bank_left_);
    double* second[] = {bank_right_.data(), bank_left_.data()};
    joined([&] { return tiles_.exchange(std::span<double* const>(second)); });
    lower_banks(settings_.banks, w, {bank_code_.data(), bank_area_.data(), bank_outlet_.data()},
                {bank_right_.data(), bank_left_.data()}, cell_, bank_h_.data(), bank_scratch_, &bank_relay_);
    if (settings_.banks.wide()) {  // what the halo's banks pass on, pass after pass (as Model::erode_banks)
        const int passes = settings_.banks.onward_passes();
        BankRelay *relay = &bank_relay_, *next = &bank_relay2_;
        for (int pass = 0; pass <= passes; ++pass, std::swap(relay, next)) {
            relay_across(*relay, gn);
            lower_relayed(settings_.banks, w, *relay, bank_outlet_.data(), cell_, bank_h_.data(),
                          pass < passes ? next : nullptr);
        }
    }
    for (int y = 0; y < own_.height; ++y)
        for (int x = 0; x < own_.width; ++x)
            h_[std::size_t(y) * std::size_t(own_.width) + std::size_t(x)] =
                bank_h_[std::size_t(y + oy) * std::size_t(gw) + std::size_t(x + ox)];
}

void TiledModel::plane_floodplains() {
    // The receivers of the tile's edge cells lie in the halo.
    tiles_.ghosted_copy(h_.data(), floodplain_grown_);
    double* grown[] = {floodplain_grown_.data()};
    joined([&] { return tiles_.exchange(std::span<double* const>(grown)); });
    const int gw = grown_.width;
    const int ox = own_.x0 - grown_.x0, oy = own_.y0 - grown_.y0;
    floodplain_mine_.clear();
    for (int y = 0; y < own_.height; ++y)
        for (int x = 0; x < own_.width; ++x) {
            const std::size_t l = std::size_t(y) * std::size_t(own_.width) + std::size_t(x);
            const int k = dir_[l];
            const double receiver = k < 0
                ? 0.0
                : floodplain_grown_[std::size_t(y + oy + kDy[k]) * std::size_t(gw) + std::size_t(x + ox + kDx[k])];
            double reach = 0.0;
            if (floodplain_source(settings_.floodplain, cell_, k, area_[l], h_[l], receiver, reach))
                floodplain_mine_.push_back({global(l), h_[l], reach});
        }
    // Each river goes to the tiles its floodplain reaches into (its own included), a few at most; every tile
    // stamps those in the whole grid's index order (the order Model stamps them in: the same nearest river
    // for every cell, ties included, as any river that can reach one of its cells is among them).
    std::vector<std::vector<FloodplainSource>> to_rank(std::size_t(tiles_.ranks()));
    for (const FloodplainSource& s : floodplain_mine_) {
        const int r = int(s.reach), x = int(s.index % W_), y = int(s.index / W_);
        for (int rank : tiles_.ranks_meeting({x - r, y - r, 2 * r + 1, 2 * r + 1}))
            to_rank[std::size_t(rank)].push_back(s);
    }
    std::vector<std::string> bytes(to_rank.size());
    for (std::size_t k = 0; k < to_rank.size(); ++k)
        if (!to_rank[k].empty()) put(bytes[k], to_rank[k]);  // nothing travels to a tile out of every reach
    const auto all = joined([&] { return tiles_.send_to_ranks(bytes); });
    floodplain_all_.clear();
    for (const auto& b : all) {
        if (b.empty()) continue;
        std::size_t at = 0;
        const auto theirs = take<FloodplainSource>(b, at);
        floodplain_all_.insert(floodplain_all_.end(), theirs.begin(), theirs.end());
    }
    std::sort(floodplain_all_.begin(), floodplain_all_.end(),
              [](const FloodplainSource& a, const FloodplainSource& b) { return a.index < b.index; });
    stamp_floodplains(floodplain_all_, W_, {own_.x0, own_.y0, own_.width, own_.height}, floodplain_nearest_,
                      floodplain_floor_);
    lower_to_floodplains(settings_.floodplain, cell_, h_.size(), floodplain_nearest_, floodplain_floor_, outlet_.data(),
                         h_.data());
}

std::vector<double> TiledModel::chi(double a0) {
    std::vector<double> out(h_.size(), 0.0);
    const double p = settings_.area_exponent / settings_.slope_exponent;
    propagate(out, [&](std::size_t l, double chi_r) {
        const double distance = (dir_[l] & 1) ? cell_ * kSqrt2 : cell_;
        out[l] = chi_r + std::pow(a0 / area_[l], p) * distance;
    });
    return out;
}

}  // namespace orogen::landscape
