// cones.hpp — the thesis's Voronoi trick (section 3.3.2, after the OpenGL Red
// Book): one flat cone per site, seen from above through an orthographic
// projection with a depth test; where cones overlap the nearest apex wins,
// so the visible colours are the Voronoi cells. Drawn offscreen with OSMesa
// (Mesa's llvmpipe, no display), one pixel per grid vertex, pixel centres on
// the vertices; each cone's colour encodes its site index.
//
// Each cone's depth is its exact distance to its apex, written per fragment,
// so the diagram is exact up to float rounding on cell borders (the thesis's
// 64-segment cones bent every border by up to 0.1 %). Each cone is as wide as
// a bound of its own cell's reach (SiteIndex::cell_radius_bounds, from the
// bucket grid, not from the cells), so every vertex is covered by its own
// site's cone — the thesis's radius-1 cones left the map's corners bare —
// while the overdraw stays a few times the grid, not sites × grid.
//
// Library orogen_core_rmp_gl; the OSMesa headers stay in cones_gl.cpp.
#pragma once

#include "rmp.hpp"

#include <orogen/grid.hpp>

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace orogen::rmp {

class ConeRenderer {
public:
    /// A width × height offscreen target in the process's one OSMesa context
    /// (orogen/gl_context.hpp, shared with the render passes).
    /// Throws orogen::Error (failed run) if OSMesa cannot create or bind the
    /// context, orogen::BadInput if the grid is larger than it can draw.
    ConeRenderer(int width, int height);
    ~ConeRenderer();
    ConeRenderer(const ConeRenderer&) = delete;
    ConeRenderer& operator=(const ConeRenderer&) = delete;

    /// Draw one cone of `radius` samples per site (sample coordinates) and
    /// read the frame back: the returned row-major ids hold, per vertex, the
    /// index of the site on top plus one (0: no cone reached the vertex).
    /// Valid until the next call.
    const std::vector<std::uint32_t>& render(std::span<const Point2> sites, double radius);
    /// The same with one radius per site (see SiteIndex::cell_radius_bounds).
    const std::vector<std::uint32_t>& render(std::span<const Point2> sites, std::span<const double> radii);

    /// render() then labels: site index per vertex, -1 where no cone reached.
    std::vector<std::int32_t> labels(std::span<const Point2> sites, double radius);

    /// "llvmpipe (LLVM 15.0.6, 256 bits)", for benchmark records.
    std::string renderer_name() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// RMP with the cone-rasterised Voronoi diagram: the same sites as
/// rmp_voronoi for the same seed; every vertex with the colour under a peak rises.
void rmp_cones(GridView terrain, const RmpParams& params, std::uint64_t seed, const IterationHook& hook = {});

}  // namespace orogen::rmp
