#include "tiles.hpp"

#include "mpi_comm.hpp"

#include <orogen/io.hpp>
#include <orogen/timelapse.hpp>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cstring>
#include <sstream>
#include <utility>

namespace orogen {

TileRect Tiling::ghosted() const {
    const TileRect o = owned();
    const int x0 = std::max(0, o.x0 - halo_), y0 = std::max(0, o.y0 - halo_);
    const int x1 = std::min(grid_width(), o.x1() + halo_), y1 = std::min(grid_height(), o.y1() + halo_);
    return {x0, y0, x1 - x0, y1 - y0};
}

int Tiling::rank_at(int x, int y) const {
    for (int r = 0; r < ranks(); ++r) {
        const TileRect t = tile(r);
        if (x >= t.x0 && x < t.x1() && y >= t.y0 && y < t.y1()) return r;
    }
    throw Error("internal error: vertex (" + std::to_string(x) + ", " + std::to_string(y) + ") lies outside the " +
                std::to_string(grid_width()) + "x" + std::to_string(grid_height()) + " grid");
}

std::vector<int> Tiling::ranks_meeting(TileRect rect) const {
    // The split is a lattice of cuts: the columns and rows of tiles the rectangle spans, found by bisection.
    const int x0 = std::max(rect.x0, 0), y0 = std::max(rect.y0, 0);
    const int x1 = std::min(rect.x1(), grid_width()), y1 = std::min(rect.y1(), grid_height());
    if (x0 >= x1 || y0 >= y1) return {};
    const auto& xs = split_.xs;
    const auto& ys = split_.ys;
    const int c0 = int(std::upper_bound(xs.begin(), xs.end(), x0) - xs.begin()) - 1;
    const int c1 = int(std::upper_bound(xs.begin(), xs.end(), x1 - 1) - xs.begin()) - 1;
    const int r0 = int(std::upper_bound(ys.begin(), ys.end(), y0) - ys.begin()) - 1;
    const int r1 = int(std::upper_bound(ys.begin(), ys.end(), y1 - 1) - ys.begin()) - 1;
    std::vector<int> out;
    for (int r = r0; r <= r1; ++r)
        for (int c = c0; c <= c1; ++c) out.push_back(r * split_.cols + c);
    return out;
}

void Tiling::exchange(std::span<const GridView> grids) {
    const TileRect g = ghosted();
    std::vector<void*> data;
    for (const GridView& held : grids) {
        if (held.width != g.width || held.height != g.height)
            throw Error("internal error: exchange got a " + std::to_string(held.width) + "x" +
                        std::to_string(held.height) + " grid for a ghosted tile of " + std::to_string(g.width) + "x" +
                        std::to_string(g.height));
        data.push_back(held.data);
    }
    exchange_values(data, sizeof(float));
}

std::vector<double> Tiling::gather_rows(std::span<const double> mine, int per_row) {
    // Rank order is row-major, so the eastmost tiles in rank order hold the rows in grid order.
    const std::size_t n = eastmost() ? std::size_t(owned().height) * std::size_t(per_row) : 0;
    if (n && mine.size() != n)
        throw Error("internal error: gather_rows got " + std::to_string(mine.size()) + " values for " +
                    std::to_string(n));
    const auto all =
        gather(std::string_view(reinterpret_cast<const char*>(mine.data()), n * sizeof(double)), Gather::to_every_rank);
    std::vector<double> rows(std::size_t(grid_height()) * std::size_t(per_row));
    std::size_t at = 0;
    for (const std::string& part : all) {
        if (at * sizeof(double) + part.size() > rows.size() * sizeof(double))
            throw Error("internal error: gather_rows got more rows than the grid has");
        std::memcpy(rows.data() + at, part.data(), part.size());
        at += part.size() / sizeof(double);
    }
    return rows;
}

// ------------------------------------------------------------------ a grid eroder's tiled loop

TiledFields::TiledFields(Tiling& tiles, double cell)
    : tiles_(tiles), cell_(cell), own_(tiles.owned()), ghosted_(tiles.ghosted()), ox_(own_.x0 - ghosted_.x0),
      oy_(own_.y0 - ghosted_.y0), waited_before_(tiles.seconds_waiting()) {}

GridView TiledFields::grow(const float* tile) {
    grids_.push_back(std::make_unique<std::vector<float>>(tiles_.ghosted_copy(tile)));
    return {grids_.back()->data(), ghosted_.width, ghosted_.height, cell_};
}

GridView TiledFields::zeros() {
    grids_.push_back(std::make_unique<std::vector<float>>(std::size_t(ghosted_.width) * std::size_t(ghosted_.height)));
    return {grids_.back()->data(), ghosted_.width, ghosted_.height, cell_};
}

void TiledFields::exchange(std::span<const GridView> grids) {
    const auto t0 = std::chrono::steady_clock::now();
    tiles_.exchange(grids);
    exchanging_ += std::chrono::steady_clock::now() - t0;
}

std::vector<float>& TiledFields::storage_of(const GridView& grid) {
    for (auto& g : grids_)
        if (g->data() == grid.data && !g->empty()) return *g;
    throw Error("internal error: TiledFields was given a grid it does not hold");
}

std::vector<float> TiledFields::take(GridView grid) {
    std::vector<float>& held = storage_of(grid);
    // Row y's destination never passes its source, so rows are moved in order.
    for (int y = 0; y < own_.height; ++y)
        std::memmove(held.data() + std::size_t(y) * std::size_t(own_.width),
                     held.data() + std::size_t(y + oy_) * std::size_t(ghosted_.width) + std::size_t(ox_),
                     std::size_t(own_.width) * sizeof(float));
    held.resize(std::size_t(own_.width) * std::size_t(own_.height));
    return std::move(held);
}

std::string TiledFields::note(std::int64_t steps) const {
    const double sweeping = std::chrono::duration<double>(sweeping_).count();
    const double exchanging = std::chrono::duration<double>(exchanging_).count();
    std::ostringstream note;
    note.precision(3);
    note << "rank " << tiles_.rank() << " of " << tiles_.ranks() << ": tile " << own_.width << "x" << own_.height
         << " at (" << own_.x0 << ", " << own_.y0 << "), " << steps << " steps: sweeps " << sweeping
         << " s, halo exchange " << exchanging << " s ("
         << (sweeping + exchanging > 0 ? 100.0 * exchanging / (sweeping + exchanging) : 0.0)
         << " %), of which waiting for the other ranks " << tiles_.seconds_waiting() - waited_before_ << " s";
    return note.str();
}

// ------------------------------------------------------------------ the split

TileRect TileSplit::tile(int index) const {
    const int r = index / cols, c = index % cols;
    return {xs[std::size_t(c)], ys[std::size_t(r)], xs[std::size_t(c) + 1] - xs[std::size_t(c)],
            ys[std::size_t(r) + 1] - ys[std::size_t(r)]};
}

int TileSplit::smallest_width() const {
    int w = INT_MAX;
    for (int c = 0; c < cols; ++c) w = std::min(w, xs[std::size_t(c) + 1] - xs[std::size_t(c)]);
    return w;
}

int TileSplit::smallest_height() const {
    int h = INT_MAX;
    for (int r = 0; r < rows; ++r) h = std::min(h, ys[std::size_t(r) + 1] - ys[std::size_t(r)]);
    return h;
}

TileSplit split_grid(int width, int height, int rows, int cols) {
    TileSplit s;
    s.grid_width = width;
    s.grid_height = height;
    s.rows = rows;
    s.cols = cols;
    for (int c = 0; c <= cols; ++c) s.xs.push_back(int(std::int64_t(c) * width / cols));
    for (int r = 0; r <= rows; ++r) s.ys.push_back(int(std::int64_t(r) * height / rows));
    return s;
}

std::optional<std::pair<int, int>> parse_tiles(std::string_view text) {
    const auto x = text.find_first_of("xX");
    if (x == std::string_view::npos || x == 0 || x + 1 == text.size()) return std::nullopt;
    auto number = [](std::string_view t) -> std::optional<int> {
        if (t.empty() || t.size() > 6 || t.find_first_not_of("0123456789") != std::string_view::npos)
            return std::nullopt;
        const int v = std::stoi(std::string(t));
        return v >= 1 ? std::optional<int>(v) : std::nullopt;
    };
    const auto r = number(text.substr(0, x)), c = number(text.substr(x + 1));
    if (!r || !c) return std::nullopt;
    return std::pair{*r, *c};
}

std::pair<int, int> automatic_tiles(int ranks, int width, int height) {
    // The factor pair whose tiles are closest to square (ties: more rows, so
    // each tile's rows stay long and contiguous in memory).
    std::pair<int, int> best{ranks, 1};
    double best_score = 1e300;
    for (int rows = 1; rows <= ranks; ++rows) {
        if (ranks % rows) continue;
        const int cols = ranks / rows;
        const double tw = double(width) / cols, th = double(height) / rows;
        const double score = std::max(tw, th) / std::min(tw, th);
        if (score < best_score - 1e-12 || (std::abs(score - best_score) <= 1e-12 && rows > best.first)) {
            best = {rows, cols};
            best_score = score;
        }
    }
    return best;
}

void check_tiled(const Plan& plan, const TileSplit& split, const TiledCheckOptions& options, spec::Diagnostics& diags) {
    const std::string how = (options.tiles_given ? "--tiles " : "the automatic split ") + std::to_string(split.rows) +
        "x" + std::to_string(split.cols);
    const std::string grid = std::to_string(split.grid_width) + "x" + std::to_string(split.grid_height);
    if (split.cols > split.grid_width || split.rows > split.grid_height) {
        diags.error(spec::Location{plan.source, 1, 1, 1},
                    how + " cuts the " + grid + " grid into more " +
                        (split.cols > split.grid_width ? "columns" : "rows") +
                        " than it has vertices; use fewer ranks or --tiles with fewer " +
                        (split.cols > split.grid_width ? "columns" : "rows"));
        return;
    }
    for (const PlannedNode& node : plan.nodes) {
        const std::string who = "'" + node.label + "' (" + node.node->qualified_name() + ")";
        if (!runs_tiled(node)) {
            const std::string problem =
                heightmap_memory_problem(split.grid_width, split.grid_height, options.whole_grid_limit);
            if (!problem.empty())
                diags.error(node.where,
                            who + " runs on rank 0 over the whole " + grid + " grid (" + untiled_reason(node) +
                                "), which " + problem +
                                "; remove it from this spec (run it on the result, in a smaller spec), "
                                "change what keeps it from tiling or use a smaller grid");
            continue;
        }
        const int halo = node.node->tile_halo;
        const bool narrow = split.cols > 1 && split.smallest_width() < halo;
        const bool low = split.rows > 1 && split.smallest_height() < halo;
        if (narrow || low)
            diags.error(node.where,
                        who + " exchanges a halo of " + std::to_string(halo) +
                            " vertices with each neighbouring tile, so tiles must be at least " + std::to_string(halo) +
                            " vertices " + (narrow ? "wide" : "high") + ", but " + how + " cuts the " + grid +
                            " grid into tiles " +
                            std::to_string(narrow ? split.smallest_width() : split.smallest_height()) + " " +
                            (narrow ? "wide" : "high") + "; use fewer " + (narrow ? "columns" : "rows") +
                            " (--tiles), fewer ranks or a larger grid");
        if (auto it = node.params.find(timelapse_param().name); it != node.params.end() && !node.node->tiled_timelapse)
            if (const auto* every = std::get_if<std::int64_t>(&it->second); every && *every > 0)
                diags.error(node.where,
                            who + ": time-lapses are not recorded in a tiled run yet; set " + timelapse_param().name +
                                "=0 or run without mpirun");
    }
}

// ------------------------------------------------------------------ one rank

int TiledRun::agree(int exit_code, int* reporter) {
    // One shape of collective for every agreement, so a rank that failed
    // inside a node meets the others at the agreement inside their next
    // exchange: {worst exit code, lowest failing rank (negated, for MAX)}.
    int v[2] = {exit_code, exit_code != 0 ? -rank_ : INT_MIN};
    mpi::max_all(v, 2);
    if (reporter) *reporter = v[1] == INT_MIN ? -1 : -v[1];
    return v[0];
}

namespace {

constexpr int kTagWest = 11, kTagEast = 12, kTagNorth = 13, kTagSouth = 14, kTagCarry = 15, kTagTile = 20,
              kTagFetch = 21, kTagText = 22, kTagRoute = 23;

/// Copy the rectangle (x, y, w, h) of `grid` (row length `stride`) into `out`, or back with `to_grid`.
template <typename T>
void copy_rect(T* grid, int stride, int x, int y, int w, int h, T* out, bool to_grid) {
    for (int r = 0; r < h; ++r) {
        T* g = grid + std::size_t(y + r) * std::size_t(stride) + std::size_t(x);
        T* o = out + std::size_t(r) * std::size_t(w);
        if (to_grid) std::memcpy(g, o, std::size_t(w) * sizeof(T));
        else std::memcpy(o, g, std::size_t(w) * sizeof(T));
    }
}

}  // namespace

// ------------------------------------------------------------------ what a tiled node sees

void NodeTiling::agree_or_throw() {
    const auto t0 = std::chrono::steady_clock::now();
    const int code = run_.agree(0);
    waiting_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (code) throw PeerFailed(code, code == 2 ? Error::Kind::bad_input : Error::Kind::failed_run);
}

void NodeTiling::exchange_values(std::span<void* const> grids, std::size_t value_bytes) {
    agree_or_throw();
    const int halo = this->halo();
    if (halo == 0 || ranks() == 1 || grids.empty()) return;
    const TileSplit& split = run_.split();
    const TileRect o = owned(), g = ghosted();
    const int rank = this->rank(), r = rank / split.cols, c = rank % split.cols;
    const int west = c > 0 ? rank - 1 : -1, east = c + 1 < split.cols ? rank + 1 : -1;
    const int north = r > 0 ? rank - split.cols : -1, south = r + 1 < split.rows ? rank + split.cols : -1;
    const int ox = o.x0 - g.x0, oy = o.y0 - g.y0;  // the owned part inside each grid
    // Bytes from here on: a value is `vb` bytes, a grid row `stride` of them.
    const int vb = int(value_bytes);
    const std::size_t count = grids.size(), stride = std::size_t(g.width) * value_bytes;
    std::vector<char> out, in;
    auto grid = [&](std::size_t k) { return static_cast<char*>(grids[k]); };
    // East and west: the owned rows only (the corners come with the rows below);
    // grid k's block of halo × o.height values at k·block in each message.
    auto columns = [&](int send_x, int to, int recv_x, int from, int tag) {
        const std::size_t block = std::size_t(halo) * std::size_t(o.height) * value_bytes;
        out.resize(to >= 0 ? block * count : 0);
        in.resize(from >= 0 ? block * count : 0);
        if (to >= 0)
            for (std::size_t k = 0; k < count; ++k)
                copy_rect(grid(k), g.width * vb, send_x * vb, oy, halo * vb, o.height, out.data() + k * block, false);
        mpi::sendrecv(out.data(), out.size(), to, in.data(), in.size(), from, tag);
        if (from >= 0)
            for (std::size_t k = 0; k < count; ++k)
                copy_rect(grid(k), g.width * vb, recv_x * vb, oy, halo * vb, o.height, in.data() + k * block, true);
    };
    columns(ox, west, ox + o.width, east, kTagWest);  // my first columns go west, the east's come in
    columns(ox + o.width - halo, east, ox - halo, west, kTagEast);
    // North and south: whole rows of each grid, halo columns included (the
    // same columns for both, as tiles in one column of the split share their cuts).
    auto rows = [&](int send_y, int to, int recv_y, int from, int tag) {
        const std::size_t block = std::size_t(halo) * stride;
        out.resize(to >= 0 ? block * count : 0);
        in.resize(from >= 0 ? block * count : 0);
        if (to >= 0)
            for (std::size_t k = 0; k < count; ++k)
                std::memcpy(out.data() + k * block, grid(k) + std::size_t(send_y) * stride, block);
        mpi::sendrecv(out.data(), out.size(), to, in.data(), in.size(), from, tag);
        if (from >= 0)
            for (std::size_t k = 0; k < count; ++k)
                std::memcpy(grid(k) + std::size_t(recv_y) * stride, in.data() + k * block, block);
    };
    rows(oy, north, oy + o.height, south, kTagNorth);
    rows(oy + o.height - halo, south, oy - halo, north, kTagSouth);
}

std::vector<std::string> NodeTiling::gather(std::string_view bytes, Gather where) {
    agree_or_throw();
    if (where == Gather::to_rank0) return run_.gather_text(std::string(bytes));
    return mpi::allgather(bytes);
}

std::vector<std::string> NodeTiling::send_to_ranks(std::span<const std::string> to_rank) {
    if (to_rank.size() != std::size_t(ranks()))
        throw Error("internal error: send_to_ranks() takes " + std::to_string(ranks()) +
                    " messages, one per rank, not " + std::to_string(to_rank.size()));
    agree_or_throw();
    if (ranks() == 1) return {to_rank.front()};
    return mpi::alltoall(to_rank, kTagRoute);
}

void NodeTiling::share_from_rank0(std::string& bytes) {
    agree_or_throw();
    run_.broadcast(bytes);
}

std::shared_ptr<Heightmap> NodeTiling::scatter_from_rank0(const Heightmap* whole) {
    agree_or_throw();
    return run_.scatter(whole);
}

void NodeTiling::carry(Toward toward, std::span<double> values, int per_line,
                       const std::function<void(int, int)>& advance) {
    const TileSplit& split = run_.split();
    const int rank = this->rank(), c = rank % split.cols, r = rank / split.cols;
    int from = -1, to = -1;  // upstream and downstream neighbours
    switch (toward) {
        case Toward::east: from = c > 0 ? rank - 1 : -1, to = c + 1 < split.cols ? rank + 1 : -1; break;
        case Toward::west: from = c + 1 < split.cols ? rank + 1 : -1, to = c > 0 ? rank - 1 : -1; break;
        case Toward::south:
            from = r > 0 ? rank - split.cols : -1, to = r + 1 < split.rows ? rank + split.cols : -1;
            break;
        case Toward::north:
            from = r + 1 < split.rows ? rank + split.cols : -1, to = r > 0 ? rank - split.cols : -1;
            break;
    }
    const int lines = per_line > 0 ? int(values.size() / std::size_t(per_line)) : 0;
    // Blocks of 64 lines: small enough that the downstream neighbour starts soon, large
    // enough that a 4096-line tile sends 64 messages (a few latencies) a call.
    constexpr int kBlock = 64;
    const int tag = kTagCarry + 1 + int(toward);  // one tag per direction: a west carry never meets an east one
    for (int first = 0; first < lines; first += kBlock) {
        const int count = std::min(kBlock, lines - first);
        double* block = values.data() + std::size_t(first) * std::size_t(per_line);
        const std::size_t bytes = std::size_t(count) * std::size_t(per_line) * sizeof(double);
        if (from >= 0) mpi::recv(block, bytes, from, tag);
        advance(first, count);
        if (to >= 0) mpi::send(block, bytes, to, tag);
    }
}

namespace {

/// The indices [lo, hi) of the positions of `axis` that lie in [a, b).
std::pair<int, int> samples_within(const AxisSamples& axis, int a, int b) {
    const auto first_at_least = [&](int v) {  // the positions increase: a binary search over the indices
        int lo = 0, hi = axis.size();
        while (lo < hi) {
            const int mid = lo + (hi - lo) / 2;
            if (axis.at(mid) < v) lo = mid + 1;
            else hi = mid;
        }
        return lo;
    };
    const int lo = first_at_least(a), hi = first_at_least(b);
    return {lo, std::max(lo, hi)};
}

bool valid_axis(const AxisSamples& axis, int extent) {
    if (axis.count < 0 || axis.step < 1) return false;
    std::int64_t end = -1;  // the progression's last position
    if (axis.count > 0) {
        end = axis.first + std::int64_t(axis.count - 1) * axis.step;
        if (axis.first < 0 || end >= extent) return false;
    }
    return axis.last < 0 || (axis.last > end && axis.last < extent);
}

}  // namespace

std::vector<float> NodeTiling::fetch_samples(const float* mine, AxisSamples columns, AxisSamples rows) {
    agree_or_throw();
    if (!valid_axis(columns, grid_width()) || !valid_axis(rows, grid_height()))
        throw Error("internal error: fetch of samples outside the " + std::to_string(grid_width()) + "x" +
                    std::to_string(grid_height()) + " grid");
    if (columns.size() == 0 || rows.size() == 0) columns = rows = {};
    // Every rank learns every rank's lattice, so each knows what to send whom without asking.
    const int n = ranks();
    std::vector<int> wants(std::size_t(8 * n));
    const int own_want[8] = {columns.first, columns.step, columns.count, columns.last,
                             rows.first,    rows.step,    rows.count,    rows.last};
    mpi::allgather(own_want, 8, wants.data());
    auto want_of = [&](int r) {
        const int* w = &wants[std::size_t(8 * r)];
        return std::pair{AxisSamples{w[0], w[1], w[2], w[3]}, AxisSamples{w[4], w[5], w[6], w[7]}};
    };
    // The index ranges of a lattice that fall in a tile: [c0, c1) × [r0, r1).
    struct Part {
        int c0, c1, r0, r1;
        std::size_t size() const { return std::size_t(c1 - c0) * std::size_t(r1 - r0); }
    };
    auto part = [](const TileRect& t, const AxisSamples& cols, const AxisSamples& rws) {
        const auto [c0, c1] = samples_within(cols, t.x0, t.x1());
        const auto [r0, r1] = samples_within(rws, t.y0, t.y1());
        return Part{c0, c1, r0, r1};
    };
    const TileRect o = owned();
    const int ncols = columns.size();
    std::vector<float> out(std::size_t(ncols) * std::size_t(rows.size())), give_buffer, take_buffer;
    // Round s: send to rank + s what it wants of this tile, receive from rank − s what it holds of the
    // lattice. Both ends of a pair compute the same part, so an empty one is skipped on both.
    for (int s = 0; s < n; ++s) {
        const int to = (rank() + s) % n, from = (rank() - s + n) % n;
        const auto [to_cols, to_rows] = want_of(to);
        const Part give = part(o, to_cols, to_rows), take = part(tile(from), columns, rows);
        give_buffer.resize(give.size());
        std::size_t k = 0;
        for (int j = give.r0; j < give.r1; ++j) {
            const float* row = mine + std::size_t(to_rows.at(j) - o.y0) * std::size_t(o.width);
            for (int i = give.c0; i < give.c1; ++i) give_buffer[k++] = row[to_cols.at(i) - o.x0];
        }
        if (s == 0) {
            take_buffer.swap(give_buffer);  // this rank's own part of its own lattice
        } else {
            take_buffer.resize(take.size());
            mpi::sendrecv(give_buffer.data(), give_buffer.size() * sizeof(float), give.size() ? to : -1,
                          take_buffer.data(), take_buffer.size() * sizeof(float), take.size() ? from : -1, kTagFetch);
        }
        k = 0;
        for (int j = take.r0; j < take.r1; ++j)
            for (int i = take.c0; i < take.c1; ++i)
                out[std::size_t(j) * std::size_t(ncols) + std::size_t(i)] = take_buffer[k++];
    }
    return out;
}

void TiledRun::broadcast(std::string& text) { mpi::broadcast(text); }

std::vector<std::string> TiledRun::gather_text(const std::string& text) {
    if (rank_ != 0) {
        const std::uint64_t n = text.size();
        mpi::send(&n, sizeof n, 0, kTagText);
        if (n) mpi::send(text.data(), text.size(), 0, kTagText);
        return {};
    }
    std::vector<std::string> all(static_cast<std::size_t>(ranks()));
    all[0] = text;
    for (int r = 1; r < ranks(); ++r) {
        std::uint64_t n = 0;
        mpi::recv(&n, sizeof n, r, kTagText);
        all[std::size_t(r)].resize(std::size_t(n));
        if (n) mpi::recv(all[std::size_t(r)].data(), std::size_t(n), r, kTagText);
    }
    return all;
}

std::shared_ptr<Heightmap> TiledRun::gather(const Heightmap* tile) {
    const TileRect mine = owned();
    if (!tile || tile->width() != mine.width || tile->height() != mine.height)
        throw Error("internal error: gather got no tile or one of the wrong size");
    const std::vector<std::string> names = tile->layer_names();
    if (rank_ != 0) {
        mpi::send(tile->heights().data(), tile->size() * sizeof(float), 0, kTagTile);
        for (const auto& n : names) mpi::send(tile->layer(n).data, tile->size() * sizeof(float), 0, kTagTile);
        return nullptr;
    }
    auto whole = std::make_shared<Heightmap>(split_.grid_width, split_.grid_height, tile->cell());
    std::vector<GridView> grids{whole->view()};
    for (const auto& n : names) grids.push_back(whole->layer(n, 0.0f));
    std::vector<float> buffer;
    for (int r = 0; r < ranks(); ++r) {
        const TileRect t = split_.tile(r);
        buffer.resize(std::size_t(t.width) * std::size_t(t.height));
        for (std::size_t k = 0; k < grids.size(); ++k) {
            if (r == 0) {
                const float* src = k == 0 ? tile->heights().data() : tile->layer(names[k - 1]).data;
                std::copy(src, src + buffer.size(), buffer.begin());
            } else {
                mpi::recv(buffer.data(), buffer.size() * sizeof(float), r, kTagTile);
            }
            copy_rect(grids[k].data, grids[k].width, t.x0, t.y0, t.width, t.height, buffer.data(), true);
        }
    }
    return whole;
}

std::shared_ptr<Heightmap> TiledRun::scatter(const Heightmap* whole) {
    // Rank 0 says what it holds: size, cell, layers (one line each).
    std::string header;
    if (rank_ == 0) {
        std::ostringstream h;
        h.precision(17);
        if (!whole) h << "none\n";
        else {
            h << whole->width() << ' ' << whole->height() << ' ' << whole->cell() << '\n';
            for (const auto& n : whole->layer_names()) h << n << '\n';
        }
        header = h.str();
    }
    mpi::broadcast(header);
    std::istringstream h(header);
    std::string first;
    std::getline(h, first);
    if (first == "none") throw Error("internal error: scatter of a value rank 0 does not hold");
    int w = 0, hg = 0;
    double cell = 1.0;
    std::istringstream(first) >> w >> hg >> cell;
    if (w != split_.grid_width || hg != split_.grid_height)
        throw BadInput("a tiled node was given a " + std::to_string(w) + "x" + std::to_string(hg) +
                       " heightmap, but the tiles cut the spec's " + std::to_string(split_.grid_width) + "x" +
                       std::to_string(split_.grid_height) + " grid; give the spec a grid of the input's size");
    std::vector<std::string> names;
    for (std::string n; std::getline(h, n);) names.push_back(n);
    const TileRect mine = owned();
    auto tile = std::make_shared<Heightmap>(mine.width, mine.height, cell);
    std::vector<GridView> mine_grids{tile->view()};
    for (const auto& n : names) mine_grids.push_back(tile->layer(n, 0.0f));
    if (rank_ != 0) {
        for (auto& g : mine_grids) mpi::recv(g.data, g.size() * sizeof(float), 0, kTagTile);
        return tile;
    }
    std::vector<float> buffer;
    for (int r = 0; r < ranks(); ++r) {
        const TileRect t = split_.tile(r);
        buffer.resize(std::size_t(t.width) * std::size_t(t.height));
        for (std::size_t k = 0; k <= names.size(); ++k) {
            const float* src = k == 0 ? whole->heights().data() : whole->layer(names[k - 1]).data;
            copy_rect(const_cast<float*>(src), w, t.x0, t.y0, t.width, t.height, buffer.data(), false);
            if (r == 0) std::copy(buffer.begin(), buffer.end(), mine_grids[k].data);
            else mpi::send(buffer.data(), buffer.size() * sizeof(float), r, kTagTile);
        }
    }
    return tile;
}

bool TiledRun::prepare_inputs(const PlannedNode& node, std::vector<Value>& inputs) {
    const bool tiled = runs_tiled(node);
    for (std::size_t i = 0; i < inputs.size() && i < node.inputs.size(); ++i) {
        const std::string& key = node.inputs[i];
        if (key.empty()) continue;
        auto it = places_.find(key);
        const Place place = it == places_.end() ? Place::rank0 : it->second;
        // A series (time-lapse frames) stays on rank 0, whole: the node reads it there and
        // cuts what it needs with scatter_from_rank0 (erode:stream-power's uplift_history).
        // The other ranks get a series of no frames, so that every rank sees the input given.
        const bool series = i < node.node->inputs.size() && node.node->inputs[i].many == Many::series;
        if (tiled && place == Place::rank0 && series) {
            if (rank_ != 0) {
                auto none = std::make_shared<Series>();
                none->element = node.node->inputs[i].type;
                inputs[i] = Value(std::shared_ptr<const Series>(std::move(none)));
            }
        } else if (tiled && place == Place::rank0) {
            inputs[i] = Value(scatter(rank_ == 0 ? inputs[i].heightmap().get() : nullptr));
        } else if (!tiled && place == Place::tiles) {
            auto whole = gather(inputs[i].heightmap().get());
            inputs[i] = whole ? Value(std::move(whole)) : Value();
        }
    }
    return tiled || rank_ == 0;
}

void TiledRun::produced(const PlannedNode& node) {
    if (node.value_name.empty()) return;
    const Place p = runs_tiled(node) ? Place::tiles : Place::rank0;
    places_[node.value_name] = p;
    for (const auto& side : node.node->side_outputs)
        places_[node.value_name + "." + side.name] =
            side.type == ValueType::heightmap && !side.series ? p : Place::rank0;
}

}  // namespace orogen
