// shape.hpp — analytic test surfaces (the thesis's experiment 4.1 eroded a
// crooked, a pyramid and a hemispheric surface) and a few more for tests.
#pragma once

#include <orogen/grid.hpp>

#include <string_view>

namespace orogen::shape {

enum class Kind { crooked, pyramid, hemisphere, flat, plane, cone };

/// "crooked" → Kind::crooked; throws orogen::BadInput listing the kinds otherwise.
Kind kind_from_name(std::string_view name);

struct ShapeParams {
    Kind kind = Kind::pyramid;
    double height = 100.0;  ///< metres: the top (flat: the level; plane: the lowest corner)
    double slope = 10.0;  ///< degrees, plane only
    double direction = 0.0;  ///< degrees, plane only: the way it rises; 0 east, 90 south
};

/// Fill `terrain` with the surface, sized by the grid: pyramid, hemisphere and
/// cone stand on the centre with the largest footprint that fits, 0 m around.
///   crooked     a tilted surface, high in the north, with twisted ridges (0..height)
///   pyramid     square base the size of the grid, apex `height`
///   hemisphere  a half-ellipsoid: radius half the shorter side, top `height`
///   flat        `height` everywhere
///   plane       `height` at its lowest corner, rising at `slope` degrees toward `direction`
///   cone        radius half the shorter side, apex `height`
void make_shape(GridView terrain, const ShapeParams& params);

}  // namespace orogen::shape
