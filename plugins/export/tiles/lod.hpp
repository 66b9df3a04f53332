// lod.hpp — a heightmap as a chunked level-of-detail pyramid (Ulrich 2002,
// "Rendering massive terrains using chunked level of detail control"), the
// chunks written as glTF by export:tiles format=glb and listed in a 3D Tiles
// tileset (OGC 3D Tiles 1.1) that Cesium, Cesium for Unreal and Unity, and
// other streaming viewers read.
//
// Level 0 is the engine tiles of tiles.hpp at full resolution: tile_size
// samples a side, neighbours sharing their edge samples. Level k keeps the
// samples at multiples of 2^k (and always the grid's last row and column,
// as mesh::kept_indices does), and one of its chunks covers 2 × 2 chunks
// of level k − 1, so every chunk has at most tile_size × tile_size vertices.
// The top level is a single chunk.
//
// No cracks: neighbours of one level share their edge vertices and normals
// bit for bit (the normals are central differences over the level's own
// samples, the chunk's border included). Where neighbours of different
// levels meet, a skirt (a strip hanging down from the chunk's edge) closes
// the gap; its depth is twice the largest deviation of any level's edge from
// the full-resolution edge, so it covers whatever level the neighbour has.
//
// Plain C++ over sample arrays (no glTF or JSON headers): node.cpp fetches
// the samples (from the ranks that hold them, in a tiled run) and writes.
#pragma once

#include <orogen/grid.hpp>
#include <orogen/tiles.hpp>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace orogen::lod {

/// One chunk: level, place in its level's grid of chunks, and the grid samples it spans,
/// [x0, x1] × [y0, y1] inclusive.
struct Chunk {
    int level = 0, column = 0, row = 0;
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    std::string file;  ///< <stem>_l<level>_x<column>_y<row>.glb
};

/// Levels of the pyramid of a width × height grid with chunks of tile_size samples a side (≥ 1).
int level_count(int width, int height, int tile_size);
/// Every chunk, level 0 first, each level row by row from the north-west.
std::vector<Chunk> pyramid(int width, int height, int tile_size, const std::string& stem);

/// The samples level `level` keeps in [a, b] of an axis of n samples (multiples of 2^level, and n − 1).
AxisSamples level_samples(int n, int level, int a, int b);

/// Heights at a lattice of grid positions, row-major (xs.size() × ys.size()).
struct Samples {
    std::vector<int> xs, ys;
    std::vector<float> h;
    float at(std::size_t i, std::size_t j) const { return h[j * xs.size() + i]; }
};

/// The lattice a chunk is made from: its level's samples one step beyond it on every side (for the edge
/// normals) within the grid, at the next finer level's spacing (the chunk's error is measured against
/// them; level 0: its own).
std::array<AxisSamples, 2> chunk_lattice(const Chunk& chunk, int width, int height);

/// The full-resolution samples along the lines of the chunk's edges, widened to whole steps of the
/// coarsest level: [0] its north and south rows, [1] its west and east columns (as fetch lattices).
std::array<std::array<AxisSamples, 2>, 2> edge_lattices(const Chunk& chunk, int width, int height, int levels);

/// The skirt depth (m, after vertical_scale) that closes any crack along the chunk's edges: twice the
/// largest deviation of a level's edge (levels 1 .. levels − 1) from the full-resolution edge, at least
/// 1 % of a cell. `rows`: the samples of edge_lattices()[0], `columns`: of [1].
double skirt_depth(const Chunk& chunk, const Samples& rows, const Samples& columns, int width, int height, int levels,
                   double cell, double vertical_scale);

/// A chunk's triangle mesh: its level's samples within the chunk as a grid of two counter-clockwise
/// triangles per cell (terrain_mesh.hpp's layout), then the skirt: the edge ring copied `skirt` m lower,
/// with outward-facing walls. Positions local to the chunk's first sample (X east, Y up, Z south, m).
struct Mesh {
    std::vector<float> positions, normals;  // 3 per vertex
    std::vector<std::uint16_t> texcoords;  // 2 per vertex, u east and v south over the chunk, normalised
    std::vector<std::uint32_t> indices;  // 3 per triangle
    std::array<float, 3> min{}, max{};  // of the positions, exactly the written floats
    std::size_t vertex_count() const { return positions.size() / 3; }
};
Mesh chunk_mesh(const Chunk& chunk, const Samples& samples, int width, int height, double cell, double vertical_scale,
                double skirt);

/// The largest vertical distance (m, after vertical_scale) between the chunk's surface and the samples
/// of the finer level inside it: the error of drawing this chunk instead of its children (0 at level 0).
double deviation(const Chunk& chunk, const Samples& samples, int width, int height, double vertical_scale);

/// The chunk's splatted colour (terrain_mesh.hpp's rules over the whole terrain's range lo..hi, m),
/// RGBA8, texture_width × texture_height pixels over the chunk.
std::vector<std::uint8_t> chunk_texture(const Chunk& chunk, const Samples& samples, double cell, float lo, float hi,
                                        int texture_width, int texture_height);

/// What the tileset needs to know of a written chunk.
struct Written {
    double deviation = 0.0;  ///< deviation(), m
    std::array<float, 3> min{}, max{};  ///< Mesh::min and max (glTF frame, local to the chunk)
};

/// The chunk's place in the glTF frame: its node's translation, m (x0 · cell, 0, y0 · cell).
std::array<double, 3> translation(const Chunk& chunk, double cell);

/// The pyramid as an OGC 3D Tiles 1.1 tileset (JSON): the top chunk as the root, each chunk's children
/// the 2 × 2 chunks of the level below it, refine REPLACE. A chunk's geometricError is its deviation
/// plus its children's largest (so it bounds the distance to the full-resolution surface); its
/// boundingVolume a box around its content and its children's. 3D Tiles is Z-up: glTF's (x, y, z) is the
/// tileset's (x, −z, y). `written[i]` belongs to chunks[i]; the files are named relative to the tileset.
std::string tileset_json(const std::vector<Chunk>& chunks, const std::vector<Written>& written, int width, int height,
                         int tile_size, double cell, double vertical_scale);

}  // namespace orogen::lod
