// A tiled run under MPI (docs/mpi.md): how the grid is split into tiles, the
// check-time rules a tiled plan must pass, and TiledRun, which the runner
// consults around every node (scatter to tiles, gather on rank 0, agree on
// failure). The MPI calls themselves are in mpi_comm.cpp.
#pragma once

#include "spec/diagnostics.hpp"
#include "spec/plan.hpp"

#include <orogen/session.hpp>
#include <orogen/tiles.hpp>
#include <orogen/values.hpp>

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace orogen {

/// The grid cut into rows × cols tiles (TileSplit, orogen/tiles.hpp).
TileSplit split_grid(int width, int height, int rows, int cols);

/// rows × cols = ranks with tiles as near square as the grid allows.
std::pair<int, int> automatic_tiles(int ranks, int width, int height);

struct TiledCheckOptions {
    int ranks = 1;
    bool tiles_given = false;  ///< --tiles given (else automatic): for the messages
    /// Memory one whole-grid heightmap may take on rank 0 (bytes), for the nodes that are not tiled.
    std::uint64_t whole_grid_limit = 0;
};

/// The rules a tiled run adds to the checker's: one tile per rank, tiles at
/// least as large as every tiled node's halo, the nodes that are not tiled
/// small enough to run whole on rank 0. Errors go to `diags` at the node.
void check_tiled(const Plan& plan, const TileSplit& split, const TiledCheckOptions& options, spec::Diagnostics& diags);

/// One rank's side of a tiled run: what the runner consults around every node.
class TiledRun {
public:
    TiledRun(TileSplit split, int rank) : split_(std::move(split)), rank_(rank) {}

    int rank() const { return rank_; }
    int ranks() const { return split_.count(); }
    TileRect owned() const { return split_.tile(rank_); }
    const TileSplit& split() const { return split_; }

    /// Collective, before `node` runs: gives it what it reads: tiles for a
    /// tiled node (a whole value held on rank 0 is cut and sent out), whole
    /// values on rank 0 for the others (tiles are gathered there). Returns
    /// whether this rank runs the node.
    bool prepare_inputs(const PlannedNode& node, std::vector<Value>& inputs);
    /// Record where `node`'s outputs live (tiles, or rank 0 only). A tiled node's side values that are not
    /// heightmaps (tectonics:plates' history) are whole values, held on rank 0.
    void produced(const PlannedNode& node);
    /// Collective: every rank's exit code so far (0 ok); returns the worst, and in `reporter` the lowest rank
    /// that failed (the one whose message is printed).
    int agree(int exit_code, int* reporter = nullptr);
    /// Collective: the tile of every rank, gathered into one whole heightmap on rank 0 (empty elsewhere).
    std::shared_ptr<Heightmap> gather(const Heightmap* tile);
    /// Collective: rank 0's whole heightmap `whole`, cut into tiles; this rank's tile.
    std::shared_ptr<Heightmap> scatter(const Heightmap* whole);

    /// Collective: rank 0's `text` on every rank.
    void broadcast(std::string& text);
    /// Collective: every rank's `text`, in rank order, on rank 0 (empty elsewhere).
    std::vector<std::string> gather_text(const std::string& text);

private:
    enum class Place { tiles, rank0 };
    TileSplit split_;
    int rank_;
    std::map<std::string, Place, std::less<>> places_;
};

/// What one tiled node sees of the run (NodeContext::tiling()): the run's
/// split with the node's ghost width, and the primitives over MPI. Each
/// collective but carry() opens with the run's failure agreement, its wait
/// counted in seconds_waiting().
class NodeTiling final : public Tiling {
public:
    NodeTiling(TiledRun& run, int halo) : Tiling(run.split(), run.rank(), halo), run_(run) {}

    std::vector<std::string> gather(std::string_view bytes, Gather where) override;
    std::vector<std::string> send_to_ranks(std::span<const std::string> to_rank) override;
    void share_from_rank0(std::string& bytes) override;
    std::shared_ptr<Heightmap> scatter_from_rank0(const Heightmap* whole) override;
    std::vector<float> fetch_samples(const float* mine, AxisSamples columns, AxisSamples rows) override;
    void carry(Toward toward, std::span<double> values, int per_line,
               const std::function<void(int, int)>& advance) override;

protected:
    void exchange_values(std::span<void* const> grids, std::size_t value_bytes) override;

private:
    /// The opening agreement: throws PeerFailed if a rank failed.
    void agree_or_throw();
    TiledRun& run_;
};

}  // namespace orogen
