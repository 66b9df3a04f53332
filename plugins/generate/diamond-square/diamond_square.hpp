// Diamond-Square (Fournier et al. 1982; thesis section 3.1, Listing 3.1).
//
// Corners get random heights; then diamond steps (the centre of each square
// from its 4 corners) and square steps (each edge midpoint from its 2 edge
// ends and the 2 neighbouring centres) alternate, the random offset shrinking
// by `roughness` each level (the thesis halves it: roughness 0.5).
//
// Any grid size works, not only 2^k+1: each axis is subdivided at interval
// midpoints ((a+b)/2, integer) until every interval has length 1, so
// uneven intervals simply finish a level or two earlier. For 2^k+1 this is
// exactly the classic algorithm.
#pragma once

#include <orogen/grid.hpp>

#include <cstdint>

namespace orogen::diamond_square {

struct Params {
    double amplitude = 1.0;  ///< metres: corners and first-level offsets are uniform in ±amplitude
    double roughness = 0.5;  ///< offset scale multiplier per level, in (0, 1]; higher = rougher
};

/// Overwrite every sample of `out` with a Diamond-Square surface (metres).
/// Each vertex's random offset is a hash of (seed, x, y): deterministic for
/// any thread count.
void generate(GridView out, const Params& params, std::uint64_t seed);

/// The part of generate()'s surface on a `width` × `height` grid that `out`
/// covers, `out` holding the vertices from column x0 and row y0 on: the same
/// bits generate() gives there (a tile of a tiled run). It computes each
/// level only where a vertex of the tile depends on it: the tile grown by one
/// interval of that level on each side beyond the intervals holding it (a
/// square step reads the neighbouring diamond centres, which read their
/// corners), so the work is about the tile's plus a border of a few vertices
/// a level, and the memory about the tile's.
void generate_tile(GridView out, int x0, int y0, int width, int height, const Params& params, std::uint64_t seed);

}  // namespace orogen::diamond_square
