// gltf_writer.hpp — the heightmap as a textured glTF 2.0 terrain.
//
// Plain interface; tinygltf is included only by gltf_writer.cpp.
#pragma once

#include <orogen/grid.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

namespace orogen::gltf {

struct Options {
    double vertical_scale = 1.0;  ///< vertical exaggeration (heights × scale)
    int decimate = 1;  ///< keep every k-th vertex, k ≥ 1
    int chunks = 0;  ///< meshes per side; 0 = fewest that keep 16-bit indices
    int texture_size = 2048;  ///< largest side of the baked colour texture, pixels
};

struct Summary {
    std::size_t meshes = 0, vertices = 0, triangles = 0;
    int texture_width = 0, texture_height = 0;
    std::size_t bytes = 0;  ///< binary payload (vertex data, indices, texture)
};

/// Write `heights` (metres) to `target`: `.glb` (one binary file) or `.gltf`
/// (JSON, with its buffer beside it as <stem>.bin; both committed together).
/// Atomic: a failure leaves any existing file untouched. Throws
/// orogen::BadInput for a bad extension or options, orogen::Error on I/O failure.
Summary write_gltf(ConstGridView heights, const Options& options, const std::filesystem::path& target);

/// One textured mesh: a chunk of a tiled terrain (export:tiles format=glb).
struct MeshData {
    std::span<const float> positions, normals;  ///< 3 per vertex (m; unit)
    std::span<const std::uint16_t> texcoords;  ///< 2 per vertex, normalised
    std::span<const std::uint32_t> indices;  ///< 3 per triangle; written 16-bit when the vertices allow
    std::array<float, 3> min{}, max{};  ///< of the positions, exactly
};

/// Write `mesh` with the PNG `png` as its base colour to `target` (.glb or .gltf), as one node named
/// `name` placed at `translation` (m). Atomic. Returns the binary payload's size in bytes.
std::size_t write_mesh(const MeshData& mesh, std::span<const std::uint8_t> png, std::array<double, 3> translation,
                       const std::string& name, const std::filesystem::path& target);

}  // namespace orogen::gltf
