// paraview_state.hpp — a ParaView Python state script that opens an orogen run.
//
// Plain C++ (no VTK, no ParaView): the node (node.cpp) writes the data files
// with export:vtk's writers (Z up) and this script beside them; everything it
// needs to look right is decided here, from the data, at export time:
//   * the colour map of the chosen layer, with orogen-view's choices
//     (viewer/scene.cpp): categorical for plate and boundary ids (one colour
//     and a name per id present), diverging around 0 for eroded (or any layer
//     with both signs), a hypsometric ramp for height, blues for water,
//     yellow-brown for sediment, viridis otherwise; ranges end at the 98th
//     percentile of magnitudes so a few extreme cells do not wash them out;
//   * the vertical exaggeration (auto: relief a fifth of the larger side);
//   * an oblique camera (azimuth clockwise from north, elevation above the horizon).
// The script finds its files relative to its own folder, so the folder can move.
#pragma once

#include <array>
#include <span>
#include <string>
#include <vector>

namespace orogen::paraview {

/// How a layer's values map to colours.
struct Colours {
    enum Kind { sequential, diverging, categorical };
    Kind kind = sequential;
    std::string title;  ///< scalar bar title with the unit, "eroded (m)"
    double low = 0.0, high = 1.0;  ///< colour range (sequential, diverging: symmetric about 0)
    /// Control points of a sequential or diverging ramp, RGB 0..1, spread evenly over low..high.
    std::vector<std::array<double, 3>> ramp;
    struct Category {
        int value = 0;
        std::string name;
        std::array<double, 3> rgb{};
    };
    std::vector<Category> categories;  ///< categorical: one per value present, by value
};

/// The colours for layer `name` (or "height") with `values` (not empty).
Colours colours_for(const std::string& name, std::span<const float> values);

/// Categorical colours for plate ids (the plates' polygons).
Colours plate_colours(std::vector<int> ids);

/// Sequential colours (light to dark blue) from 0 to the 98th percentile of the
/// magnitudes of `values`, `components` floats per item (a particle attribute
/// over every frame).
Colours attribute_colours(const std::string& name, std::span<const float> values, int components);

/// Vertical exaggeration that makes the relief (m) a fifth of the larger
/// horizontal side (m): at least 1 (never flattened), at most 20, two
/// significant digits. 1 for a flat terrain.
double auto_exaggeration(double relief, double side);

struct StateScript {
    std::string script_name;  ///< the script's own file name, for its header
    std::string terrain;  ///< .vti beside the script (relative)
    std::string plates;  ///< .pvd of plate polygons beside the script, or empty
    std::string collisions;  ///< .pvd of plate collisions beside the script, or empty
    std::string particles;  ///< .pvd of particle frames beside the script, or empty
    std::string layer;  ///< point array that colours the terrain ("height" or a layer)
    Colours colours;  ///< of `layer`
    Colours plates_colours;  ///< of the plate polygons (categorical by id)
    std::string particle_colour;  ///< particle attribute that colours them (empty: solid)
    Colours particle_colours;  ///< of `particle_colour`, by magnitude
    double exaggeration = 1.0;
    double height_min = 0.0, height_max = 0.0;  ///< m
    double size_x = 0.0, size_y = 0.0;  ///< extent east and north, m
    double azimuth = 200.0, elevation = 30.0;  ///< degrees
};

/// The Python text (UTF-8, deterministic).
std::string state_script(const StateScript& s);

/// A Python string literal for `text` (escapes quotes, backslashes and control characters).
std::string python_string(const std::string& text);

}  // namespace orogen::paraview
