// sph.hpp — hydraulic erosion by smoothed particle hydrodynamics: the
// thesis's favourite eroder (§3.5.3, §4.1), with a real fluid underneath.
//
// Fluid: 3-D weakly compressible SPH (Monaghan 1994/2005):
//   density   ρ_i = Σ_j m W(r_ij)                       (cubic spline, support h = 4 r)
//   pressure  p_i = B((ρ_i/ρ0)^7 − 1), B = ρ0 c0²/7, clamped at 0 (Tait; free surfaces)
//   momentum  a_i = −Σ_j m (p_i/ρ_i² + p_j/ρ_j² + Π_ij) ∇W_ij + g
//             Π_ij = −α c0 (h/2) μ_ij / ρ̄_ij, μ_ij = v_ij·r_ij/(r_ij² + 0.01 (h/2)²) when v_ij·r_ij < 0
//             (Monaghan's artificial viscosity: stable, damps only approaching pairs)
//   time      symplectic Euler, sub-steps Δt ≤ cfl·h/(c0 + v_max) and ≤ 0.25·√(h/a_max)
// Why WCSPH and not DFSPH: erosion runs are thin, fast films on steep
// terrain with a free surface nearly everywhere; WCSPH's one neighbour pass
// for density and one for forces per sub-step, with no pressure solve, is the
// cheapest per particle-step there, and its compressibility is set by c0
// (δρ/ρ ≈ (v/c0)²). DFSPH pays off with deep, still water and large steps.
//
// Neighbours: a cell list with cells of size h (27 cells per particle). Every
// sub-step the particle arrays are sorted by cell (a stable radix sort of keys
// linear in the particles' bounding box of cells, x fastest, padded by one
// cell), so the 3 cells of each of the 9 rows around a cell are one contiguous
// run. Density and forces go a cell at a time: the runs are copied once into
// contiguous arrays and every particle of the cell sums over all of them in
// 16 independent float lanes (out-of-support candidates masked), which GCC
// vectorizes; the lanes are added in a fixed order at the end. The order of
// every sum follows from the state alone: the same bits for any thread count
// and any of the vector clones (AVX-512, AVX2, baseline x86-64).
//
// Terrain contact (the thesis, done correctly): the particle's motion in a
// sub-step is a ray; Möller–Trumbore tests it against the two triangles of
// the tile beneath its start and its end; at a hit the particle stops there
// and its velocity loses its inward normal component (restitution e) along
// the normal interpolated bilinearly from the tile's four vertex normals;
// finally any particle below the triangulated surface (a tile edge the ray
// missed, a deposit that grew under it) is lifted onto it. No particle ever
// ends a sub-step below the surface. Near the ground (and, with a closed
// boundary, the map's edges) a particle's density and pressure push include
// the fluid's rest lattice continued behind them (WallTable), so a particle
// at rest against a wall, an edge or a corner reads the interior's density.
//
// Erosion (conserving): a particle in contact (within its radius of the
// surface) has a capacity C = Kc · V · |v_t| · max(sin α, min_slope) (V its
// volume, v_t its speed along the slope, α the slope); below capacity it
// dissolves acidity·Δt·(C − s) of terrain, above it deposits deposit·Δt·(s − C);
// when it evaporates (lifespan) or reaches the sea it leaves all it carries.
// Terrain changes go to the 4 vertices of the tile under the particle with
// bilinear weights, in double, each vertex's additions in particle order
// (chunks of particles in parallel, rows two chunks share queued), so
// terrain + carried + removed-over-an-open-edge is constant to round-off.
#pragma once

#include <orogen/grid.hpp>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <vector>

namespace orogen {
struct ParticleFrame;
}

namespace orogen::sph {

enum class Boundary {
    closed,  ///< the map's edges are walls, with the terrain's boundary term (the rest lattice behind them)
    open,  ///< particles that cross an edge leave (with their sediment) and are counted
};

struct Settings {
    double radius = 0.5;  ///< particle radius r, m; spacing 2r, kernel support h = 4r
    double rest_density = 1000.0;  ///< ρ0, kg/m³
    double sound_speed = 20.0;  ///< c0, m/s; δρ/ρ ≈ (v/c0)²
    double viscosity = 0.05;  ///< Monaghan's α (dimensionless)
    double gravity = 9.81;  ///< m/s²
    double cfl = 0.4;  ///< Courant number of the sub-steps
    double friction = 1.0;  ///< 1/s: tangential velocity decay while touching the terrain
    double restitution = 0.0;  ///< fraction of the inward normal velocity reflected at contact
    Boundary boundary = Boundary::closed;
    double sea_level = -std::numeric_limits<double>::infinity();  ///< m: particles below it are removed

    // Erosion (capacity Kc in s/m: m³ of terrain per m³ of water per m/s of speed along the slope).
    bool erode = true;
    double capacity = 0.5;
    double deposit = 1.0;  ///< 1/s: rate of dropping the excess over capacity
    double min_slope = 0.05;  ///< lower bound of sin α in the capacity
    /// m: no vertex is lowered by more than this in one sub-step (keeps single
    /// particles from drilling holes; material is conserved either way).
    double max_dig = 0.05;

    /// Particles per chunk of the parallel terrain exchange (see settle() in integrator.cpp); any value
    /// gives the same bits, a serial loop's included. Not a node parameter: for the tests that check
    /// exactly that.
    std::size_t settle_chunk = 16384;
    /// The largest share of the particles that may have changed cell since the last sort for the sort to
    /// merge them into the others' order (merge_movers in neighbourhood.cpp) instead of radix-sorting
    /// all; either gives the same permutation. Not a node parameter: for the tests (0: always the radix sort).
    double merge_movers_up_to = 0.125;
};

struct Vec3 {
    float x = 0, y = 0, z = 0;
};

/// Counters of the particle budget: spawned = alive + evaporated + left + sea.
struct Counts {
    std::int64_t spawned = 0;
    std::int64_t evaporated = 0;  ///< reached their lifespan
    std::int64_t left = 0;  ///< crossed an open edge
    std::int64_t sea = 0;  ///< fell below the sea level
    std::int64_t refused = 0;  ///< not spawned: the particle budget was full
};

class Simulation {
public:
    /// `terrain`: heights in m on width × height vertices (copied, kept in
    /// double). `capacity`: the most particles alive at once (memory is
    /// reserved for them up front).
    Simulation(ConstGridView terrain, const Settings& settings, std::size_t capacity);
    ~Simulation();
    Simulation(const Simulation&) = delete;
    Simulation& operator=(const Simulation&) = delete;

    /// Bytes the simulation needs per particle of capacity (for bad-input messages).
    static std::size_t bytes_per_particle();

    /// Add one particle (position in m: x east, y up, z south); false if the
    /// budget is full. `lifespan` in steps (0 = forever), `acidity` in 1/s.
    bool add(Vec3 position, Vec3 velocity, float acidity, std::int32_t lifespan);

    /// Rain: `count` particles at random xz (counter-based hashes of `seed`,
    /// `step`) `height` m above the terrain.
    void rain(std::int64_t count, double height, std::uint64_t seed, std::int64_t step, float acidity,
              std::int32_t lifespan);
    /// A spring: `count` particles spread over a disc of radius 2·spacing around
    /// (x, z) in m, one spacing above the terrain.
    void spring(double x, double z, std::int64_t count, std::uint64_t seed, std::int64_t step, std::int64_t which,
                float acidity, std::int32_t lifespan);

    /// Advance by dt seconds in CFL-limited sub-steps. Throws orogen::Error
    /// naming `step` and the particle count if anything goes non-finite.
    void advance(double dt, std::int64_t step);
    /// One sub-step of exactly dt (no CFL split; for benchmarks and tests).
    void substep(double dt);
    /// The CFL-limited sub-step length for the current state, s.
    double stable_dt() const;
    /// End of a node step: age every particle by one step; evaporate those at
    /// their lifespan (their sediment goes to the terrain); accumulate `water`.
    void end_step();

    // State.
    std::size_t size() const;  ///< particles alive
    std::size_t capacity() const;
    const Counts& counts() const;
    std::int64_t substeps() const;
    /// Sorts by cell that merged the particles which changed cell into the others' order (the rest radix-sorted all).
    std::int64_t merged_sorts() const;
    double time() const;
    /// The terrain's triangulated surface height at (x, z), m.
    double surface(double x, double z) const;
    /// Lowest (particle height − surface height) over all particles, m (+inf if none).
    double min_clearance() const;
    /// Terrain volume Σ h·cell² (double), carried sediment Σ s, and the
    /// sediment that left over an open edge, all m³.
    double terrain_volume() const;
    double carried_sediment() const;
    double removed_sediment() const;

    std::span<const Vec3> positions() const;
    std::span<const Vec3> velocities() const;
    std::span<const float> densities() const;
    std::span<const float> pressures() const;
    std::span<const float> sediments() const;

    /// Write the eroded terrain (float) into `out` (the input's size).
    void write_terrain(GridView out) const;
    /// Mean water depth per vertex over the steps so far, m.
    void write_water(GridView out) const;
    /// Append the current particles as a frame (position, velocity, density,
    /// pressure, sediment, acidity, age).
    void record(ParticleFrame& frame) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace orogen::sph
