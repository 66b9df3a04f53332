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

#include <cstdint>

namespace orogen {

/// A rectangle of vertices in global grid coordinates.
struct TileRect {
    int x0 = 0, y0 = 0;         ///< first column and row
    int width = 0, height = 0;  ///< vertices
    int x1() const { return x0 + width; }
    int y1() const { return y0 + height; }
    bool operator==(const TileRect&) const = default;
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
    /// Collective: the least and greatest of each rank's `lo`/`hi` (exact).
    virtual void min_max(float& lo, float& hi) = 0;
};

}  // namespace orogen
