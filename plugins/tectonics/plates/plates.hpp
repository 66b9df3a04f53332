// plates.hpp — the thesis's tectonic plate simulation (section 3.6) and what
// its chapter 5 left as future work.
//
// Rigid convex plates move in a 2-D Box2D world, kept in motion and inside
// the area by four kinematic beams. Where two plates touch along a two-point
// contact, the boundary is classified by the plates' relative velocity at
// the contact: approaching → convergent (a jagged mountain range, or a
// trench and a chain of arc volcanoes where a denser plate dives under a
// lighter one), separating → divergent (a rift valley with fault-block
// flanks and a ridge), sliding past → transform (height unchanged). The
// relief is accumulated per event and composed, saturating, at the end
// (profiles.hpp). A plate that has taken more
// than `rift_threshold` of collision impulse splits along a line through its
// stress point, and the two parts move apart.
//
// The simulation frame: the plate area is [0, size.x] × [0, size.y]
// simulation units ("u"), size = 36 u on the heightmap's longer side (the
// thesis's 36 × 36 plate), x east and y south like the heightmap; one unit is
// samples_per_unit() samples. The beams' rest positions leave a free margin
// of 2 u around the area (the thesis's 40 × 40 world).
//
// Deterministic: Box2D steps single-threaded, events are applied in the order
// Box2D reports them, every random number comes from orogen::random keyed by
// (seed, purpose, index). Box2D headers stay in plates.cpp.
#pragma once

#include "polygon.hpp"

#include <orogen/grid.hpp>
#include <orogen/tiles.hpp>
#include <orogen/values.hpp>

#include <array>
#include <functional>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace orogen::plates {

/// How the four beams move.
enum class Drive {
    still,  ///< beams stay put: the plates keep their initial velocities (scripted scenarios)
    converge,  ///< opposite beams push inward together, the two axes half a period apart: squeezes the plates
    rotate,  ///< beams convey their surfaces round the box (friction) and squeeze gently: plates circulate
    shear,  ///< north beam conveys east, south beam west: plates slide past each other
    thesis,  ///< the thesis's beams: all moving in phase, so the box shakes the plates back and forth
};
inline constexpr std::array<std::string_view, 5> drive_names = {"still", "converge", "rotate", "shear", "thesis"};
std::optional<Drive> parse_drive(std::string_view name);

/// How a convergent contact between plates of similar density raises its range.
enum class RangeStyle {
    peaks,  ///< a crest of peaks along the contact, saturating where contacts repeat (profiles.hpp)
    cells,  ///< the thesis: the Voronoi cells the contact crosses, a fresh diagram per contact, summed
};
inline constexpr std::array<std::string_view, 2> range_style_names = {"peaks", "cells"};
std::optional<RangeStyle> parse_range_style(std::string_view name);

inline constexpr double area_units = 36.0;  ///< u, the plate area's longer side
inline constexpr double margin_units = 2.0;  ///< u, free space between the area and the beams at rest
inline constexpr int max_plate_vertices = 8;  ///< b2_maxPolygonVertices

/// Size of the plate area in simulation units for a width × height grid.
Point2 area_size(int width, int height);
/// Heightmap samples per simulation unit.
double samples_per_unit(int width, int height);
/// The most plates a width × height grid can hold: each plate must cover at
/// least 16 × 16 samples (smaller ones cannot carry a range), at most 256.
int max_plates(int width, int height);

/// A plate to start from, in simulation units.
struct PlateSpec {
    Polygon polygon;  ///< convex, counter-clockwise in (x east, y south), ≤ 8 vertices
    Point2 velocity;  ///< u/s
    double angular_velocity = 0.0;  ///< rad/s
    double density = 1.0;  ///< relative; the denser plate of a convergent pair subducts
};

/// Plate densities: oceanic crust is denser than continental.
inline constexpr double oceanic_density = 3.0;
inline constexpr double continental_density = 2.7;

/// Split the area (size from area_size) into `count` convex plates by random
/// straight cuts: each cut goes through a random point of the largest plate
/// at a random angle; a cut that would give a part more than 8 vertices, a
/// part under a quarter of the plate, or a sliver edge is drawn again. A
/// fraction `oceanic_fraction` of the plates is oceanic. Every plate starts
/// with a random velocity up to `speed` u/s. Throws orogen::Error if a plate
/// cannot be cut after many tries (count far above max_plates).
std::vector<PlateSpec> random_plates(Point2 size, int count, double oceanic_fraction, double speed, std::uint64_t seed);

struct Params {
    int steps = 1000;
    double dt = 0.1;  ///< s per step (the thesis stepped 1.0; see docs/tectonics.md)
    int velocity_iterations = 10;
    int position_iterations = 8;
    double restitution = 0.5;
    double friction = 0.6;
    Drive drive = Drive::converge;
    double speed = 1.0;  ///< u/s, beam speed (the thesis's 1)
    double stroke = 1.0;  ///< u, how far a beam moves inward from rest (≤ margin_units)
    /// u/s: below this relative speed at a contact the plates are resting on
    /// each other and the contact makes no boundary event.
    double min_speed = 0.05;

    // Relief, per event (profiles.hpp). Widths scale with the RMP's Voronoi cell size sqrt(area / cones).
    int cones = 100;  ///< Voronoi sites over the grid (cells style: per range); sets every width
    RangeStyle ranges = RangeStyle::peaks;
    double height = 80.0;  ///< m raised per convergent collision
    double jitter = 0.5;  ///< per-peak / per-cell height variation (thesis 4.2)
    double rift_depth = 20.0;  ///< m
    double ridge_height = 10.0;  ///< m
    double trench_depth = 25.0;  ///< m
    double arc_height = 35.0;  ///< m
    /// Contacts' worth of relief a place can take at most: repeated contacts
    /// saturate toward saturation × the per-contact amount (not for ranges=cells).
    double saturation = 5.0;
    double subduction_contrast = 0.1;  ///< density difference above which the denser plate subducts

    /// Accumulated plate–plate impulse (N·s, sim units) that splits a plate; 0 = never. Neither part of a
    /// rift may be smaller than half the mean start plate (or a fifth of the plate).
    double rift_threshold = 20000.0;
    double rift_speed = 0.5;  ///< u/s, how fast the two parts of a rifted plate move apart
    int max_plates = 256;  ///< rifting stops at this many plates

    int record_every = 10;  ///< record plate polygons every this many steps (and the first and last)
};

/// Where the simulation writes. `terrain` is required; `uplift` (m, added
/// to), `boundary` (kind of the last event drawn over a sample, 0 none) and
/// `plate` (id of the plate covering the sample at the end, -1 none) are
/// skipped when their data is null. All the same size.
struct Layers {
    GridView terrain;
    GridView uplift;
    GridView boundary;
    GridView plate;
};

struct Stats {
    std::int64_t events[4] = {0, 0, 0, 0};  ///< by BoundaryKind (index 0: resting contacts skipped)
    std::int64_t subductions = 0;  ///< convergent events shaped as trench and arc
    std::int64_t rifts = 0;  ///< plates split during the run
    double box2d_seconds = 0.0;  ///< wall time inside b2World::Step
    double relief_seconds = 0.0;  ///< wall time raising ranges, rifts, trenches
};

/// One boundary's relief, in the order the simulation made them (what
/// draw_tile() replays).
struct ReliefStamp {
    enum class Kind : std::uint8_t { range, subduction, rift, cells };
    Kind kind = Kind::range;
    Point2 a, b;  ///< samples, clipped to the grid
    Point2 toward_light;  ///< subduction: from the dense plate toward the light one
    std::uint64_t seed = 0;  ///< cells: the RMP range's seed
    std::int64_t step = 0;  ///< the simulation step whose contact made it (time-lapses replay up to a step)
};

/// What draws a finished simulation into any rectangle of the grid without
/// running Box2D again: a tiled run's rank 0 simulates, the others receive
/// this (encode/decode) and draw their tiles from it.
struct Replay {
    int width = 0, height = 0;  ///< the whole grid, samples
    double cell = 1.0;  ///< m
    std::vector<ReliefStamp> stamps;
    std::vector<CollisionEvent> boundaries;  ///< every event (the boundary layer), metres
    std::vector<Polygon> final_polygons;  ///< samples
    std::vector<int> final_ids;
};
std::string encode(const Replay& replay);
/// Throws orogen::Error if `bytes` is not what encode() wrote.
Replay decode_replay(std::string_view bytes);

struct Result {
    PlateHistory history;  ///< metres, heightmap coordinates (sample × cell)
    Stats stats;
    std::vector<PlateSpec> final_plates;  ///< simulation units, world polygons at the end
    std::vector<int> final_ids;
    Replay replay;  ///< recorded on every run
};

/// Run the simulation from `plates` (simulation units, see area_size).
/// Throws orogen::Error naming the step if Box2D produces a non-finite
/// position, orogen::BadInput for unusable parameters or plates.
/// `on_step(step)` is called after every step (progress, cancellation).
Result simulate(std::span<const PlateSpec> plates, const Params& params, std::uint64_t seed, const Layers& layers,
                const std::function<void(std::int64_t)>& on_step = {});

/// Called with the terrain as it would stand if the run ended after `step`:
/// the input terrain plus the relief of every boundary so far (the relief is
/// composed once at the end of a run, so this is a copy with it applied).
using SnapshotFn = std::function<void(std::int64_t step, ConstGridView terrain)>;
/// simulate(), calling `on_snapshot` after every `snapshot_every`-th step
/// (before the last step's; the caller has the final terrain itself).
Result simulate(std::span<const PlateSpec> plates, const Params& params, std::uint64_t seed, const Layers& layers,
                const std::function<void(std::int64_t)>& on_step, std::int64_t snapshot_every,
                const SnapshotFn& on_snapshot);

/// The simulation alone, for a width × height grid of `cell` metres: Box2D,
/// rifting and the history, no grid touched (result.replay says what to
/// draw). simulate() over the whole grid is this followed by draw_tile() over it.
Result simulate_events(std::span<const PlateSpec> plates, const Params& params, std::uint64_t seed, int width,
                       int height, double cell, const std::function<void(std::int64_t)>& on_step = {});

/// Draws `replay` into the rectangle `tile` of its grid: `layers` hold
/// exactly the tile's samples (terrain required; uplift, boundary, plate
/// optional as in simulate()). Every sample gets the bits simulate() gives it
/// over the whole grid. `params` and `seed` are the simulation's.
/// `on_snapshot` (with `snapshot_every` > 0) is called with the tile's terrain
/// as simulate()'s on_snapshot gets it over the whole grid, at the same steps.
void draw_tile(const Replay& replay, const Params& params, std::uint64_t seed, const Layers& layers, TileRect tile,
               std::int64_t snapshot_every = 0, const SnapshotFn& on_snapshot = {});

/// Draw segment a–b (sample coordinates) into `layer` with `value`, `radius`
/// samples thick on each side (Bresenham walk, clipped to the grid).
void draw_segment(GridView layer, Point2 a, Point2 b, float value, int radius);
/// Fill every sample inside the convex polygon (sample coordinates) with `value`.
void fill_polygon(GridView layer, std::span<const Point2> polygon, float value);
/// The same two for a layer that holds the rectangle `at` of the grid (a, b and the polygon in the grid's
/// sample coordinates, clipped to `at`).
void draw_segment(GridView layer, TileRect at, Point2 a, Point2 b, float value, int radius);
void fill_polygon(GridView layer, TileRect at, std::span<const Point2> polygon, float value);

}  // namespace orogen::plates
