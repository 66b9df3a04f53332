// vdb_writer.hpp — OpenVDB files: the terrain as a level set, particles as points.
//
// Plain interface; OpenVDB's headers are included only by vdb_terrain.cpp and
// vdb_points.cpp. Frame: X east, Y up, Z south, metres (as glTF, VTK and the
// particle values); voxel (i, j, k) is centred at (i, j, k) · voxel size, so
// with the default voxel size (= cell size) column (i, k) is sample (i, k).
//
// Terrain file grids:
//   surface  GRID_LEVEL_SET, narrow band: signed distance to the terrain
//            surface (negative below ground), approximated per column as the
//            vertical distance × cos(slope) — exact for planes, within a few
//            per cent of a voxel where the slope changes; background =
//            half_width × voxel size. Signs off the band are exact (below
//            the column's ground = inside), and the ground under the band,
//            down to 4096 voxels under the lowest point, is inside tiles.
//   height   the heightmap itself (metres) on the plane j = 0, GRID_UNKNOWN.
//   water    GRID_LEVEL_SET of the water body (between ground and ground +
//            water, where the water layer exceeds water_min), if given.
#pragma once

#include <orogen/grid.hpp>
#include <orogen/values.hpp>

#include <cstddef>
#include <filesystem>

namespace orogen {
class AtomicFile;
}

namespace orogen::vdb {

/// Replace the random UUID OpenVDB put in the header of the file being written with one made from the file's
/// other bytes, so the same data gives the same file (orogen's outputs are bit-identical run to run).
void stamp_content_uuid(AtomicFile& file);

struct TerrainOptions {
    double voxel_size = 0.0;  ///< metres; 0 = the heightmap's cell size
    double half_width = 3.0;  ///< narrow band half-width, voxels (OpenVDB's usual 3)
    double water_min = 1e-3;  ///< metres of water for a column to count as wet
    /// Store the level sets' distances as 16-bit floats: half the file, an error
    /// under 1/1000 of a voxel (|d| ≤ half_width voxels). The height grid stays 32-bit.
    bool half_float = true;
};

struct TerrainSummary {
    std::size_t surface_voxels = 0, water_voxels = 0;  ///< active voxels
    double voxel_size = 0.0;
};

/// Write the terrain (and the water layer, if `water` is given) to `target` (.vdb).
TerrainSummary write_terrain(ConstGridView heights, const ConstGridView* water, const std::filesystem::path& target,
                             const TerrainOptions& options = {});

/// Particle frames as OpenVDB points grids named "particles", every attribute
/// kept (3-component ones as Vec3f): one frame to `target`, several to
/// <stem>_NNNNNN.vdb beside it (committed together). voxel_size 0 = about
/// 8 points per voxel. Returns the number of files written.
std::size_t write_particles(const ParticleSeries& series, const std::filesystem::path& target, double voxel_size = 0.0);

/// openvdb::initialize(), once per process (thread-safe).
void initialize_once();

}  // namespace orogen::vdb
