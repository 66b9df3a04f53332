// voronoi.hpp — an exact Voronoi diagram of random sites over a grid, found
// one cell at a time.
//
// RMP raises only the cell under the peak each iteration, so nothing here
// builds the whole diagram: sites go into a uniform bucket grid (O(sites)),
// a nearest-site query searches rings of buckets outward, and a cell is found
// by clipping the grid rectangle with the bisectors of the sites near it.
// A cell is convex, so the grid vertices it owns form one contiguous run per
// row; the run's ends are settled by exact nearest-site queries, so the spans
// agree with `nearest` vertex for vertex (ties: the lowest site index wins).
//
// Coordinates are sample coordinates: vertex (x, y) sits at (x, y); the grid
// covers [0, width-1] × [0, height-1].
#pragma once

#include <orogen/relief/convex_fill.hpp>

#include <orogen/grid.hpp>

#include <cstdint>
#include <span>
#include <vector>

namespace orogen::relief {

/// `count` sites uniformly over [0, width-1] × [0, height-1] (sample
/// coordinates); site i is a pure function of (seed, i), so any method that
/// asks for the same seed gets the same sites.
std::vector<Point2> random_sites(int count, int width, int height, std::uint64_t seed);

/// A convex polygon, counter-clockwise in (x, y), plus for each edge the site
/// whose bisector made it (-1: the grid border). Edge k runs from vertex k to k+1.
struct CellPolygon {
    std::vector<Point2> vertices;
    std::vector<int> edge_site;
};

/// Sites in a uniform bucket grid, for nearest-site queries and single cells.
class SiteIndex {
public:
    /// Index `sites` (sample coordinates) over a grid of `width` × `height`
    /// vertices. O(sites + buckets); the span must outlive the index.
    SiteIndex(std::span<const Point2> sites, int width, int height);

    std::span<const Point2> sites() const { return sites_; }
    int width() const { return width_; }
    int height() const { return height_; }

    /// The site nearest (x, y); on equal distances the lowest index.
    int nearest(double x, double y) const;

    /// The Voronoi cell of site `s` clipped to the grid rectangle.
    CellPolygon cell(int s) const;

    /// Call fn(y, x0, x1) for every row y holding vertices of site `s`'s cell:
    /// the vertices x0..x1 (inclusive) of row y are exactly those whose
    /// `nearest` is s. Rows in increasing order. Cost: the cell's rows, not the grid.
    template <typename Fn>
    void for_each_span(int s, Fn&& fn) const {
        for_each_span(s, cell(s), fn);
    }
    template <typename Fn>
    void for_each_span(int s, const CellPolygon& polygon, Fn&& fn) const {
        std::vector<Span> spans;
        spans_of(s, polygon, spans);
        for (const Span& sp : spans) fn(sp.y, sp.x0, sp.x1);
    }

    /// A radius every vertex of the grid is within of its nearest site
    /// (an upper bound, from the bucket grid): cones this wide cover the map.
    double covering_radius() const;

    /// For each site, a radius its whole cell lies within (an upper bound from
    /// a grid of tiles, not the cells themselves): the least r with r ≥ B(t)
    /// for every tile t within r of the site, where B(t) bounds the
    /// nearest-site distance over tile t. A point p of s's cell has
    /// |p − s| = (distance to its nearest site) ≤ B(tile of p), and walking
    /// out from s along the (convex) cell shows no point passes r. Cones this
    /// wide cover their cells, with far less overdraw than one covering radius.
    std::vector<double> cell_radius_bounds() const;

    using Span = RowSpan;
    void spans_of(int s, const CellPolygon& polygon, std::vector<Span>& out) const;

private:
    std::span<const Point2> sites_;
    int width_, height_;
    double extent_x_, extent_y_;  // grid rectangle, samples
    int buckets_x_, buckets_y_;
    double bucket_size_;  // samples
    std::vector<int> bucket_start_;  // buckets_x_*buckets_y_ + 1 offsets into bucket_items_
    std::vector<int> bucket_items_;  // site indices, ascending within a bucket

    int bucket_x(double x) const;
    int bucket_y(double y) const;
};

/// The cells a path from a to b (sample coordinates, inside the grid) passes
/// through, in the order first met: those of the Bresenham line's vertices
/// and those the continuous segment crosses. `polygons`, if given, receives
/// each listed cell's polygon (same order), to fill it without clipping again.
std::vector<int> crossed_cells(const SiteIndex& index, Point2 a, Point2 b,
                               std::vector<CellPolygon>* polygons = nullptr);

/// The amount a cell is raised by: `height` · (1 + jitter · u), u in [-1, 1)
/// a pure function of (seed, site), so every method raises a cell alike.
double cell_amount(double height, double jitter, std::uint64_t seed, int site);

/// Label every vertex with its nearest site (brute force over the index, for
/// tests and the full-diagram pictures). Row-major, width × height.
std::vector<std::int32_t> label_grid(const SiteIndex& index);

}  // namespace orogen::relief
