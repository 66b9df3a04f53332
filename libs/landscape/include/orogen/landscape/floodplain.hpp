// floodplain.hpp — the flat floors of large rivers' valleys.
//
// Real valleys widen downstream: 10 m above rivers draining 1 km² those of
// the 30 m reference DEMs are 100–130 m wide, above rivers draining 100 km²
// 300–400 m, their floors nearly flat for three to five cells to either side
// (`orogen analyze`'s valley width against drainage area, W ∝ A^0.2–0.3;
// docs/realism.md). A river that migrates across its valley planes the floor
// and its floods spread sediment over it; the banks (banks.hpp) cut only the
// cells next to each step's river, and each step's soil creep refills the
// cells beyond.
//
// Each step, every cell within the floodplain's half-width
//
//     W(A) = width · (A / area)^exponent   (m)
//
// of a river cell draining A ≥ area (one that drains somewhere, and, with a
// max_slope, no steeper than that to its receiver) is lowered,
// never raised, to that river plus the floor slope over the distance d:
// h ← min(h, h_river + slope · d). Of the rivers whose floodplain reaches a
// cell, its nearest one sets it (ties: the lower index), not the lowest: a
// cell inside a bend then never falls below the bend's own river, so the
// floor keeps the river's course rather than cutting it off. Outlets stay.
//
// In three parts, so that a tiled run gives the same bits: the rivers that
// plane a floor (floodplain_source, cell by cell), each river's reach stamped
// in index order (stamp_floodplains, over any window of the grid, by bands
// of rows on every thread) and the cells lowered (lower_to_floodplains). A river's floodplain reaches W/cell
// cells, up to ten at 300 km² with the default pipeline's numbers, more than
// a tile's halo of one: each tile sends its rivers (a few per cent of its
// cells) to the tiles their floodplains reach into, and each stamps its own
// window (TiledModel::plane_floodplains).
#pragma once

#include "flow.hpp"

#include <cstdint>
#include <span>
#include <vector>

namespace orogen::landscape {

struct Floodplain {
    double area = 0.0;  ///< m²: rivers draining more have floodplains (0: none)
    double width = 30.0;  ///< m: the half-width W at `area`
    double exponent = 0.5;  ///< W ∝ A^exponent
    double slope = 0.0;  ///< tan of the angle at which the floor rises from its river
    /// tan: only rivers no steeper than this (to their receiver) plane a floodplain (0: every river). Real
    /// floodplains lie along gentle reaches; a steep river in a gorge has none.
    double max_slope = 0.0;
    bool any() const { return area > 0.0; }
};

/// A river cell that planes a floodplain: its index in the whole grid, its height (m) before any cell is
/// lowered, and how far its floodplain reaches (cells, W/cell).
struct FloodplainSource {
    std::int64_t index;
    double height;
    double reach;
};

/// Whether a cell planes a floodplain: `dir` its D8 receiver's code (−1: none), `area` its drainage area (m²),
/// `h` and `h_receiver` its and its receiver's heights (m). If so, sets `reach` (cells).
bool floodplain_source(const Floodplain& fp, double cell, int dir, double area, double h, double h_receiver,
                       double& reach);

/// A rectangle of the grid (vertices): the window a tile stamps and lowers.
struct FloodplainWindow {
    int x0 = 0, y0 = 0, width = 0, height = 0;
};

/// For each cell of `window` (row-major in it), the distance (cells) to the nearest of `sources` (in
/// increasing index order of a `grid_width`-wide grid) whose floodplain reaches it, strictly nearer winning
/// (ties: the lower index), and that river's height: `nearest` (∞ where none reaches) and `floor`, resized.
void stamp_floodplains(std::span<const FloodplainSource> sources, int grid_width, FloodplainWindow window,
                       std::vector<double>& nearest, std::vector<double>& floor);

/// Lowers, never raises, each of the `n` cells of `heights` that a floodplain reaches (not a river, not an
/// outlet when `outlet` is given) to its river's height plus the floor's rise over the distance. Returns the
/// volume removed, m³.
double lower_to_floodplains(const Floodplain& fp, double cell, std::size_t n, const std::vector<double>& nearest,
                            const std::vector<double>& floor, const std::uint8_t* outlet, double* heights);

/// Lowers the `width` × `height` grid's `heights` (m, row-major) to the floodplains of its rivers (above),
/// the rivers and the cells that stay as `flow` gives them. `nearest` and `floor` are scratch (resized).
/// Returns the volume removed, m³.
double carve_floodplains(const Floodplain& fp, int width, int height, double cell, const D8Flow& flow, double* heights,
                         std::vector<double>& nearest, std::vector<double>& floor);

}  // namespace orogen::landscape
