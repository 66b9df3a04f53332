// vtk_writer.hpp — VTK XML files for ParaView: heightmaps, particles, plates.
//
// Plain interface; VTK's headers are included only by vtk_writer.cpp.
//
// Two frames of reference, chosen by Options::up (every file records its
// own in the field-data string array "orogen_up", "z" or "y"; metres, origin
// at heightmap sample (0, 0), the north-west corner):
//   z (default)  X east, Y north, Z up: ParaView's and GIS's convention. The
//                terrain lies in the XY plane (Y = −row·cell, so it spans
//                Y ∈ [−(h−1)·cell, 0]), ParaView's default camera looks down
//                on it and "Warp By Scalar" (normal 0 0 1) raises it.
//   y            X east, Y up, Z south: glTF's convention and orogen's own
//                (the particle values, plate coordinates, export:gltf).
// The z frame is the y frame turned +90° about X, (x, y, z) → (x, −z, y): no
// mirror, so triangle winding and handedness are kept.
//   heightmap .vti  image data. z: width × height × 1 points, spacing
//                   (cell, cell, 1), origin (0, −(h−1)·cell, 0), rows stored
//                   south first (VTK's j axis runs north). y: width × 1 ×
//                   height points in the XZ plane, rows as stored. Point
//                   arrays "height" and every layer by its name.
//   heightmap .vtp  the triangle mesh (as export:gltf lays it out: two CCW
//                   triangles per tile, height·scale along the up axis),
//                   "Normals", and the same point arrays; points row-major
//                   as the heightmap, north row first.
//   particles       one .vtp per frame (points + vertex cells, every attribute
//                   as a point array; 3-component attributes are vectors and
//                   turn with the frame), listed with their times in a .pvd.
//   plates          per snapshot: a .vtp of plate polygons (cell arrays
//                   plate, velocity, density) and a .vtp of the collisions
//                   since the previous snapshot (lines a–b with plate_a,
//                   plate_b, kind, impulse, step), parts 0 and 1 of a .pvd;
//                   all at height 0.
// Every file is written through orogen::AtomicFile; a series is committed
// together, after every file of it has been written.
#pragma once

#include <orogen/grid.hpp>
#include <orogen/values.hpp>

#include <filesystem>
#include <span>
#include <string>

namespace orogen::vtk {

struct NamedGrid {
    std::string name;
    ConstGridView grid;
};

/// Which axis points up in the files (see above).
enum class Up { z, y };

/// "z" → Up::z, "y" → Up::y (the nodes' `up` parameter).
Up up_from_name(const std::string& name);

struct Options {
    Up up = Up::z;  ///< frame of reference of every point and vector
    bool compress = false;  ///< zlib-compress the arrays (smaller, slower)
    double vertical_scale = 1.0;  ///< .vtp heightmap mesh only
    int decimate = 1;  ///< .vtp heightmap mesh only: keep every k-th vertex
};

/// Heightmap (+ named layers of the same size) as .vti or .vtp, by `target`'s extension.
void write_heightmap(ConstGridView heights, std::span<const NamedGrid> layers, const std::filesystem::path& target,
                     const Options& options = {});

/// One piece of a tiled heightmap as a .vti whose extent is the piece's place in
/// the whole grid: columns x0 .. x0+width−1, rows y0 .. y0+height−1 (the
/// .vti a whole grid gives, cut there). Pieces listed in a .pvti (pvti_text)
/// overlap by one row or column, as ParaView's parallel image data wants.
/// `whole_height`: rows of the whole grid (up=z places the piece counting rows from the south).
void write_heightmap_piece(ConstGridView piece, std::span<const NamedGrid> layers, int x0, int y0, int whole_height,
                           const std::filesystem::path& target, const Options& options = {});

/// A .pvti piece: its file (relative to the .pvti) and extent in the whole grid (first and last column, row).
struct PvtiPiece {
    std::string file;
    int x0 = 0, x1 = 0, y0 = 0, y1 = 0;
};
/// The .pvti text over `pieces` of a width × height grid, `cell` metres apart, with the point arrays
/// "height" and `layer_names` (all Float32), in that order.
/// The pieces' extents are given in orogen's rows (north to south); up=z turns them as the pieces are.
std::string pvti_text(int width, int height, double cell, std::span<const std::string> layer_names,
                      std::span<const PvtiPiece> pieces, Up up = Up::y);

/// Particle frames: `target` .pvd (one <stem>_NNNNNN.vtp per frame beside it) or
/// .vtp (a single frame). Returns the number of files written.
std::size_t write_particles(const ParticleSeries& series, const std::filesystem::path& target,
                            const Options& options = {});

/// Plate history: `target` .pvd with <stem>_plates_NNNNNN.vtp and
/// <stem>_collisions_NNNNNN.vtp per snapshot (parts 0 and 1). With
/// `collisions_target` (a .pvd beside `target`), the collisions are listed
/// there instead and `target` lists only the polygons: two plain series that
/// a reader takes one at a time (export:paraview-state). Returns the number
/// of files written.
std::size_t write_plates(const PlateHistory& history, const std::filesystem::path& target, const Options& options = {},
                         const std::filesystem::path& collisions_target = {});

/// The .pvd text for (time, file, part) entries.
struct PvdEntry {
    double time = 0.0;
    int part = 0;
    std::string file;  ///< relative to the .pvd
};
std::string pvd_text(std::span<const PvdEntry> entries);

}  // namespace orogen::vtk
