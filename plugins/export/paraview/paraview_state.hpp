// paraview_state.hpp — a ParaView Python state script that opens an orogen run.
//
// Plain C++ (no VTK, no ParaView): the node (node.cpp) writes the data files
// with export:vtk's writers (Z up) and this script beside them; everything it
// needs to look right is decided here, from the data, at export time:
//   * the colour map of the chosen layer, from its values: categorical for
//     plate and boundary ids (one colour and a name per id present); every
//     other range runs over the values' 2nd to 98th percentile, so a few
//     extreme cells do not wash it out. Diverging only around a meaningful
//     zero: a layer whose 2–98 % range has both signs (eroded: cut and
//     deposited) is diverging about 0; an `eroded` that is one-signed there
//     (uplift and erosion over millions of years: every cell lost kilometres)
//     is shown relative to its median (a derived point array, LAYER_vs_median),
//     diverging about that median, so the valleys cut deeper than the map's
//     typical cell stand out from the ridges that lost less. A hypsometric
//     ramp for height, blues for water and flow, a log scale for drainage
//     (upstream area), yellow-brown for sediment, viridis otherwise;
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
    bool log = false;  ///< sequential on a log scale (low > 0)
    /// The point array coloured: the layer itself, or LAYER_vs_median (the layer minus `shift`).
    std::string array;
    double shift = 0.0;  ///< subtracted from the layer to make `array` (its median), else 0
    /// The 2nd and 98th percentiles of `array`'s values (categorical: the smallest and largest id).
    double data_low = 0.0, data_high = 0.0;
};

/// The q-quantile (0 ≤ q ≤ 1) of the finite values, by nearest rank; 0 when there are none.
double percentile(std::span<const float> values, double q);

using XY = std::array<double, 2>;

/// A convex polygon clipped to the rectangle [x0, x1] × [y0, y1] (Sutherland–Hodgman); empty when it
/// lies outside.
std::vector<XY> clip_polygon(const std::vector<XY>& polygon, double x0, double y0, double x1, double y1);

/// The segment a–b clipped to the rectangle (Liang–Barsky); false when it lies outside.
bool clip_segment(XY& a, XY& b, double x0, double y0, double x1, double y1);

/// `points` with points inserted along each edge (and the closing edge when `closed`) so that none is
/// longer than `step` (> 0).
std::vector<XY> densify(const std::vector<XY>& points, double step, bool closed);

/// The colours for layer `name` (or "height") with `values` (not empty).
Colours colours_for(const std::string& name, std::span<const float> values);

/// Categorical colours for plate ids (the plates' polygons).
Colours plate_colours(std::vector<int> ids);

/// Sequential colours (light to dark blue) from the 2nd to the 98th percentile
/// of the magnitudes of `values`, `components` floats per item (a particle
/// attribute over every frame).
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
    std::string layer;  ///< the layer that colours the terrain ("height" or a layer; colours.array is drawn)
    Colours colours;  ///< of `layer`
    Colours plates_colours;  ///< of the plate polygons (categorical by id)
    std::string particle_colour;  ///< particle attribute that colours them (empty: solid)
    Colours particle_colours;  ///< of `particle_colour`, by magnitude
    /// Particles whose "sediment" is at least this are drawn apart, in their own colour (the
    /// 90th percentile over every frame); 0: none (no sediment attribute, or none carried).
    double sediment_threshold = 0.0;
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
