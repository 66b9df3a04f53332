// convex_fill.hpp — which grid vertices lie in a convex polygon, row by row.
// Shared by the graph method (faces of a line arrangement) and the exact
// Voronoi (cells, whose span ends it then settles with exact queries).
#pragma once

#include <orogen/grid.hpp>

#include <span>
#include <vector>

namespace orogen::rmp {

/// Vertices x0..x1 (inclusive) of grid row y.
struct RowSpan {
    int y, x0, x1;
};

/// For a convex polygon (sample coordinates), the rows of a width × height
/// grid that hold vertices inside it or on its border (within 1e-7 samples),
/// each as one span. A degenerate polygon (a point or a segment) gives the
/// vertices on it.
void convex_row_spans(std::span<const Point2> polygon, int width, int height, std::vector<RowSpan>& out);

}  // namespace orogen::rmp
