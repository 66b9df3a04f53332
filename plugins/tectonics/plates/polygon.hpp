// polygon.hpp — convex polygons for the plate simulation: area, centroid,
// convexity, and the split of a convex polygon by a straight cut.
//
// The thesis (Listing 3.2) sorted each vertex to one side of a cut by the
// angle atan((v.y - c.y)/(v.x - c.x)) - rayAngle, which loses the quadrant:
// vertices left and right of the ray centre get the same angle. Here the side
// is the sign of the cross product d × (v − p), exact for every direction.
// Units are whatever the caller uses (the simulation uses its own units).
#pragma once

#include <orogen/grid.hpp>

#include <optional>
#include <span>
#include <utility>
#include <vector>

namespace orogen::plates {

using Polygon = std::vector<Point2>;

/// Signed area (positive for counter-clockwise in a right-handed x, y frame).
double signed_area(std::span<const Point2> polygon);
/// Area centroid of a non-degenerate polygon.
Point2 centroid(std::span<const Point2> polygon);
/// True if the polygon has ≥ 3 vertices, positive area, and every turn is a
/// left turn (cross product > `tolerance` × scale²): strictly convex, CCW.
bool is_convex_ccw(std::span<const Point2> polygon, double tolerance = 1e-9);
/// True if `p` lies inside or on the convex CCW polygon.
bool contains(std::span<const Point2> polygon, Point2 p);

/// Which side of the directed line (p, d) the point v lies on: > 0 left, < 0
/// right. The fixed Listing 3.2.
inline double side_of(Point2 p, Point2 d, Point2 v) { return d.x * (v.y - p.y) - d.y * (v.x - p.x); }

/// The two points where the line through `p` with direction `d` enters and
/// leaves the convex polygon (what the thesis got from two opposite ray
/// casts), or nothing if the line misses it.
std::optional<std::pair<Point2, Point2>> line_entry_exit(std::span<const Point2> polygon, Point2 p, Point2 d);

/// Split a convex CCW polygon by the line through `p` with direction `d`.
/// Returns {left part, right part}, both convex CCW, or nothing if the line
/// misses the polygon, passes within `min_gap` of a vertex (which would leave
/// a sliver edge or a degenerate part), or a part would be empty.
std::optional<std::pair<Polygon, Polygon>> split_convex(std::span<const Point2> polygon, Point2 p, Point2 d,
                                                        double min_gap);

}  // namespace orogen::plates
