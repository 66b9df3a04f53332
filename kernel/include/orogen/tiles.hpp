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
// single-process run gives there (the seam tests compare the bytes). The
// halo exchange below hands it the vertices of the neighbouring tiles it
// needs. No MPI header appears here: the kernel implements the exchange.
#pragma once

#include <orogen/error.hpp>
#include <orogen/grid.hpp>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace orogen {

class Heightmap;  // values.hpp

/// A rectangle of vertices in global grid coordinates.
struct TileRect {
    int x0 = 0, y0 = 0;         ///< first column and row
    int width = 0, height = 0;  ///< vertices
    int x1() const { return x0 + width; }
    int y1() const { return y0 + height; }
    bool operator==(const TileRect&) const = default;
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

/// The split of a tiled run, as one rank sees it.
class Tiling {
public:
    virtual ~Tiling() = default;
    virtual int rank() const = 0;
    virtual int ranks() const = 0;
    virtual int grid_width() const = 0;   ///< the whole grid, vertices
    virtual int grid_height() const = 0;
    /// This rank's tile: what its heightmaps hold.
    virtual TileRect owned() const = 0;
    /// Rank `rank`'s tile (0 ≤ rank < ranks()).
    virtual TileRect tile(int rank) const = 0;
    /// `owned` grown by `halo` vertices on every side, clipped to the grid.
    TileRect grown(int halo) const;

    /// Collective (every rank calls it, in the same order): fills the part of
    /// `held` (a grid covering grown(halo)) outside `owned` with the
    /// neighbouring ranks' tiles, corners included. The owned part is sent,
    /// never changed. Needs every tile to be at least `halo` vertices wide and
    /// high (the kernel checks this at check time against the node's
    /// tile_halo). Throws PeerFailed if another rank failed before the call.
    virtual void exchange_halo(GridView held, int halo) = 0;
    /// Seconds spent so far in exchange_halo() waiting for every rank to arrive
    /// (its opening agreement), as opposed to moving the halo: under load or
    /// with uneven tiles, most of an exchange's time is this wait.
    virtual double seconds_waiting() const = 0;
    /// The line a tiled sweeping eroder reports when it ends (NodeContext::info):
    /// "rank R of N: tile WxH at (X, Y), STEPS steps: sweeps S s, halo exchange
    /// E s (P %), of which waiting for the other ranks W s", W counted from
    /// `waited_before` (seconds_waiting() when the node started).
    std::string sweep_note(std::int64_t steps, double sweeping_s, double exchanging_s, double waited_before) const;
    /// Collective: the least and greatest of each rank's `lo`/`hi` (exact).
    virtual void min_max(float& lo, float& hi) = 0;

    // For eroders whose every step needs global reductions (erode:pipe's
    // CFL limit and sediment fix-up): several fields at once, and sums in
    // the single process's order.

    /// Collective: exchange_halo() for several grids of the same size (each
    /// covering grown(halo)) at once: one opening agreement and one message
    /// per side, whatever the number of grids.
    virtual void exchange_halos(std::span<const GridView> held, int halo) = 0;
    /// Collective: element by element, the greatest of every rank's
    /// `values[0..count)`, on every rank (exact: a maximum does not round).
    /// Opens with the failure agreement (throws PeerFailed).
    virtual void max_all(float* values, int count) = 0;
    /// Collective, along each row of tiles from west to east: `carry` holds
    /// `per_row` values for each of this tile's rows; they come in from the
    /// west neighbour (the westmost tile keeps what the caller put there),
    /// `advance(first, count)` carries rows [first, first + count) of them over
    /// this tile's columns, and they go on to the east neighbour. This
    /// reproduces a single process's sequential accumulation along whole rows
    /// (floating-point sums are not associative, so partial sums per tile
    /// would not give its bits). The rows travel in blocks, so that a tile
    /// works on a block while its east neighbour works on the one before: the
    /// chain costs about one tile's pass plus a block's per tile to the east,
    /// not a whole pass per tile. Every tile of a row of tiles has the same
    /// rows. The caller must not throw between its last collective and this
    /// call on one rank only (a west neighbour that never sends would hang it).
    virtual void carry_east(std::span<double> carry, int per_row,
                            const std::function<void(int first, int count)>& advance) = 0;
    /// Collective: `per_row` values for each row of the whole grid, in row
    /// order, on every rank, taken from the eastmost tile of each row of
    /// tiles (`mine`: owned().height × per_row values there; ignored
    /// elsewhere). With carry_east(): whole-row results, then summed in row
    /// order by every rank alike.
    virtual std::vector<double> gather_rows(std::span<const double> mine, int per_row) = 0;
    /// Whether this tile is the eastmost of its row of tiles (the one whose `mine` gather_rows() takes).
    bool eastmost() const { return owned().x1() == grid_width(); }

    // For nodes whose pieces of work do not follow the tiles (export:tiles'
    // engine tiles straddle them): any rectangle of the grid, from whichever
    // ranks hold it.

    /// The rank whose tile holds vertex (x, y) of the whole grid.
    int rank_at(int x, int y) const;
    /// Collective: every rank asks for one rectangle `want` inside the whole
    /// grid (width or height 0: nothing) and gets its values, row-major, taken
    /// from the tiles that hold them. `mine`: this rank's tile, owned().width ×
    /// owned().height values, row-major. Opens with the failure agreement
    /// (throws PeerFailed).
    std::vector<float> fetch(const float* mine, TileRect want) {
        return fetch_samples(mine, {want.x0, 1, want.width, -1}, {want.y0, 1, want.height, -1});
    }
    /// Collective: fetch() of a lattice: the values at every (columns.at(i),
    /// rows.at(j)), row-major, columns.size() × rows.size() of them (either
    /// empty: nothing). Every position must lie inside the grid. For a level
    /// of detail that covers a large area at a fraction of its samples.
    virtual std::vector<float> fetch_samples(const float* mine, AxisSamples columns, AxisSamples rows) = 0;
    /// Collective: the sum of every rank's `value`, added in rank order on
    /// every rank (the same bits everywhere; exact for integers below 2^53).
    /// Opens with the failure agreement.
    virtual double sum_all(double value) = 0;

    // For nodes that compute something once for the whole grid and draw it
    // into every tile (tectonics:plates runs Box2D on rank 0).

    /// Collective: rank 0's `bytes` on every rank (others' are replaced).
    /// Opens with the failure agreement, so rank 0 failing before the call
    /// ends the others with PeerFailed rather than a hang.
    virtual void share_from_rank0(std::string& bytes) = 0;

    // For line solvers whose recurrence runs across the whole grid
    // (erode:diffusion's tridiagonal sweeps).

    /// Which way carry() goes: along each row of tiles (east: from the west
    /// neighbour to the east one; west: the reverse), or along each column of
    /// tiles (south: from the north neighbour to the south one; north: the
    /// reverse).
    enum class Toward { east, west, south, north };
    /// Collective, along each row (east, west) or column (south, north) of
    /// tiles: carry_east() in any of the four directions. `values` holds
    /// `per_line` values for each line of this tile: its rows going east or
    /// west, its columns going south or north. They come in from the upstream
    /// neighbour (the first tile keeps what the caller put there),
    /// `advance(first, count)` carries lines [first, first + count) over this
    /// tile, and they go on downstream, in blocks of lines so that neighbours
    /// overlap. A Thomas solve along whole rows is a forward carry east (the
    /// eliminated coefficients) and a backward one west (the solution); with an
    /// advance that swaps what came in for the tile's own edge, a carry is also
    /// an edge exchange in one direction. Same caveat as carry_east().
    virtual void carry(Toward toward, std::span<double> values, int per_line,
                       const std::function<void(int first, int count)>& advance) = 0;

    // For nodes that solve a graph spanning the tiles (erode:stream-power's
    // drainage: every tile routes its own cells, rank 0 joins the tiles' edges).

    /// Collective: exchange_halos() for grids of doubles (each covering
    /// grown(halo), row-major): heights a double-precision model carries
    /// between steps, or whole numbers below 2^53 (cell indices, counts).
    virtual void exchange_double_halos(std::span<double* const> held, int halo) = 0;
    /// Collective: every rank's `bytes`, in rank order, on rank 0 (empty
    /// elsewhere). With share_from_rank0(): rank 0 solves what the tiles sent
    /// and hands every rank the answer. Opens with the failure agreement.
    virtual std::vector<std::string> gather_to_rank0(const std::string& bytes) = 0;
    // For nodes that read a whole value rank 0 holds: a series input of a
    // tiled node stays there (the other ranks get a series of no frames), as
    // erode:stream-power's uplift_history.
    /// Collective: rank 0's whole-grid heightmap `whole` (its heights and
    /// layers; ignored on the other ranks) cut into tiles, every rank getting
    /// its own. Opens with the failure agreement. Throws BadInput if `whole`
    /// is not the grid's size.
    virtual std::shared_ptr<Heightmap> scatter_from_rank0(const Heightmap* whole) = 0;
};

}  // namespace orogen
