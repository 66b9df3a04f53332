// terrain_mesh.hpp — the heightmap as a triangle mesh, and its splatted colour.
//
// Plain C++ over orogen::ConstGridView (no glTF/VTK headers), shared by the
// glTF and VTK exporters so the geometry can be tested and benchmarked alone.
//
// Layout, as the thesis's heightmap: width × height vertices, (width−1) ×
// (height−1) tiles of two counter-clockwise triangles each (seen from above).
// Coordinates are Y-up, right-handed, metres, as glTF requires:
//   X = x · cell (east),  Y = h · vertical_scale (up),  Z = y · cell (south),
// with the origin at sample (0, 0). Tile (x, y) with corners
//   a = (x, y)  b = (x+1, y)  c = (x, y+1)  d = (x+1, y+1)
// becomes triangles (a, c, b) and (b, c, d): both have normals pointing +Y.
//
// A big terrain is split into chunks (blocks of tiles that share their border
// vertices, so there are no cracks) to keep each mesh under 65 535 vertices
// and use 16-bit indices.
#pragma once

#include <orogen/grid.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace orogen::mesh {

/// Sample indices kept along an axis of `n` samples when keeping every
/// `step`-th vertex: 0, step, 2·step, ... and always n − 1 (so the mesh keeps
/// the terrain's full extent). `step` ≥ 1.
std::vector<int> kept_indices(int n, int step);

/// A block of tiles: kept columns [column_begin, column_end] and kept rows
/// [row_begin, row_end] (inclusive, indices into TerrainMesh::columns/rows).
struct MeshChunk {
    int column_begin = 0, column_end = 0;
    int row_begin = 0, row_end = 0;

    int vertex_columns() const { return column_end - column_begin + 1; }
    int vertex_rows() const { return row_end - row_begin + 1; }
    std::size_t vertex_count() const { return std::size_t(vertex_columns()) * std::size_t(vertex_rows()); }
    std::size_t triangle_count() const {
        return 2 * std::size_t(vertex_columns() - 1) * std::size_t(vertex_rows() - 1);
    }
    /// 16-bit indices suffice (glTF reserves 65535 as primitive restart).
    bool fits_16bit() const { return vertex_count() <= 65535; }
};

/// The most vertices a 16-bit-indexed chunk may hold (65535 is reserved).
inline constexpr std::size_t max_16bit_vertices = 65535;

/// How the heightmap becomes meshes.
struct TerrainMesh {
    ConstGridView heights;
    double vertical_scale = 1.0;  ///< multiplies heights (vertical exaggeration)
    std::vector<int> columns;  ///< kept sample x indices
    std::vector<int> rows;  ///< kept sample y indices
    std::vector<MeshChunk> chunks;

    std::size_t vertex_count() const;  ///< over all chunks (borders counted per chunk)
    std::size_t triangle_count() const;
};

/// Plan the mesh: keep every `decimate`-th vertex (≥ 1), split into
/// `chunks` × `chunks` blocks; `chunks` = 0 picks the fewest blocks per side
/// that keep every block at ≤ 65535 vertices (16-bit indices).
/// Needs a grid of at least 2 × 2 samples.
TerrainMesh plan_mesh(ConstGridView heights, int decimate, int chunks, double vertical_scale);

/// Y-up position of sample (x, y), metres. The exporters' accessor bounds
/// use this same function, so they match the written floats exactly.
inline std::array<float, 3> position(const TerrainMesh& mesh, int x, int y) {
    return {float(double(x) * mesh.heights.cell), float(double(mesh.heights.at(x, y)) * mesh.vertical_scale),
            float(double(y) * mesh.heights.cell)};
}

/// Unit normal (Y-up) of the surface Y = h·scale at sample (x, y): central
/// differences over the full-resolution grid, one-sided at the edges.
std::array<float, 3> surface_normal(ConstGridView heights, int x, int y, double vertical_scale);

/// Axis-aligned bounds of a chunk's positions, metres (exactly the floats written).
struct Bounds {
    std::array<float, 3> min{}, max{};
};
Bounds chunk_bounds(const TerrainMesh& mesh, const MeshChunk& chunk);

// Per-chunk vertex data, row-major over the chunk's kept rows and columns.
/// 3 floats per vertex: X, Y, Z in metres.
void chunk_positions(const TerrainMesh& mesh, const MeshChunk& chunk, std::span<float> out);
/// 3 floats per vertex: unit normal.
void chunk_normals(const TerrainMesh& mesh, const MeshChunk& chunk, std::span<float> out);
/// 2 values per vertex: u = x/(width−1), v = y/(height−1) across the whole
/// terrain (so one texture covers every chunk), as floats ...
void chunk_texcoords(const TerrainMesh& mesh, const MeshChunk& chunk, std::span<float> out);
/// ... or as unsigned 16-bit normalised (u · 65535, rounded).
void chunk_texcoords(const TerrainMesh& mesh, const MeshChunk& chunk, std::span<std::uint16_t> out);
/// 3 indices per triangle, two CCW triangles per tile, local to the chunk.
void chunk_indices(const MeshChunk& chunk, std::span<std::uint32_t> out);
void chunk_indices(const MeshChunk& chunk, std::span<std::uint16_t> out);

// ------------------------------------------------------------------ colour

/// How much of each material covers a point (the weights sum to 1).
struct SplatWeights {
    float sand = 0, grass = 0, rock = 0, snow = 0;
};

/// Where the materials go. The defaults are the thesis's (§3.7.1): four
/// height bands of width δ = (max − min)/4 — sand, grass, rock, snow — each
/// blended into from the one below over the first half of its band; then
/// slope: where the normal's y falls below 0.75, grass and snow turn to rock,
/// completely at 0.5 (a 0.25-wide blend band). The render:terrain shader
/// applies these same rules (its uniforms come from this struct).
struct SplatRules {
    /// Fraction of the height range (0 = lowest, 1 = highest) where grass,
    /// rock and snow start; increasing, in (0, 1). Sand starts at 0.
    std::array<float, 3> band_start{0.25f, 0.5f, 0.75f};
    /// A band blends in from the one below over this fraction of its own width.
    float blend_fraction = 0.5f;
    /// Normal y (1 flat, 0 vertical) below which rock starts to cover grass and
    /// snow, and at which it covers them completely; slope_full < slope_start.
    float slope_start = 0.75f, slope_full = 0.5f;
};

/// The splatting weights at a point of `height` (min/max: the terrain's range)
/// whose unit normal has y = `normal_y`.
SplatWeights splat_weights(float height, float min_height, float max_height, float normal_y,
                           const SplatRules& rules = {});
/// Throws orogen::BadInput saying what is wrong if `rules` are not ordered as SplatRules says.
void validate(const SplatRules& rules);

/// 8-bit sRGB colours of the four materials.
inline constexpr std::array<std::uint8_t, 3> sand_colour{194, 178, 128};
inline constexpr std::array<std::uint8_t, 3> grass_colour{86, 125, 58};
inline constexpr std::array<std::uint8_t, 3> rock_colour{125, 116, 107};
inline constexpr std::array<std::uint8_t, 3> snow_colour{242, 244, 247};

std::array<std::uint8_t, 3> splat_colour(const SplatWeights& w);

/// Bake the splatted colour into an RGBA8 texture of `texture_width` ×
/// `texture_height` pixels covering the whole terrain (pixel centres sample
/// the heights and slopes bilinearly; alpha 255). Slope uses the true
/// (unexaggerated) terrain.
std::vector<std::uint8_t> bake_splat_texture(ConstGridView heights, int texture_width, int texture_height);

}  // namespace orogen::mesh
