// gltf_writer.hpp — the heightmap as a textured glTF 2.0 terrain.
//
// Plain interface; tinygltf is included only by gltf_writer.cpp.
#pragma once

#include <orogen/grid.hpp>

#include <cstddef>
#include <filesystem>

namespace orogen::gltf {

struct Options {
    double vertical_scale = 1.0;  ///< vertical exaggeration (heights × scale)
    int decimate = 1;             ///< keep every k-th vertex, k ≥ 1
    int chunks = 0;               ///< meshes per side; 0 = fewest that keep 16-bit indices
    int texture_size = 2048;      ///< largest side of the baked colour texture, pixels
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

}  // namespace orogen::gltf
