// maps.hpp — the texture maps game engines take beside a heightmap.
//
//   splat map  RGBA8, one material per channel — R sand, G grass, B rock,
//              A snow — from the same height and slope rules as every other
//              orogen colour (terrain_mesh.hpp: splat_weights). The four
//              bytes of a pixel always sum to exactly 255, as Unreal's and
//              Unity's terrain layer weights expect.
//   normal map RGB8 tangent-space normals of the surface (+X east, +Y north
//              for OpenGL, south for DirectX, +Z up), encoded n·127.5 + 127.5.
//
// Plain C++ over orogen::ConstGridView; the same pixel count as the heightmap
// (one texel per vertex).
#pragma once

#include <orogen/grid.hpp>

#include <cstdint>
#include <vector>

namespace orogen::maps {

/// RGBA8 weights, row-major, width × height texels, bytes summing to 255.
std::vector<std::uint8_t> splat_map(ConstGridView heights);

enum class Green { opengl, directx };

/// RGBA8 (alpha 255) tangent-space normals of the surface h·vertical_scale.
std::vector<std::uint8_t> normal_map(ConstGridView heights, double vertical_scale, Green green);

/// Weights in [0, 1] summing to 1, rounded to bytes summing to exactly
/// `total` (largest remainders get the leftover units; ties to the lower channel).
void round_to_total(const float weights[4], int total, std::uint8_t out[4]);

}  // namespace orogen::maps
