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
// the highest surface at or below h whose slope between neighbouring
// vertices nowhere exceeds S_c = tan(angle), d the length of the shortest
// path over the 8-neighbour grid (cell and cell·√2 steps). What is above h'
// has slid away; nothing is raised, so the limit makes no pit (a lowered
// vertex lies S_c·d above the neighbour that lowered it).
//
// Computed as a greatest fixed point, h' = min(h, min over neighbours of
// h'(nb) + S_c·d), by sweeps of that update in the four directions (down,
// up, right, left: each reads the row or column it just finished, so a
// sweep's vertices on one row or column are independent and run in
// parallel) until a round changes nothing (usually two to four rounds). The
// update is monotone, even in floating point (rounding is monotone), so any
// order of sweeps, any thread count and any split into tiles reach the very
// same bits: the greatest fixed point below h.
#pragma once

#include <orogen/tiles.hpp>

#include <cstdint>

namespace orogen::threshold {

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

/// Lowers `heights` (width × height, row-major, row 0 north, metres, vertices
/// `cell` metres apart) in place to the greatest surface below them whose
/// slope down to a neighbour nowhere exceeds `slopes`.
/// `fixed` (optional, one flag per vertex): vertices that keep their height
/// (base level), though they still limit their neighbours. `removed` (optional,
/// one per vertex): each vertex's lowering is added to it (m).
Result limit_slopes(double* heights, int width, int height, double cell, const Slopes& slopes,
                    const std::uint8_t* fixed = nullptr, double* removed = nullptr);

/// The same on this rank's tile of a tiled run (the tiles' halo must be ≥ 1):
/// `heights`, `fixed` and `removed` are the tile's (owned().width ×
/// owned().height). Collective; every vertex gets the bits the whole grid's
/// limit gives it. The Result is the whole grid's (reduced over the ranks).
Result limit_slopes(Tiling& tiles, double* heights, double cell, const Slopes& slopes,
                    const std::uint8_t* fixed = nullptr, double* removed = nullptr);

}  // namespace orogen::threshold
