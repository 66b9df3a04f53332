// orogen/tiles.hpp — what a node sees of a tiled (MPI) run.
//
// Under `mpirun -n N orogen run ...` the grid is split into R × C tiles, one
// per rank (docs/mpi.md). A node that declares NodeDescriptor::tile_halo ≥ 0
// runs on every rank at once: its heightmap inputs and its output hold only
// the rank's own tile (`owned`, in global vertex coordinates), and
// NodeContext::tiling() describes the split. Everything else runs on rank 0
// over the whole grid, the kernel gathering its inputs there.
//
// A tiled node must give, on every vertex of its tile, the very bits the
// single-process run gives there (the seam tests compare the bytes).
//
// The shape is PETSc's DMDA: the layout (the split, this rank's corners and
// its ghosted corners), the ghost width declared once (tile_halo), ghosted
// grids with one exchange for any number of them and any value type, and
// typed reductions with an operator. Everything is built over seven virtual
// primitives the kernel implements; no MPI header appears here. A tiled grid
// eroder's loop (grow, exchange, step, check, copy back) is TiledFields below.
#pragma once

#include <orogen/error.hpp>
#include <orogen/grid.hpp>

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace orogen {

class Heightmap;  // values.hpp

/// A rectangle of vertices in global grid coordinates.
struct TileRect {
    int x0 = 0, y0 = 0;  ///< first column and row
    int width = 0, height = 0;  ///< vertices
    int x1() const { return x0 + width; }
    int y1() const { return y0 + height; }
    bool operator==(const TileRect&) const = default;
};

/// The grid cut into rows × cols tiles; tile i = r·cols + c is rank i's.
/// Cuts fall at floor(k·size/parts) (the kernel's split_grid): tiles differ
/// in size by at most one vertex, and nothing is aligned to powers of two.
struct TileSplit {
    int grid_width = 0, grid_height = 0;
    int rows = 1, cols = 1;
    std::vector<int> xs, ys;  ///< cols+1 and rows+1 cut positions
    int count() const { return rows * cols; }
    TileRect tile(int index) const;
    int smallest_width() const;
    int smallest_height() const;
};

/// Sample positions along one axis of the whole grid, increasing: first,
/// first + step, ..., `count` of them, then `last` when ≥ 0 (beyond them).
/// A decimated lattice that keeps the grid's far edge: {0, 4, 8, ..., 4096}
/// or {0, 4, ..., 4092, 4095}.
struct AxisSamples {
    int first = 0, step = 1, count = 0, last = -1;
    int size() const { return count + (last >= 0 ? 1 : 0); }
    int at(int i) const { return i < count ? first + i * step : last; }
};

/// Thrown inside a tiled node on the ranks that did not fail when another
/// rank failed: the failing rank reports the error, the others stop quietly
/// with its exit code. A node lets it pass (it derives from orogen::Error).
class PeerFailed : public Error {
public:
    PeerFailed(int exit_code, Kind kind) : Error("another rank failed", kind), exit_code_(exit_code) {}
    int exit_code() const { return exit_code_; }

private:
    int exit_code_;
};

/// The split of a tiled run, as one rank sees it while one node runs.
///
/// "Collective" below: every rank calls it, in the same order. Every
/// collective but carry() opens with the ranks' failure agreement: if another
/// rank failed before the call, it throws PeerFailed (let it pass).
class Tiling {
public:
    virtual ~Tiling() = default;

    // ------------------------------------------------------------ the layout

    int rank() const { return rank_; }
    int ranks() const { return split_.count(); }
    int grid_width() const { return split_.grid_width; }  ///< the whole grid, vertices
    int grid_height() const { return split_.grid_height; }
    /// This rank's tile: what its heightmaps hold.
    TileRect owned() const { return split_.tile(rank_); }
    /// Rank `rank`'s tile (0 ≤ rank < ranks()).
    TileRect tile(int rank) const { return split_.tile(rank); }
    /// The rank whose tile holds vertex (x, y) of the whole grid.
    int rank_at(int x, int y) const;
    /// The ranks whose tiles hold a vertex of `rect` (clipped to the grid), in
    /// rank order; none when it lies outside the grid. With send_to_ranks():
    /// what reaches a few cells beyond its own tile goes to those tiles only.
    std::vector<int> ranks_meeting(TileRect rect) const;
    /// Whether this tile is the eastmost of its row of tiles.
    bool eastmost() const { return owned().x1() == grid_width(); }

    // ------------------------------------------------------- ghosted grids

    /// The ghost width: the node's NodeDescriptor::tile_halo, declared there
    /// once. The kernel has checked that every tile is at least this wide and
    /// high.
    int halo() const { return halo_; }
    /// owned() grown by halo() vertices on every side, clipped to the grid:
    /// what a ghosted grid covers.
    TileRect ghosted() const;
    /// A ghosted grid holding `tile` (owned().width × owned().height values,
    /// row-major) in its owned part, T() in the ghosts (exchange() fills them).
    template <typename T>
    std::vector<T> ghosted_copy(const T* tile) const;
    /// The same into `held`, reusing its memory (a solver's working grid kept
    /// between the steps of a run: no fresh pages to fault in each step).
    template <typename T>
    void ghosted_copy(const T* tile, std::vector<T>& held) const;
    /// Collective: fills the ghosts of each of `grids` (ghosted grids,
    /// row-major) with the neighbouring ranks' owned values, corners included;
    /// the owned parts are sent, never changed. One opening agreement and one
    /// message per side, whatever the number of grids. T: float, double or
    /// std::int64_t (whole numbers, cell indices).
    template <typename T>
    void exchange(std::span<T* const> grids);
    /// exchange() of float views, each of the ghosted() size (else Error).
    void exchange(std::span<const GridView> grids);
    void exchange(GridView grid) { exchange(std::span<const GridView>(&grid, 1)); }

    // ---------------------------------------------------------- reductions

    enum class Reduce { sum, min, max };
    /// Collective: element by element, every rank's `values` combined by `op`,
    /// on every rank, in rank order (a sum adds rank 0's, then rank 1's, ...
    /// to 0: the same bits everywhere, whatever MPI's reduction tree; exact
    /// for integers below 2^53 in a double). T: float, double, std::int64_t.
    /// Every rank gives as many values.
    template <typename T>
    void reduce(std::span<T> values, Reduce op);
    template <typename T>
    T reduce(T value, Reduce op) {
        reduce(std::span<T>(&value, 1), op);
        return value;
    }

    // ------------------------------------------------------ moving bytes

    enum class Gather { to_rank0, to_every_rank };
    /// Collective: every rank's `bytes`, in rank order, on rank 0 (empty
    /// elsewhere) or on every rank. With share_from_rank0(): rank 0 solves
    /// what the tiles sent and hands every rank the answer.
    virtual std::vector<std::string> gather(std::string_view bytes, Gather where) = 0;
    /// Collective: `to_rank[r]` (ranks() of them, most of them empty as a
    /// rule) goes to rank r; returns what every rank sent this one, in rank
    /// order (its own to itself included). Only the non-empty ones travel,
    /// after one all-to-all of their sizes: for what each tile needs from its
    /// near neighbours only, however many ranks run (a river's floodplain
    /// reaching across a seam), where gather() would send everything to all.
    virtual std::vector<std::string> send_to_ranks(std::span<const std::string> to_rank) = 0;
    /// Collective: rank 0's `bytes` on every rank (others' are replaced).
    virtual void share_from_rank0(std::string& bytes) = 0;
    /// Collective: rank 0's whole-grid heightmap `whole` (its heights and
    /// layers; ignored on the other ranks) cut into tiles, every rank getting
    /// its own (a series input of a tiled node stays on rank 0). Throws
    /// BadInput if `whole` is not the grid's size.
    virtual std::shared_ptr<Heightmap> scatter_from_rank0(const Heightmap* whole) = 0;
    /// Collective: every rank asks for the values at every (columns.at(i),
    /// rows.at(j)) of the whole grid, row-major, columns.size() × rows.size()
    /// of them (either empty: nothing), and gets them from the tiles that hold
    /// them. `mine`: this rank's tile, owned().width × owned().height values.
    /// Every position must lie inside the grid. For pieces of work that do not
    /// follow the tiles (export:tiles' engine tiles, a level of detail).
    virtual std::vector<float> fetch_samples(const float* mine, AxisSamples columns, AxisSamples rows) = 0;
    /// fetch_samples() of one rectangle `want` (width or height 0: nothing).
    std::vector<float> fetch(const float* mine, TileRect want) {
        return fetch_samples(mine, {want.x0, 1, want.width, -1}, {want.y0, 1, want.height, -1});
    }

    /// Which way carry() goes: along each row of tiles (east: from the west
    /// neighbour to the east one; west: the reverse), or along each column of
    /// tiles (south: from the north neighbour to the south one; north: the
    /// reverse).
    enum class Toward { east, west, south, north };
    /// Collective, along each row (east, west) or column (south, north) of
    /// tiles: `values` holds `per_line` values for each line of this tile (its
    /// rows going east or west, its columns going south or north). They come
    /// in from the upstream neighbour (the first tile keeps what the caller
    /// put there), `advance(first, count)` carries lines [first, first +
    /// count) over this tile, and they go on downstream, in blocks of lines
    /// so that neighbours overlap: the chain costs about one tile's pass plus
    /// a block's per tile downstream. This reproduces a single process's
    /// sequential recurrence along whole lines (floating-point sums are not
    /// associative; a Thomas solve is a carry east then one west). No opening
    /// agreement: the caller must not throw between its last collective and
    /// this call on one rank only (an upstream neighbour that never sends
    /// would hang it).
    virtual void carry(Toward toward, std::span<double> values, int per_line,
                       const std::function<void(int first, int count)>& advance) = 0;
    /// Collective: `per_row` values for each row of the whole grid, in row
    /// order, on every rank, taken from the eastmost tile of each row of tiles
    /// (`mine`: owned().height × per_row values there; ignored elsewhere).
    /// With carry() east: whole-row results, then summed in row order by every
    /// rank alike.
    std::vector<double> gather_rows(std::span<const double> mine, int per_row);

    /// Seconds this node has spent so far in the opening agreements of its
    /// collectives, waiting for every rank to arrive (as opposed to moving
    /// data): under load or with uneven tiles, most of an exchange is this.
    double seconds_waiting() const { return waiting_; }

protected:
    Tiling(TileSplit split, int rank, int halo) : split_(std::move(split)), rank_(rank), halo_(halo) {}
    /// The primitive under exchange(): `grids` of ghosted() size, `value_bytes` each value.
    virtual void exchange_values(std::span<void* const> grids, std::size_t value_bytes) = 0;
    /// Added to by the implementation's opening agreements (seconds).
    double waiting_ = 0.0;

private:
    TileSplit split_;
    int rank_ = 0, halo_ = 0;
};

template <typename T>
std::vector<T> Tiling::ghosted_copy(const T* tile) const {
    std::vector<T> held;
    ghosted_copy(tile, held);
    return held;
}

template <typename T>
void Tiling::ghosted_copy(const T* tile, std::vector<T>& held) const {
    const TileRect own = owned(), g = ghosted();
    held.assign(std::size_t(g.width) * std::size_t(g.height), T());
    const std::size_t ox = std::size_t(own.x0 - g.x0), oy = std::size_t(own.y0 - g.y0);
    for (std::size_t y = 0; y < std::size_t(own.height); ++y)
        std::copy_n(tile + y * std::size_t(own.width), own.width, held.data() + (y + oy) * std::size_t(g.width) + ox);
}

template <typename T>
void Tiling::exchange(std::span<T* const> grids) {
    static_assert(std::is_same_v<T, float> || std::is_same_v<T, double> || std::is_same_v<T, std::int64_t>);
    std::vector<void*> raw(grids.begin(), grids.end());
    exchange_values(raw, sizeof(T));
}

template <typename T>
void Tiling::reduce(std::span<T> values, Reduce op) {
    static_assert(std::is_same_v<T, float> || std::is_same_v<T, double> || std::is_same_v<T, std::int64_t>);
    const std::vector<std::string> all = gather(
        std::string_view(reinterpret_cast<const char*>(values.data()), values.size_bytes()), Gather::to_every_rank);
    for (const std::string& part : all)
        if (part.size() != values.size_bytes()) throw Error("internal error: the ranks reduce different counts");
    for (std::size_t i = 0; i < values.size(); ++i) {
        T acc{};
        for (std::size_t r = 0; r < all.size(); ++r) {
            T v;
            std::memcpy(&v, all[r].data() + i * sizeof(T), sizeof(T));
            if (op == Reduce::sum) acc += v;
            else if (r == 0) acc = v;
            else if (op == Reduce::max ? v > acc : v < acc) acc = v;  // ties keep the lower rank's
        }
        values[i] = acc;
    }
}

/// The tiled loop of a grid eroder (erode:thermal, hydraulic, pipe): its
/// fields moved from the tile into ghosted grids, their ghosts refilled by one
/// exchange before each sweep of steps (a sweep of k steps needs a halo k
/// stencils wide, and then leaves the owned part with the single process's
/// bits, only the ghosts stale), the finiteness check of the owned part, the
/// owned parts moved back into tiles, and the info line saying where the time
/// went. Its grids live until take().
class TiledFields {
public:
    TiledFields(Tiling& tiles, double cell);
    Tiling& tiling() const { return tiles_; }
    TileRect owned() const { return own_; }
    TileRect ghosted() const { return ghosted_; }
    int ox() const { return ox_; }  ///< where the owned part starts in a grid
    int oy() const { return oy_; }

    /// A new ghosted grid holding `tile` (owned().width × owned().height,
    /// row-major) in its owned part, 0 in the ghosts.
    GridView grow(const float* tile);
    /// A new ghosted grid of zeros.
    GridView zeros();
    /// Collective: refills the ghosts of `grids` (this object's), counted as
    /// exchanging in the info line.
    void exchange(std::span<const GridView> grids);
    void exchange(GridView grid) { exchange(std::span<const GridView>(&grid, 1)); }
    /// `steps` steps in sweeps of at most `per_sweep`: before each, exchange()
    /// of fields() (the grids the sweep reads across the tile's edge), then
    /// sweep(first step, count) (timed as sweeping), then after(steps done).
    template <typename Fields, typename Sweep, typename After>
    void sweeps(std::int64_t steps, int per_sweep, Fields&& fields, Sweep&& sweep, After&& after);
    /// Throws Error if the owned part of `grid` (one of this object's, or an
    /// owned tile when `grid` is owned()'s size) holds a NaN or infinity:
    /// NodeContext::check_finite's message, naming the sample by its index in
    /// the whole grid.
    void check_finite(ConstGridView grid, std::string_view what, std::int64_t step) const;
    /// The owned part of `grid` (this object's) as a tile, moved to the front
    /// of the grid's own memory (a copy into fresh memory costs page faults:
    /// seconds of system time at 4097² on a loaded machine); the grid is gone.
    std::vector<float> take(GridView grid);
    /// Frees `grid` (this object's) now.
    void drop(GridView grid) { std::vector<float>().swap(storage_of(grid)); }

    /// "rank R of N: tile WxH at (X, Y), STEPS steps: sweeps S s, halo exchange
    /// E s (P %), of which waiting for the other ranks W s".
    std::string note(std::int64_t steps) const;

private:
    std::vector<float>& storage_of(const GridView& grid);
    Tiling& tiles_;
    double cell_;
    TileRect own_, ghosted_;
    int ox_ = 0, oy_ = 0;
    std::vector<std::unique_ptr<std::vector<float>>> grids_;
    std::chrono::steady_clock::duration exchanging_{}, sweeping_{};
    double waited_before_ = 0.0;
};

template <typename Fields, typename Sweep, typename After>
void TiledFields::sweeps(std::int64_t steps, int per_sweep, Fields&& fields, Sweep&& sweep, After&& after) {
    for (std::int64_t i = 0; i < steps;) {
        const int k = int(std::min<std::int64_t>(per_sweep, steps - i));
        exchange(fields());
        const auto t0 = std::chrono::steady_clock::now();
        sweep(i, k);
        sweeping_ += std::chrono::steady_clock::now() - t0;
        i += k;
        after(i);
    }
}

}  // namespace orogen
