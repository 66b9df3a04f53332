// rock.hpp — rock of varying strength under a landscape: tilted beds.
//
// Real ranges are cut into rock whose strength changes from bed to bed:
// sandstone over shale, limestone over marl, gneiss over schist. Strong beds
// stand steeper and erode slower; weak ones fail at gentler angles and give
// way to the rivers (Sklar & Dietrich 2001; Schmidt & Montgomery 1995 for
// the hillslope angle; Forte et al. 2016 for the landscapes of alternating
// beds). This is what spreads a range's slopes over many angles rather than
// one, and cuts benches, hogbacks and strike valleys where the beds surface.
//
// The beds are `thickness` metres thick, dipping at `dip` towards azimuth
// `toward`; each has a strength s in (0, 1), one of 256 classes drawn from
// the seed and its index (counter-based: the same beds on any thread count
// and any tiling). Planar beds crop out in bands that run straight across a
// whole range, a tell no real range shows: real strata are folded. With a
// fold amplitude the bed surfaces rise and fall by up to that many metres
// in folds `fold_wavelength` across and three times as long along their
// axes, which run along the strike (a smooth random field from the seed):
// the outcrops bend, close around the folds' noses and end. Real beds are
// not all one thickness either: with a thickness spread each bed's base is
// moved by up to ±spread/2 of a thickness, so beds run from (1 − spread) to
// (1 + spread) times `thickness` and the outcrops are spaced unevenly. And
// real strata are broken by faults: with a fault spacing, faults of random
// strike, one per `fault_spacing` square on average and 1–3 spacings long,
// offset the beds by up to `fault_throw` metres. The throw is greatest at a
// fault's middle and dies away towards its tips and away from it (over half
// its length), so the outcrops step across each fault and run on beyond it.
// The rock a cell shows is the one at its rock height ζ = h − uplift received
// (the height that rock had at the start: the beds rise with the uplift, and
// erosion digs into them). Its landslide angle is angle + spread·(2s − 1) and
// its erodibility K·contrast^(1/2 − s): the weakest bed erodes √contrast
// times faster than the average, the strongest √contrast times slower.
// Nor is a bed one rock from end to end: its facies change along it (a
// sandstone grades into siltstone, a reef limestone into marl away from the
// reef). With a facies length each bed's strength drifts along it, blended
// smoothly between values drawn for the bed at the corners of a lattice
// that many metres across: a cliff band fades out along its outcrop into a
// bench and a weak bed stiffens, as real ones do, rather than each bed
// holding one strength across the whole map.
// Within a bed the rock is not one either: it is cut by joints into blocks
// of sounder and weaker rock (Selby 1980 on rock mass strength). With a
// block spread each cell's block, a cell deep, stands steeper than its bed's
// landslide slope by a share of it up to block_spread (tan, from the seed,
// the cell and the slice of rock height): threshold hillslopes break into
// spurs and chutes instead of standing as planes, and as erosion cuts down
// through the blocks the pattern changes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace orogen::landscape {

struct Beds {
    double thickness = 0.0;  ///< m (0: one rock everywhere)
    double dip_slope = 0.0;  ///< tan of the dip angle
    double dip_east = 0.0;  ///< unit vector, grid x (east), the beds dip towards
    double dip_south = 1.0;  ///< ... and grid y (south)
    double angle = 0.0;  ///< mean landslide angle, radians (0: no landslides)
    double angle_spread = 0.0;  ///< radians: ± from the weakest bed to the strongest
    double erodibility_contrast = 1.0;  ///< K of the weakest bed / K of the strongest (≥ 1)
    double fold_amplitude = 0.0;  ///< m: the bed surfaces rise and fall by up to this (0: planar beds)
    double fold_wavelength = 5000.0;  ///< m, across the fold axes (3 times as long along them)
    double thickness_spread = 0.0;  ///< beds are (1 ± spread) × thickness thick, in [0, 0.95] (0: all alike)
    double fault_spacing = 0.0;  ///< m: one fault per this square on average (0: no faults)
    double fault_throw = 0.0;  ///< m: the largest vertical offset of the beds across a fault
    /// Each cell's block of rock (a cell deep) stands up to this share steeper (tan) than its bed's landslide
    /// slope, from the seed (0: every block as its bed).
    double block_spread = 0.0;
    double facies_length = 0.0;  ///< m: a bed's strength drifts along it over about this (0: one per bed)
    double facies_share = 0.5;  ///< how much of a bed's strength the drift sets, in [0, 1]
    std::uint64_t seed = 0;

    /// A bed's strength is one of this many classes, s = (k + 1/2)/kStrengths.
    static constexpr int kStrengths = 256;

    bool layered() const { return thickness > 0.0; }
    bool folded() const { return layered() && fold_amplitude > 0.0; }
    bool faulted() const { return layered() && fault_spacing > 0.0 && fault_throw > 0.0; }
    bool facies() const { return layered() && facies_length > 0.0 && facies_share > 0.0; }
    /// The height (m) the folds lift the bed surfaces at (x, y) (m from the grid's north-west corner,
    /// x east, y south), in [-fold_amplitude, fold_amplitude]; 0 when not folded.
    double fold(double x, double y) const;
    /// The height (m) the faults lift the beds at (x, y) by (it jumps across each fault's trace); 0 when
    /// not faulted.
    double fault(double x, double y) const;
    /// The height (m) above the bed surface through the origin of the rock at rock height `zeta` (m)
    /// at (x, y) is zeta + offset(x, y): the dip's, the folds' and the faults' part, the same at every step.
    double offset(double x, double y) const;
    /// The index of the bed whose base is the highest at or below height q (m) above the bed surface
    /// through the origin: floor(q / thickness) when the beds are all alike.
    std::int64_t bed_at(double q) const;
    /// The height (m) of bed k's base above the bed surface through the origin: k·thickness, moved by up
    /// to ±thickness_spread/2 of a thickness.
    double bed_base(std::int64_t k) const;
    /// The strength class k of the bed at rock height `zeta` (m) at (x, y) (m from the grid's north-west
    /// corner, x east, y south), from the seed and the bed's index (and, with facies, where along the bed
    /// (x, y) lies); kStrengths/2 when unlayered.
    int bed_class(double zeta, double x, double y) const;
    /// Its strength, (k + 1/2)/kStrengths in (0, 1).
    double strength(double zeta, double x, double y) const;
    /// tan of the landslide angle of rock of strength s.
    double landslide_slope(double s) const;
    /// K's factor for rock of strength s.
    double erodibility_factor(double s) const;
};

/// A block of a grid's cells: `count` cells, `width` to a row, the first at (x0, y0) of the grid, cells
/// `cell` metres apart (the whole grid in one process; a tile's own cells in a tiled run).
struct CellBlock {
    std::size_t count = 0;
    int width = 0, x0 = 0, y0 = 0;
    double cell = 1.0;
};

/// Beds::offset of each cell of `block`; left empty when the rock is not layered. Computed once per run.
void bed_offsets(const Beds& beds, const CellBlock& block, std::vector<double>& offsets);

/// What rock_at found in each cell last time: the bed, the cell-deep slice of rock height and the bed's
/// strength class there. A cell still in both shows the same rock, so its slope and factor are kept; one
/// in the same bed but a new slice keeps its class (its facies are drawn once per bed) and draws only its
/// joint block (a river cuts through a 150 m bed in many steps, through a 30 m slice in one or two). Kept
/// by the caller between calls on the same block, with the same `slopes` and `factors`.
struct RockMemo {
    std::vector<std::int64_t> key;
};

/// What rock_at reads of each cell of the block: its height, the uplift it received and its bed_offsets
/// (block.count values each).
struct RockInputs {
    const double* heights = nullptr;
    const double* uplifted = nullptr;
    const double* offsets = nullptr;
};

/// Each cell's landslide slope (tan) and erodibility factor in `block` (the joint blocks are a cell wide
/// and deep). `slopes` / `factors` are resized; either is left empty when it would be uniform. With a
/// `memo` (see RockMemo) the same values, sooner.
void rock_at(const Beds& beds, const CellBlock& block, const RockInputs& at, std::vector<double>& slopes,
             std::vector<double>& factors, RockMemo* memo = nullptr);

}  // namespace orogen::landscape
