// vti_reader.hpp — a VTK XML image (.vti) with a point array `height` as a heightmap: what export:vtk
// writes (up=z: X east, Y north; up=y: X east, Z south) and what ParaView saves of it.
#pragma once

#include <orogen/values.hpp>

#include <filesystem>
#include <memory>

namespace orogen::vti {

struct Header {
    int width = 0, height = 0;
    double cell = 0.0;  ///< metres: the spacing along X (0 if it is not a positive number)
};

/// The image's size and spacing, read without its arrays. Throws orogen::BadInput naming the file if
/// VTK cannot read it as image data, it is not one layer of samples (a 3-D volume), it is larger than
/// the memory budget allows.
Header read_header(const std::filesystem::path& path);

/// The heights (point array `height`), rows north to south, `cell` metres apart (0: the image's spacing).
/// Throws orogen::BadInput as read_header, if there is no `height` array (naming the arrays there are) or
/// it is not one number per point, or if neither `cell` nor the image gives a positive cell size.
std::shared_ptr<Heightmap> read(const std::filesystem::path& path, double cell);

}  // namespace orogen::vti
