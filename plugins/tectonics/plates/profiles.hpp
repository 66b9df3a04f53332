// profiles.hpp — the relief plate boundaries leave: rugged collision ranges,
// trenches with a chain of arc volcanoes, rift valleys with stepped
// fault-block flanks and a rough axial ridge.
//
// Every contact event is first *accumulated* into a per-feature activity
// field (metres, as if each contact added its full amount), and the relief is
// composed once at the end (apply):
//
//   relief = sat(range)·peaks(x, y)                       collision ranges
//          − sat(trench) + volcanoes(sat(arc) at each vent) + ⅕·sat(arc)  subduction
//          − sat(rift)·terrace(flank) + min(sat(ridge)·rough(x, y), that)  rifts
//
// with sat(a) = cap·(1 − exp(−a/cap)), cap = saturation × the per-contact
// amount: a boundary touched once gets (almost) one contact's relief, a
// boundary touched 200 times gets at most `saturation` contacts' worth, so no
// region becomes a smear of summed profiles. The texture functions (peaks,
// vents, terrace wobble) are fixed functions of position for a seed, so
// repeated contacts at one place sharpen the same peaks instead of averaging
// many random ones into a blur.
//
// Widths are multiples of the RMP's Voronoi cell size c = sqrt(area/cones)
// (samples). Plain C++ over GridView, testable alone. Each add_* costs the
// area of the band it touches (∝ segment length × width); apply costs one
// pass over the grid.
#pragma once

#include <orogen/grid.hpp>
#include <orogen/tiles.hpp>

#include <cstdint>
#include <vector>

namespace orogen::plates {

struct ReliefShape {
    double cell = 16.0;  ///< samples: the Voronoi cell size c; every width below scales with it
    double range_height = 60.0;  ///< m per convergent contact (before the peak texture)
    double jitter = 0.5;  ///< per-peak / per-volcano height variation: × (1 + jitter·u), u ∈ [−1, 1)
    double trench_depth = 40.0;  ///< m per subduction contact
    double arc_height = 30.0;  ///< m per subduction contact (volcano height before jitter)
    double rift_depth = 20.0;  ///< m per divergent contact
    double ridge_height = 10.0;  ///< m per divergent contact, the axial ridge
    double saturation = 5.0;  ///< contacts' worth: no place gets more than saturation × a contact's amount
};

/// Widths and offsets across a boundary, in samples, for a cell size c.
struct ReliefWidths {
    double range_half;  ///< 0.8 c: a range's envelope reaches this far either side of the contact
    double peak_spacing;  ///< 0.4 c: spacing of the range's peaks (a second octave at a third of it)
    double trench_offset;  ///< 0.12 c on the dense side: the trench's deepest line
    double trench_outer;  ///< 0.3 c: the trench's gentle outer (oceanic) wall
    double trench_inner;  ///< 0.12 c: its steep inner wall, toward the arc
    double arc_offset;  ///< 0.6 c inland on the light plate: the volcanic line
    double arc_band;  ///< 0.2 c: half-width of the band whose vents erupt
    double vent_spacing;  ///< 0.4 c: lattice of possible vents
    double vent_radius;  ///< 0.3 c: a volcano's base radius (± 20 %)
    double rift_floor;  ///< 0.15 c: half-width of the flat rift floor
    double rift_half;  ///< 0.6 c: the flanks reach the original ground here
    double ridge_half;  ///< max(0.08 c, 1.5): the axial ridge's half-width
    double end_reach;  ///< 0.3 c: relief fades past a segment's ends over this distance
};
ReliefWidths relief_widths(double cell);

/// cap·(1 − exp(−a/cap)): ≈ a for a ≪ cap, never above cap. cap ≤ 0 gives 0.
double saturate(double accumulated, double cap);

/// Stairs: d (≥ 0) → stepped d with treads `step` apart, each tread tilted
/// slightly (rotated fault blocks, 20 % of a step over its width) and a steep
/// scarp (the last quarter of each step) to the next. Monotone
/// non-decreasing and continuous; terrace(0) = 0, terrace(k·step) = k·step.
/// A rift's flank position 0..1 (rim to floor) terraced into 3 blocks.
double terrace(double depth, double step);

/// Ridged fractal noise in [0, 1] (4 octaves, the first `spacing` samples):
/// sharp crests and valleys that carve a range's peaks into ridges.
double ridged_field(double x, double y, double spacing, std::uint64_t seed);

/// The range texture: the maximum over a jittered lattice of cones
/// (spacing `spacing` samples, one site per lattice cell, radius 0.95
/// spacing, concave flanks), each cone's height 1 + jitter·u from the seed.
/// Values in [0, 1 + jitter]: distinct peaks joined by sharp ridges and
/// saddles — the RMP's per-cell heights (thesis 4.2) drawn as peaks.
double peak_field(double x, double y, double spacing, double jitter, std::uint64_t seed);

class BoundaryRelief {
public:
    BoundaryRelief(int width, int height, const ReliefShape& shape, std::uint64_t seed);
    /// The relief of a width × height grid, held only over `window` (global
    /// sample coordinates, inside the grid): what a rank of a tiled run keeps.
    /// Every sample of the window gets the bits the whole grid's relief has
    /// there, except within vent_margin() of the window's edge (a volcano
    /// there may stand on a vent outside the window): apply() only inside that.
    BoundaryRelief(int width, int height, TileRect window, const ReliefShape& shape, std::uint64_t seed);
    /// Samples a window must reach past the samples it composes (two vent lattice cells and rounding).
    int vent_margin() const;

    /// A convergent contact between plates of similar density, along a–b
    /// (sample coordinates): a range straddling the contact.
    void add_range(Point2 a, Point2 b);
    /// A dense plate diving under a light one along a–b; `toward_light`
    /// points (any length) from the dense plate to the light one: the trench
    /// lies on the dense side, the volcanic line inland on the light side.
    void add_subduction(Point2 a, Point2 b, Point2 toward_light);
    /// Plates pulling apart along a–b: a rift valley with an axial ridge.
    void add_rift(Point2 a, Point2 b);

    /// Compose the accumulated relief and add it to `terrain` (and to
    /// `uplift` if non-null). Same size as the constructor's. Deterministic
    /// whatever the thread count.
    void apply(GridView terrain, GridView* uplift = nullptr) const;
    /// The same for the samples of rectangle `at` (global coordinates; `terrain` and `uplift` hold exactly
    /// them), which must lie inside the window shrunk by vent_margin() where the window is not the grid's edge.
    void apply(GridView terrain, TileRect at, GridView* uplift = nullptr) const;

    /// The composed relief alone at every sample (m), for tests and figures.
    std::vector<float> relief() const;

    const ReliefWidths& widths() const { return widths_; }
    int width() const { return width_; }  ///< the whole grid
    int height() const { return height_; }

private:
    struct Vent {
        double x = 0, y = 0, radius = 1, height = 0;  // samples, m (0: dormant)
    };
    struct Vents {
        double spacing = 1;
        int nx = 0, ny = 0;
        std::vector<Vent> vents;
        const Vent& at(int i, int j) const { return vents[std::size_t(j + 1) * std::size_t(nx) + std::size_t(i + 1)]; }
        Vent& at(int i, int j) { return vents[std::size_t(j + 1) * std::size_t(nx) + std::size_t(i + 1)]; }
    };
    Vents vents() const;
    float relief_at(int x, int y, const Vents& vents) const;
    std::vector<float>& field(std::vector<float>& f);

    int width_, height_;  // the whole grid
    TileRect window_;  // the samples held (the activity fields' extent)
    ReliefShape shape_;
    ReliefWidths widths_;
    std::uint64_t seed_;
    // Activity fields (m, unsaturated), allocated on first use.
    std::vector<float> range_, trench_, arc_, rift_, ridge_;
    std::vector<float> flank_;  // largest flank position over rift contacts: 1 floor, 0 rim
};

}  // namespace orogen::plates
