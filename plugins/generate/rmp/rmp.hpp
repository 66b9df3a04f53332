// rmp.hpp — Repeated Magnification and Probing (Kamal and Uddin; the
// thesis's section 3.3): each iteration cuts the map into random regions and
// raises the region(s) under each peak. Many regions per iteration give a
// steep, narrow mountain; few give a wide one; height grows with iterations.
//
// Three ways to find the regions, all in sample coordinates:
//   voronoi — exact Voronoi cells on the CPU, only the raised ones (voronoi.hpp);
//   cones   — the thesis's GPU trick, drawn through OSMesa (cones.hpp, its own library);
//   graph   — faces of an arrangement of random lines (graph.hpp).
// `voronoi` and `cones` draw the same sites for the same seed and iteration.
#pragma once

#include <orogen/relief/convex_fill.hpp>

#include <orogen/grid.hpp>

#include <cstdint>
#include <functional>
#include <vector>

namespace orogen::rmp {

struct RmpParams {
    std::vector<Point2> peaks{{0.5, 0.5}};  ///< grid-relative, 0..1 across the grid
    int iterations = 100;
    int cones = 100;  ///< Voronoi sites per iteration (voronoi, cones)
    double height = 5.0;  ///< metres raised in the first iteration
    double decay = 1.0;  ///< the raise is multiplied by this each iteration (thesis: 1 − 1/iterations)
    double jitter = 0.0;  ///< 0: every region by the same amount; >0: each by height·(1 + jitter·u), u in [-1, 1)
    int cuts = 5;  ///< random lines per iteration (graph)
    int regions = 2;  ///< faces raised per peak per iteration, first in DFS order (graph)
};

/// Called after each iteration with its index (for progress and cancelling).
using IterationHook = std::function<void(int iteration)>;

/// Throws orogen::BadInput naming the parameter if `params` cannot run.
void validate(const RmpParams& params);

/// A grid-relative point in sample coordinates.
Point2 to_samples(Point2 relative, int width, int height);

/// The grid vertex nearest a grid-relative peak, in sample coordinates. Every
/// method raises the region holding this vertex, so they agree on the peak.
Point2 peak_vertex(Point2 relative, int width, int height);

/// The seed of iteration `k`'s diagram (sites, cuts, jitter).
std::uint64_t iteration_seed(std::uint64_t seed, int iteration);

/// Metres raised in iteration `k` before jitter: height · decay^k.
double iteration_height(const RmpParams& params, int iteration);

/// Exact Voronoi RMP. Cost per iteration: generating the sites plus the area of the raised cells.
void rmp_voronoi(GridView terrain, const RmpParams& params, std::uint64_t seed, const IterationHook& hook = {});
/// The same mountain of a width × height grid, added only to `window` (a rank's tile in a tiled run):
/// each of its samples gets the bits the whole grid gets there (every iteration draws the whole
/// grid's diagram, which costs its sites, and adds only the window's part of the raised cells).
void rmp_voronoi(relief::Window window, int width, int height, const RmpParams& params, std::uint64_t seed,
                 const IterationHook& hook = {});

/// Graph-based RMP: faces of `cuts` random lines; from each peak's face the
/// first `regions` faces of a depth-first search are raised. Throws
/// orogen::BadInput if an iteration makes fewer faces than `regions`.
void rmp_graph(GridView terrain, const RmpParams& params, std::uint64_t seed, const IterationHook& hook = {});
/// The same, added only to `window` of a width × height grid (as rmp_voronoi's window form).
void rmp_graph(relief::Window window, int width, int height, const RmpParams& params, std::uint64_t seed,
               const IterationHook& hook = {});

}  // namespace orogen::rmp
