// colour_maps.hpp — how orogen-view colours a layer: the colour map by a layer's name and values
// (diverging around zero, categorical ids, log scale for areas), and the text actors' look.
#pragma once

#include <vtkLookupTable.h>
#include <vtkSmartPointer.h>
#include <vtkTextActor.h>

#include <array>
#include <cstddef>
#include <initializer_list>
#include <map>
#include <string>
#include <vector>

namespace orogen::view {

/// A colour map with a control point at each of `colours` (RGB 0..255) spread over lo..hi, evenly in the
/// value or, with `log`, in its logarithm (lo > 0).
vtkSmartPointer<vtkLookupTable> ramp(std::initializer_list<std::array<int, 3>> colours, double lo, double hi,
                                     bool log = false);

/// A categorical table for whole-number ids, with names and colours where given.
vtkSmartPointer<vtkLookupTable> categories(const std::vector<int>& ids, const std::map<int, std::string>& names = {},
                                           const std::map<int, std::array<unsigned char, 3>>& colours = {});

/// The plate boundaries' kinds (a collision's `boundary`), named and coloured.
extern const std::map<int, std::string> boundary_names;
extern const std::map<int, std::array<unsigned char, 3>> boundary_colours;

/// The colour map for a layer, by its name and values; `title` gets the scalar bar's title (with the unit).
vtkSmartPointer<vtkLookupTable> lut_for(const std::string& name, const float* v, std::size_t n, std::string* title);

/// A text overlay in the viewer's look: Courier, on a dark translucent band.
vtkSmartPointer<vtkTextActor> text_actor(int size, double r, double g, double b);

}  // namespace orogen::view
