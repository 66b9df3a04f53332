// profiles.hpp — the relief a plate boundary leaves where the thesis's
// symmetric RMP range does not fit: a rift valley with its ridge where two
// plates pull apart, and the asymmetric trench-and-arc profile where a dense
// plate dives under a lighter one.
//
// Both are plain functions over a GridView, in sample coordinates, so they
// can be tested alone. Each changes only the cells within a few `width`s of
// the segment (cost ∝ segment length × width, never the whole grid), and
// tapers smoothly past the segment's ends.
#pragma once

#include <orogen/grid.hpp>

namespace orogen::plates {

/// A spreading boundary: a valley `depth` m deep and about `width` samples
/// wide on each side (Gaussian), with a ridge `ridge_height` m high along its
/// axis, a quarter as wide, so the axis stands above the valley floor on both
/// sides — a rift valley with its volcanic ridge.
struct RiftShape {
    double width = 8.0;          ///< samples, the valley's half-width scale
    double depth = 30.0;         ///< m
    double ridge_height = 15.0;  ///< m
};

/// Cut a rift along a–b (sample coordinates). Adds the same change to
/// `uplift` if it is non-null (negative where the ground subsides).
void carve_rift(GridView terrain, Point2 a, Point2 b, const RiftShape& shape, GridView* uplift = nullptr);

/// A subduction zone: the denser plate bends down into a trench just off the
/// boundary on its own side; `width`·1.0 inland on the lighter plate a
/// volcanic arc rises. Asymmetric by design, unlike a collision range.
struct SubductionShape {
    double width = 8.0;          ///< samples: trench–arc distance scale
    double trench_depth = 60.0;  ///< m
    double arc_height = 40.0;    ///< m
};

/// Shape a subduction zone along a–b. `toward_light` points (in sample
/// coordinates, any length) from the subducting (dense) plate to the
/// overriding (light) one: the trench lies on the opposite side, the arc on
/// this side.
void shape_subduction(GridView terrain, Point2 a, Point2 b, Point2 toward_light, const SubductionShape& shape,
                      GridView* uplift = nullptr);

/// The cross-section functions themselves (m at signed distance s samples
/// from the boundary, s > 0 toward the light plate / either side for rifts).
double rift_profile(double s, const RiftShape& shape);
double subduction_profile(double s, const SubductionShape& shape);

}  // namespace orogen::plates
