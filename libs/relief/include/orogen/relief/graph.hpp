// graph.hpp — the thesis's graph-based RMP regions (section 3.3.1): the faces
// of an arrangement of cutting lines inside the grid rectangle.
//
// The thesis searched the line graph for minimal cycles by exhaustive DFS
// (5937 s for 5 cuts). Here the faces come from walking half-edges: at each
// vertex the walk takes the next edge clockwise from the one it arrived by,
// which traces every face once, in O(E log E). Intersections closer than a
// small epsilon are merged into one vertex, so three lines through a point,
// parallel and nearly parallel lines all give a proper planar graph.
//
// Coordinates: sample coordinates, the rectangle [0, width] × [0, height].
#pragma once

#include <orogen/relief/convex_fill.hpp>

#include <orogen/grid.hpp>

#include <cstdint>
#include <span>
#include <vector>

namespace orogen::relief {

/// An infinite line through `point` along `direction`.
struct Line {
    Point2 point;
    Point2 direction;
};

/// `count` random lines, each through a uniform point of the rectangle at a
/// uniform angle (so every one crosses it); a pure function of (seed, i).
std::vector<Line> random_cuts(int count, double width, double height, std::uint64_t seed);

/// The planar graph of the cuts and the 4 border lines, and its bounded faces.
struct Arrangement {
    std::vector<Point2> vertices;
    std::vector<std::pair<int, int>> edges;  ///< undirected, each once
    /// Bounded faces: vertex indices in counter-clockwise order (positive
    /// shoelace area in (x, y)); each face is a convex simple polygon.
    std::vector<std::vector<int>> faces;
    /// Faces sharing an edge, ascending.
    std::vector<std::vector<int>> adjacency;

    std::vector<Point2> polygon(int face) const;
};

/// Build the arrangement of `cuts` clipped to [0, width] × [0, height].
/// Lines that miss the rectangle or only touch it are ignored.
Arrangement build_arrangement(std::span<const Line> cuts, double width, double height);

/// W. R. Franklin's PNPOLY point-in-polygon test (crossing number).
bool pnpoly(std::span<const Point2> polygon, Point2 p);

/// The face holding p (the first by index if p is on an edge), or -1.
int face_containing(const Arrangement& arrangement, Point2 p);

/// Faces in depth-first (preorder) order from `start` over the adjacency graph,
/// neighbours taken in ascending index order, as the thesis's DFS.
std::vector<int> depth_first_order(const Arrangement& arrangement, int start);

}  // namespace orogen::relief
