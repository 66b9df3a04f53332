// threshold_slopes.hpp — hillslopes that stop at a threshold angle.
//
// In ranges that erode fast, hillslopes do not steepen without end: once a
// slope passes a threshold angle (30–40°, set by the rock's strength) it
// fails as landslides, and the rivers at its foot carry the debris away
// (Burbank et al. 1996, Nature 379:505; Montgomery & Brandon 2002, Earth
// Planet. Sci. Lett. 201:481). The slopes stand planar at the threshold,
// and the divides between them are sharp. This module gives that limit:
//
//     h'(x) = min over y of ( h(y) + S_c · d(x, y) ),
//
// the highest surface at or below h whose slope nowhere exceeds
// S_c = tan(angle), d the distance from x to y over the grid. What is above h'
// has slid away; nothing is raised, so the limit makes no pit (a lowered
// vertex lies S_c·d above the neighbour that lowered it).
//
// d is the Euclidean distance, not the 8-neighbour path's: with only the
// cell and cell·√2 steps every slope would face one of eight directions
// (octagonal cones; planar facets at 22.5° + k·45° that make a hillshade
// look cut from crystal, up to 8 % further than the true distance between
// them). So a vertex is also held by the points between a straight
// neighbour and the diagonal one beside it, at t = 1/4, 1/2, 3/4 of the way
// (edge_bound below): the semi-Lagrangian stencil of the eikonal equation
// |∇h'| = S_c (Tsitsiklis 1995, Sethian & Vladimirsky 2001), linear between
// the two neighbours, so a valley side at any azimuth stands within 2 % of
// S_c times its distance to the river (tests/libs/solvers). Every bound is
// a sum of the neighbours' heights with weights ≥ 0 and a constant, so it
// rises (or stays) when they rise, in floating point too.
//
// Computed as a greatest fixed point, h' = min(h, min over neighbours of
// the bounds they give), by Gauss–Seidel sweeps in the four orders of fast
// sweeping (Zhao 2005: down or up the rows, east- or westward along them;
// strips of columns side by side in parallel, each reading its neighbours'
// edge columns as they were when the sweep began). After the first sweep a
// sweep takes only the vertices next to one lowered since (the others
// already stand at or below their bound): fewer updates, the same fixed
// point. One round of four sweeps does nearly all the lowering; on one
// grid a work list then finishes it (a vertex lowered puts its neighbours
// on the list), where further rounds would look at every row to lower a
// few hundred vertices; a tiled run sweeps until a round changes nothing,
// exchanging its edges between rounds. The update is monotone, even in floating point (rounding is monotone), so any
// order of sweeps, any thread count and any split into tiles reach the very
// same bits: the greatest fixed point below h.
#pragma once

#include <orogen/tiles.hpp>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace orogen::solvers::threshold {

/// The lowest height (m) the points strictly between a straight neighbour at `axial` and the
/// diagonal neighbour beside it at `diagonal` let a vertex keep, the threshold rising `step` =
/// S_c·cell per cell: the least of (1 − t)·axial + t·diagonal + step·√(1 + t²) over t = 1/4, 1/2, 3/4.
inline double edge_interior(double axial, double diagonal, double step) {
    constexpr double kL1 = 1.0307764064044151, kL2 = 1.1180339887498949, kL3 = 1.25;  // √(1 + t²)
    return std::min(std::min(0.75 * axial + 0.25 * diagonal + step * kL1, 0.5 * axial + 0.5 * diagonal + step * kL2),
                    0.25 * axial + 0.75 * diagonal + step * kL3);
}

/// The whole edge, its ends (the two neighbours, t = 0 and 1) included.
inline double edge_bound(double axial, double diagonal, double step) {
    constexpr double kSqrt2 = 1.4142135623730951;
    return std::min(std::min(axial + step, diagonal + step * kSqrt2), edge_interior(axial, diagonal, step));
}

/// What a limit did.
struct Result {
    std::int64_t lowered = 0;  ///< vertices lowered
    double removed = 0.0;  ///< height removed, summed over the vertices (m; × cell² for m³)
    int rounds = 0;  ///< rounds of four sweeps, the last one changing nothing
};

/// The threshold slope S_c (m/m): one for every vertex, or one per vertex (rock of varying strength;
/// a vertex is limited by its own S_c: how far above its lower neighbours it may stand).
struct Slopes {
    double uniform = 0.0;  ///< > 0 unless per_vertex is given
    const double* per_vertex = nullptr;  ///< one per vertex (the tile's in a tiled run), each > 0
};

/// Working memory a limit may keep between calls (a model's steps): the grids it would otherwise
/// allocate afresh each call. At 4097² these are 0.3 GB a step, and faulting their pages in cost
/// more than the sweeps over them (docs/benchmarks.md). What it holds between calls means nothing.
struct Scratch {
    std::vector<double> before, heights, slopes;
    std::vector<std::int32_t> moved, strip_rows, list;
    std::vector<std::uint8_t> fixed, listed;
};

/// Lowers `heights` (width × height, row-major, row 0 north, metres, vertices
/// `cell` metres apart) in place to the greatest surface below them whose
/// slope down to a neighbour nowhere exceeds `slopes`.
/// `fixed` (optional, one flag per vertex): vertices that keep their height
/// (base level), though they still limit their neighbours. `removed` (optional,
/// one per vertex): each vertex's lowering is added to it (m). `scratch` (optional): working
/// memory kept by the caller; the result is the same bits with or without it.
Result limit_slopes(double* heights, int width, int height, double cell, const Slopes& slopes,
                    const std::uint8_t* fixed = nullptr, double* removed = nullptr, Scratch* scratch = nullptr);

/// The same on this rank's tile of a tiled run (the tiles' halo must be ≥ 1):
/// `heights`, `fixed` and `removed` are the tile's (owned().width ×
/// owned().height). Collective; every vertex gets the bits the whole grid's
/// limit gives it. The Result is the whole grid's (reduced over the ranks).
Result limit_slopes(Tiling& tiles, double* heights, double cell, const Slopes& slopes,
                    const std::uint8_t* fixed = nullptr, double* removed = nullptr, Scratch* scratch = nullptr);

}  // namespace orogen::solvers::threshold
