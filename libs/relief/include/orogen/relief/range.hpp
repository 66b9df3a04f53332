// range.hpp — the advanced RMP of the thesis's section 3.6.2: a mountain range
// between two points.
//
// The Voronoi cells crossed on the way from a to b are raised together. The
// thesis walked the colour labels along a Bresenham line; here the cells are
// the union of (1) the cells of the Bresenham line's vertices, as the thesis
// did, and (2) every cell the continuous segment passes through (an exact
// walk from cell to cell across the bisector it leaves by), so the raised
// band contains the whole segment and every vertex of its raster line.
//
// Used by generate:range (iterated, a fresh diagram each time) and by the
// plate simulation (one call per collision). Link orogen_core_rmp.
#pragma once

#include <orogen/grid.hpp>

#include <cstdint>

namespace orogen::relief {

struct RangeParams {
    int cones = 100;  // Voronoi sites over the whole grid
    double height = 1.0;  // metres raised per call
    double jitter = 0.0;  // 0: every crossed cell by `height`; >0: each cell by height*(1 + jitter*u), u in [-1,1)
};

/// Raise every Voronoi cell crossed by the Bresenham line from a to b (sample coordinates,
/// clamped to the grid). Sites come from `seed`. Cost is proportional to the area of the raised
/// cells, not to the grid. If `uplift` is non-null the same amounts are added to it.
/// Returns the number of cells raised.
int raise_range(GridView terrain, Point2 a, Point2 b, const RangeParams& params, std::uint64_t seed,
                GridView* uplift = nullptr);

/// Where a window lies in the whole grid: the grid's size, and the window's first sample (global coordinates).
struct GridWindow {
    int width = 0, height = 0;  ///< the whole grid, samples
    int x0 = 0, y0 = 0;  ///< the window's first sample
};

/// The same range of a `grid.width` × `grid.height` grid, added only to the samples of the window at
/// (grid.x0, grid.y0) (`terrain` and `uplift` hold exactly them): a rank's tile in a tiled run gets the bits
/// the whole grid gets there. Returns the number of cells raised (over the whole grid).
int raise_range(GridView terrain, GridWindow grid, Point2 a, Point2 b, const RangeParams& params, std::uint64_t seed,
                GridView* uplift = nullptr);

}  // namespace orogen::relief
