// tiled.hpp — the stream-power model (stream_power.hpp) on one rank's tile of
// a tiled (MPI) run, giving on every cell of the tile the bits the whole-grid
// Model gives there.
//
// Each step every rank uplifts, routes and diffuses its own tile, and the
// parts that follow the rivers across the tiles are joined the way Barnes
// (2017, 2019) joins drainage: a tile's cells form trees ("local trees"),
// each rooted at a cell of the tile that is its own receiver (an outlet or a
// pit) or at an exit, a cell on the tile's edge whose receiver lies in the
// next tile. Only the tiles' edges travel: every rank sends rank 0 the local
// tree of each edge cell (its root, and where an exit's water goes), and rank
// 0 follows the water from tile to tile over those edges alone.
//
// - Pits: rank 0 names every edge cell's basin (the pit or outlet its water
//   reaches) and sends each rank the basins of its exits; every rank labels
//   its cells, exchanges the labels of its halo and collects, from its cells
//   in pit basins, the lowest link to each neighbouring basin (flow.hpp's
//   links, under the same total order). Each rank settles the lakes whose
//   basins lie inside its tile, off its edge (basin_join.hpp: their links
//   are all its own, so a component of them leaves by its lowest link), and
//   sends rank 0 only the rest: the links between its components and its
//   spanning forest reduced to their ends. Rank 0 joins them into the whole
//   grid's tree (the same as solve_basin_graph's) and sends back the key
//   basins' levels and ways out, and the path from each edge basin's pass
//   down to its pit cut into one piece per tile it crosses. Every rank
//   orients its own lakes from those, fills them and reverses its paths.
// - Drainage area: every tile counts the cells upstream of each of its cells
//   (whole numbers: exact in any order); rank 0 passes each exit's count on
//   to the edge cell it drains into, and on down the tiles, and every rank
//   counts again with those inflows.
// - Incision, and χ: each cell's new height needs its receiver's first. A
//   rank solves the trees rooted in its tile, then, round after round, the
//   trees whose exits' receivers a neighbour has solved (their edge values
//   come with a halo exchange), until every tree is solved: as many rounds as
//   the most times a river crosses between tiles, plus one.
//
// Diffusion runs across the tiles (diffusion.hpp's tiled solver). Every step
// is collective: every rank calls it with the same dt.
#pragma once

#include "flow.hpp"
#include "stream_power.hpp"

#include <orogen/solvers/diffusion.hpp>
#include <orogen/solvers/threshold_slopes.hpp>
#include <orogen/tiles.hpp>

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace orogen::landscape {

/// Whether these settings run tiled: "" if they do, else why not (for NodeDescriptor::untiled_because).
std::string untiled_because(const Settings& settings);

class TiledModel {
public:
    /// `heights` and `uplift` (m/yr, or empty) hold this rank's tile
    /// (owned().width × owned().height, row-major). Collective (with every
    /// side closed the ranks agree on the lowest cell, the outlet).
    TiledModel(Tiling& tiles, double cell, std::vector<double> heights, std::vector<double> uplift,
               const Settings& settings);

    /// Uplift varying in time (Model::set_uplift_history); its rate(k) gives
    /// this rank's tile and is called collectively (every rank at the same step).
    void set_uplift_history(UpliftHistory history);

    /// One step of `dt` years. Returns the pits found on the whole grid. Collective.
    std::int64_t step(double dt);
    /// Model::run on the tiles: the same steps. Collective.
    void run(double years, double dt, const std::function<void(std::int64_t, std::int64_t)>& on_step = {});
    /// Route and accumulate over the current heights without eroding (for the output layers). Collective.
    void route_only();

    const std::vector<double>& heights() const { return h_; }
    /// Rock uplift this tile's cells received so far (m), as Model::uplifted().
    const std::vector<double>& uplifted() const { return uplifted_; }
    std::vector<double>& heights() { return h_; }
    /// Whether local cell `l` (row-major in the tile) is an outlet.
    bool is_outlet(std::size_t l) const { return outlet_[l] != 0; }
    /// Drainage area of each cell of the tile (m²), after a step or route_only().
    const std::vector<double>& area() const { return area_; }
    /// D8 code of each cell's receiver (kDx/kDy), −1 for an outlet.
    int direction(std::size_t l) const { return dir_[l]; }
    /// With orographic rain, the rain (m/yr) on each cell of the tile in the last step, as Model::rain().
    std::vector<double> rain() const;
    /// χ (m) of every cell of the tile for reference area a0 (m²), as Model::chi. Collective.
    std::vector<double> chi(double a0 = 1.0);
    /// Pits found on the whole grid by the last routing.
    std::int64_t pits() const { return pits_; }
    /// The most rounds a solve down the rivers needed in the last step (1: no river crossed a tile edge).
    int rounds() const { return rounds_; }
    /// Seconds so far in the collectives that join the tiles (halo exchanges, the
    /// gathers to rank 0 and its answers, its solves and the waits for the other ranks included).
    double seconds_joining() const { return joining_s_; }
    /// Local index of the first non-finite height, or −1.
    std::int64_t first_non_finite() const;
    /// Whole-grid index of local cell `l`.
    std::int64_t global(std::size_t l) const;

private:
    struct Hop {  // where an edge cell's local tree ends
        std::int64_t tree;  // the tree's root cell (whole-grid index): its pit or outlet, or its exit
        std::int64_t next;  // an exit's receiver (in the next tile); −1 if `tree` is a pit or outlet
    };
    void route(double* h);
    void directions();
    void build_trees();
    Hop hop(std::size_t l) const;
    std::string edge_hops() const;
    void resolve_pits(double* h);
    // resolve_pits' five steps (tiled.cpp), over the state they pass on (ResolveState, defined there).
    struct ResolveState;
    void label_basins(ResolveState& st);
    std::vector<Link> links_between_basins();
    void settle_tile_lakes(ResolveState& st, std::vector<Link> links);
    void join_on_rank0(ResolveState& st);
    void apply_joined(ResolveState& st, double* h);
    void accumulate();
    void update_rain();  // orographic rain over the current heights (collective), and each cell's weight
    /// Banks (banks.hpp) after an incision from heights `before`: two halo exchanges (three with
    /// banks.wide(), four with banks.wider()), the same bits as Model.
    void erode_banks(const std::vector<double>& before);
    void relay_across(BankRelay& relay, std::size_t gn);  // fills the halo of what the banks pass on
    /// Floodplains (floodplain.hpp): a halo exchange for the receivers' heights, every tile's rivers that
    /// plane a floor gathered on every rank (in index order), each tile stamping and lowering its own cells.
    void plane_floodplains();
    /// Solve `v` down the rivers: f(l, v_receiver) sets v[l] for every cell but the roots, receivers first.
    void propagate(std::vector<double>& v, const std::function<void(std::size_t, double)>& f);
    bool outlet_at(std::int64_t g) const;
    /// Runs `f` (a collective), adding its time to joining_s_.
    template <typename F>
    auto joined(F&& f) {
        const auto t0 = std::chrono::steady_clock::now();
        struct Add {
            double& to;
            std::chrono::steady_clock::time_point t0;
            ~Add() { to += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); }
        } add{joining_s_, t0};
        return f();
    }
    std::int64_t receiver_global(std::size_t l) const;  // −1 for a root
    std::int64_t owned_neighbour(std::size_t l, int k) const;  // local index, −1 outside the tile
    std::size_t grown_index(std::size_t l) const;
    std::int64_t local_of(std::int64_t g) const;  // local index of whole-grid cell g, −1 outside the tile

    Tiling& tiles_;
    TileRect own_, grown_;
    int W_, H_;
    double cell_;
    Settings settings_;
    std::vector<double> rock_slopes_, rock_k_;  // the rock each cell shows this step (rock_at), or empty
    RockMemo rock_memo_;  // the bed and slice each cell showed (rock_at)
    solvers::threshold::Scratch slope_scratch_;  // the landslide limit's working grids, kept between steps
    std::vector<double> bed_offset_;  // each cell's Beds::offset (the dip's and the folds' part), once
    std::int64_t sink_ = -1;  // every side closed: the outlet (whole-grid index)
    std::vector<double> h_, uplift_, uplifted_;
    UpliftHistory history_;
    std::size_t history_k_ = std::size_t(-1);  // the interval whose rate is in history_rate_
    std::vector<double> history_rate_;
    double time_ = 0.0;  // years since the run began
    std::vector<std::uint8_t> outlet_;
    std::vector<std::int8_t> dir_;  // D8 code of the receiver, −1 for a root
    std::vector<std::uint8_t> donors_;  // bit k: owned neighbour k sends its water here
    std::vector<std::int32_t> trees_;  // local roots (pits, outlets, exits), local index order
    std::vector<std::int32_t> tree_of_;  // each cell's tree (index into trees_)
    std::vector<std::int64_t> tree_start_;  // each tree's first position in stack_ (+ end)
    std::vector<std::int32_t> stack_;  // the trees, each receiver before its donors
    std::vector<std::int32_t> edge_;  // the tile's edge cells, local indices
    std::vector<double> grown_h_, grown_v_, grown_done_, grown_label_;  // over ghosted() (halo 1)
    std::vector<std::int64_t> label_;  // resolve_pits: each cell's basin (its pit or outlet)
    std::vector<double> count_, area_;  // cells upstream (with itself), m²
    std::vector<double> rain_weight_;  // orographic rain over the background rain, by cell
    climate::RainTransfer rain_transfer_;  // the rain's transfer function, the same every step
    // Banks: the heights before the incision (own), and over ghosted() the area, direction, lowering,
    // heights and pushes the two passes read, each cell's direction as a code, outlets, scratch.
    std::vector<double> bank_before_, bank_area_, bank_dir_, bank_e_, bank_h_, bank_right_, bank_left_, bank_scratch_;
    std::vector<std::int8_t> bank_code_;
    std::vector<std::uint8_t> bank_outlet_;
    std::optional<BankAreaFactor> bank_factor_;  // 1 − e^(−A/A_b), built at the first step
    BankRelay bank_relay_;  // what a bank down to its floor passes on (banks.wide()), the halo's exchanged
    BankRelay bank_relay2_;  // what the second cells out pass on (banks.wider())
    std::vector<double> bank_relay_out_;  // bank_relay_.out as doubles, for the exchange
    // Floodplains: the heights over ghosted(), the rivers that plane a floor (the tile's, then every
    // tile's), and each cell's nearest river and its height.
    std::vector<double> floodplain_grown_, floodplain_nearest_, floodplain_floor_;
    std::vector<FloodplainSource> floodplain_mine_, floodplain_all_;
    std::vector<double> pow_table_;
    std::unique_ptr<solvers::diffusion::Solver> diffusion_;
    std::int64_t pits_ = 0;
    int rounds_ = 0;
    double joining_s_ = 0.0;
};

}  // namespace orogen::landscape
