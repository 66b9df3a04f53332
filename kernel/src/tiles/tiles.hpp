// A tiled run under MPI (docs/mpi.md): how the grid is split into tiles, the
// check-time rules a tiled plan must pass, and TiledRun, which the runner
// consults around every node (scatter to tiles, gather on rank 0, agree on
// failure). The MPI calls themselves are in mpi_comm.cpp.
#pragma once

#include "spec/diagnostics.hpp"
#include "spec/plan.hpp"

#include <orogen/tiles.hpp>
#include <orogen/values.hpp>

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace orogen {

/// The grid cut into rows × cols tiles; tile i = r·cols + c is rank i's.
/// Cuts fall at floor(k·size/parts): tiles differ in size by at most one
/// vertex, and nothing is aligned to powers of two.
struct TileSplit {
    int grid_width = 0, grid_height = 0;
    int rows = 1, cols = 1;
    std::vector<int> xs, ys;  ///< cols+1 and rows+1 cut positions
    int count() const { return rows * cols; }
    TileRect tile(int index) const;
    int smallest_width() const;
    int smallest_height() const;
};

TileSplit split_grid(int width, int height, int rows, int cols);

/// "RxC" (rows x columns, e.g. "2x3") → {R, C}; nullopt if it is not that.
std::optional<std::pair<int, int>> parse_tiles(std::string_view text);

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

/// One rank's side of a tiled run.
class TiledRun final : public Tiling {
public:
    TiledRun(TileSplit split, int rank) : split_(std::move(split)), rank_(rank) {}

    int rank() const override { return rank_; }
    int ranks() const override { return split_.count(); }
    int grid_width() const override { return split_.grid_width; }
    int grid_height() const override { return split_.grid_height; }
    TileRect owned() const override { return split_.tile(rank_); }
    TileRect tile(int rank) const override { return split_.tile(rank); }
    void exchange_halo(GridView held, int halo) override;
    void min_max(float& lo, float& hi) override;
    void exchange_halos(std::span<const GridView> held, int halo) override;
    void max_all(float* values, int count) override;
    void carry_east(std::span<double> carry, int per_row, const std::function<void(int, int)>& advance) override;
    void carry(Toward toward, std::span<double> values, int per_line,
               const std::function<void(int, int)>& advance) override;
    std::vector<double> gather_rows(std::span<const double> mine, int per_row) override;
    double seconds_waiting() const override { return waiting_; }
    std::vector<float> fetch_samples(const float* mine, AxisSamples columns, AxisSamples rows) override;
    double sum_all(double value) override;
    void share_from_rank0(std::string& bytes) override;
    void exchange_double_halos(std::span<double* const> held, int halo) override;
    std::vector<std::string> gather_to_rank0(const std::string& bytes) override;
    std::shared_ptr<Heightmap> scatter_from_rank0(const Heightmap* whole) override;

    /// Whether `node` runs on every rank's tile (else on rank 0 over the whole grid).
    static bool runs_tiled(const PlannedNode& node);
    /// "" if `node` runs tiled, else why it runs on rank 0 (for the messages).
    static std::string untiled_reason(const PlannedNode& node);
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

    const TileSplit& split() const { return split_; }

private:
    /// The opening agreement of every collective a tiled node calls: throws PeerFailed if a rank failed.
    void agree_or_throw();
    /// exchange_halos() over grids of T (float or double), `width` values per row of grown(halo).
    template <typename T>
    void exchange_grids(std::span<T* const> grids, int halo);
    enum class Place { tiles, rank0 };
    TileSplit split_;
    int rank_;
    double waiting_ = 0.0;
    std::map<std::string, Place, std::less<>> places_;
};

}  // namespace orogen
