// reader.hpp — orogen's output files as what the viewer shows.
//
// A terrain is a grid (heights + named layers, row-major, sample (x, y) at
// index y·width + x, X east = x·cell, Z south = y·cell, Y up, metres: the
// glTF frame, docs/exporters.md). .vti, the export:vtk .vtp mesh,
// 16-bit PNG, RAW (.r16/.r32 + <file>.json sidecar), GeoTIFF and GDAL's VRT
// (export:tiles' mosaic, also reached through its .json index) all become one.
// .pvd series become frames of plates, collisions or particles; .glb/.gltf
// are imported by the scene (VTK's glTF importer builds textured actors).
// VTK files written with up=z (X east, Y north, Z up: export:vtk's default,
// marked by the field data "orogen_up") are turned into this frame as read,
// so the scene sees one frame whatever the file's; unmarked files are Y-up.
//
// Every problem with a file is an orogen::BadInput naming the file and what
// to do; VTK's own messages never reach the user.
#pragma once

#include <vtkFloatArray.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace orogen::view {

struct Layer {
    std::string name;
    vtkSmartPointer<vtkFloatArray> values;  ///< width × height samples, row-major
};

struct Terrain {
    std::filesystem::path file;
    int width = 0, height = 0;
    double cell = 1.0;  ///< metres between samples
    vtkSmartPointer<vtkFloatArray> heights;  ///< metres
    std::vector<Layer> layers;  ///< in file order
    const float* layer(const std::string& name) const;
};

/// One instant of a .pvd series; empty pointers where the series has no such part.
struct Frame {
    double time = 0.0;
    vtkSmartPointer<vtkPolyData> plates;  ///< polygons, cell arrays plate, velocity, density
    vtkSmartPointer<vtkPolyData> collisions;  ///< lines, cell arrays plate_a, plate_b, kind, impulse, step
    vtkSmartPointer<vtkPolyData> particles;  ///< vertices, point arrays per attribute
};

struct Series {
    std::filesystem::path file;
    std::vector<Frame> frames;  ///< by increasing time
};

/// Everything given on the command line (or written by a spec run).
struct Content {
    std::vector<Terrain> terrains;  ///< usually one
    std::vector<Series> series;
    std::vector<std::filesystem::path> gltf;  ///< imported by the scene
};

/// File extensions the viewer opens, for messages: ".vti, .vtp, ...".
extern const char* const known_extensions;

/// Read every file; throws orogen::BadInput (exit 2) at the first bad one.
Content read_files(std::span<const std::filesystem::path> files);

/// The files of a spec's output folder worth showing: the first terrain
/// (.vti, else a .vtp mesh, .r16/.r32, 16-bit .png, .glb/.gltf, in that
/// order of preference) and every .pvd series. Empty if there is none.
std::vector<std::filesystem::path> pick_outputs(const std::filesystem::path& folder);

}  // namespace orogen::view
