// pipe.hpp — the virtual-pipe hydraulic erosion model of Mei, Decaudin & Hu
// (2007, "Fast Hydraulic Erosion Simulation and Visualization on GPU"), made
// stable at any requested time step.
//
// State per cell: terrain b, water depth d, suspended sediment s (all m) and
// the outflow flux through the four virtual pipes to the neighbours (m³/s).
// One sub-step of length Δt:
//   1. rain: d1 = d + Δt·rain·mask;
//   2. flux: f ← max(0, f + Δt·g·A·Δh/l) per pipe (Δh the water-surface drop
//      to the neighbour, A the pipe cross-section, l the cell size), then all
//      four scaled by K = min(1, d1·l²/(Σf·Δt)) so no cell gives more water
//      than it holds (never negative);
//   3. water: d2 = d1 + Δt·(Σ inflow − Σ outflow)/l²;
//   4. velocity from the flux through the cell over the mean depth;
//   5. capacity C = Kc · max(sin α, min_slope) · min(|v|, √(g·d), c) · min(d/d_e, 1)
//      (α the local tilt from central differences; the speed capped at the
//      wave speed √(g·d) and the depth ramp d/d_e, after Št'ava et al. 2008,
//      keep thin films of rain from scouring like rivers);
//      erode (1 − e^(−Ks·Δt))·(C − s) where s < C — at most half the drop to
//      the lowest axis neighbour (no pits) — and deposit (1 − e^(−Kd·Δt))·(s − C)
//      where s > C — at most half the rise to the highest one (no mounds);
//      creep: b += κ·∇²b, κ = creep·Δt/l² ≤ 0.2 (damps one-cell ripples);
//   6. sediment moves semi-Lagrangian (bilinear back-trace, clamped to one
//      cell: water reaches only the 4 neighbours in a sub-step); with closed
//      walls the total is restored by a global fix-up factor, so terrain +
//      sediment is conserved;
//   7. evaporation: d ← d2 · e^(−Ke·Δt).
// Stability: the thesis abandoned this model because it blew up at usable
// time steps. Here the requested step is split into sub-steps with
//     Δt_sub ≤ cfl · l / (v_max + c),  c = √(g · max(d_max, A/l)),
// (v_max the largest carrying speed min(|v|, √(g·d)), the `speed` layer)
// (c bounds the speed of the model's gravity waves: √(g·A/l) is the pipe
// model's own wave speed, √(g·d) the shallow-water one); the flux limiter K
// keeps depths non-negative, and the semi-Lagrangian transport and the
// exponential rates are stable for any Δt. (|v| larger than c only occurs in
// films that drain within one sub-step, where K already bounds the
// displacement to about one cell; counting it in full would shrink the
// sub-step without bound.)
//
// Each chunk of rows runs the three passes in one sweep with a lag of one row
// (edge rows in clean-up passes); every row is the same pure function of the
// sub-step's inputs whoever computes it, so the result is the same for any
// thread count; every reduction is summed per row, then over rows in order.
#pragma once

#include <orogen/grid.hpp>
#include <orogen/tiles.hpp>

#include <cstdint>
#include <memory>
#include <vector>

namespace orogen::pipe {

enum class Boundary {
    closed,  ///< walls: no water or sediment leaves the grid
    open,  ///< water flows off the edges as if onto dry ground at the edge's height
};

struct Settings {
    double rain = 0.001;  ///< m/s of water on every cell (times the mask, if any)
    double evaporation = 0.01;  ///< 1/s: fraction of water evaporating per second (exponential)
    double capacity = 1.0;  ///< Kc, s: sediment capacity per unit tilt and speed (m per m/s)
    double dissolve = 0.5;  ///< Ks, 1/s: rate of taking up the capacity deficit
    double deposit = 1.0;  ///< Kd, 1/s: rate of dropping the capacity excess
    double gravity = 9.81;  ///< m/s²
    double pipe_area = 1.0;  ///< A, m²: cross-section of each virtual pipe
    double min_slope = 0.05;  ///< lower bound of sin α in the capacity, so flat water still carries
    /// m: water shallower than this carries in proportion to its depth (0 = Mei's
    /// original capacity, independent of depth).
    double erosion_depth = 0.05;
    /// m²/s: creep, a linear diffusion of the terrain that damps grid-scale
    /// ripples (0 = none, Mei's original). Limited to κ = creep·dt/l² ≤ 0.2 per sub-step.
    double creep = 0.0;
    double cfl = 0.5;  ///< Courant number of the sub-steps (≤ 0.7 for the pipe model)
    Boundary boundary = Boundary::closed;
};

/// The simulation state; the caller owns the memory (e.g. heightmap layers),
/// so a later run can continue from it.
struct State {
    GridView height;  ///< terrain b, m
    GridView water;  ///< water depth d, m
    GridView sediment;  ///< suspended sediment s, m of terrain
    GridView flux_west, flux_east, flux_north, flux_south;  ///< outflow through each pipe, m³/s
    GridView
        speed;  ///< carrying speed min(|v|, √(g·d)) of the last sub-step, m/s (also read at start: the first sub-step's CFL)
};

/// Vertices of the neighbouring tiles one sub-step reads, in a tiled run:
/// the sediment transport of a cell reads s1 of its 3 × 3 block (1), s1 of a
/// cell reads its axis neighbours' fluxes (2), a flux reads its axis
/// neighbour's water surface (3). The halo is refilled before every sub-step,
/// since each sub-step's length depends on the whole grid's speeds anyway.
constexpr int kTileHalo = 3;

/// CPU seconds this process has used (all its threads).
double process_cpu_seconds();

class Solver {
public:
    /// `rain_mask` (optional) holds one non-negative factor per cell.
    ///
    /// With `tiling` (a tiled run, orogen/tiles.hpp), the state grids and the
    /// mask cover this rank's ghosted tile (tiling->ghosted(), kTileHalo wide); the
    /// owned part holds the state, the mask must be valid on the halo too
    /// (the caller exchanges it once). Before each sub-step the solver refills
    /// the halo of every field a sub-step reads across a tile edge (terrain,
    /// water, sediment, the 4 fluxes); the edge of the grown tile then acts
    /// as a wall whose wrong effect reaches kTileHalo cells in, i.e. halo
    /// cells only. The reductions (the CFL maxima, the sediment totals of the
    /// closed-wall fix-up, the finiteness check) run over the owned cells and
    /// are combined across ranks in the single process's order, so every
    /// owned cell gets the single process's bits. Collective: every rank
    /// constructs, advances and finishes alike.
    Solver(const State& state, const Settings& settings, const float* rain_mask = nullptr, Tiling* tiling = nullptr);
    ~Solver();
    Solver(const Solver&) = delete;
    Solver& operator=(const Solver&) = delete;

    /// Advance by `dt` seconds in CFL-limited sub-steps. `step` (for
    /// messages) is the caller's step number. Throws orogen::Error if a
    /// non-finite value appears, naming the step and sub-step.
    void advance(double dt, std::int64_t step);
    /// Write everything back into the state (sediment fix-up, speed, terrain).
    /// Call once at the end; advance() may not be called afterwards.
    void finish();
    /// The terrain as it stands after the last advance() (the solver keeps it
    /// in its own buffer until finish()); water is State::water itself.
    ConstGridView current_height() const;

    std::int64_t substeps() const { return substeps_; }
    /// Sums of the last sub-step, in double (m³ = m·cell²... here in m summed over cells).
    /// total_water() is kept in a single process only (NaN in a tiled run).
    double total_water() const;
    double total_sediment() const;
    /// A tiled run's seconds so far in halo exchanges and in the cross-rank reductions (wall clock).
    double seconds_exchanging() const;
    double seconds_reducing() const;
    /// The same, in CPU seconds of this process (an MPI wait polls, so it counts here too).
    double cpu_seconds_exchanging() const;
    double cpu_seconds_reducing() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    std::int64_t substeps_ = 0;
};

}  // namespace orogen::pipe
