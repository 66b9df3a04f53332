// Heightmap ⇄ grayscale samples for PNG files (thesis Listing 3.6, fixed).
//
// The thesis scaled (h − min)/(max − min) by 256, so the highest point
// wrapped to black; here it is scaled by 255 (8-bit) or 65535 (16-bit) and
// rounded, so min → 0 and max → full white exactly.
#pragma once

#include <orogen/grid.hpp>

#include <cstdint>
#include <vector>

namespace orogen::formats::png {

struct Range {
    float low = 0.0f, high = 0.0f;
};

/// The minimum and maximum of `grid` (NaN samples ignored).
Range range_of(ConstGridView grid);

/// Min–max normalise to 0..2^bits−1 (bits 8 or 16). A flat grid maps to 0.
std::vector<std::uint16_t> quantise(ConstGridView grid, int bits, Range range);

/// Lambertian hillshade of the heights (metres, `cell` apart): the cosine
/// between each vertex's surface normal (central differences, one-sided at
/// the edges) and the direction to a light at `azimuth` degrees clockwise
/// from north and `elevation` degrees above the horizon, clamped at 0 and
/// scaled to 0..2^bits−1. A flat terrain reads sin(elevation) everywhere.
std::vector<std::uint16_t> hillshade(ConstGridView heights, int bits, double azimuth_degrees, double elevation_degrees,
                                     double vertical_scale = 1.0);

}  // namespace orogen::formats::png
