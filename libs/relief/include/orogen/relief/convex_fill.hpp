// convex_fill.hpp — which grid vertices lie in a convex polygon, row by row.
// Shared by the graph method (faces of a line arrangement) and the exact
// Voronoi (cells, whose span ends it then settles with exact queries).
#pragma once

#include <orogen/grid.hpp>

#include <span>
#include <vector>

namespace orogen::relief {

/// Vertices x0..x1 (inclusive) of grid row y.
struct RowSpan {
    int y, x0, x1;
};

/// For a convex polygon (sample coordinates), the rows of a width × height
/// grid that hold vertices inside it or on its border (within 1e-7 samples),
/// each as one span. A degenerate polygon (a point or a segment) gives the
/// vertices on it.
void convex_row_spans(std::span<const Point2> polygon, int width, int height, std::vector<RowSpan>& out);

/// A rectangle of a grid: `view` holds exactly its samples, its first at (x0, y0) of the grid
/// (the whole grid in one process, a rank's tile in a tiled run).
struct Window {
    GridView view;
    int x0 = 0, y0 = 0;
};

/// Adds `amount` to the window's samples among `spans` (whole-grid rows and columns);
/// `also`, if given, has the window's size and gets the same additions.
void add_spans(Window w, std::span<const RowSpan> spans, float amount, GridView* also = nullptr);

}  // namespace orogen::relief
