#include <orogen/relief/range.hpp>

#include <orogen/relief/voronoi.hpp>

#include <orogen/error.hpp>
#include <orogen/random.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <unordered_map>

namespace orogen::relief {

namespace {

// Key for the per-cell jitter draw: a cell's amount must not correlate with its position.
constexpr std::uint64_t kJitterStream = 0x4a6974746572ull;  // "Jitter"

double cross(double ax, double ay, double bx, double by) { return ax * by - ay * bx; }

// Where the segment A + t·D, inside the convex counter-clockwise polygon at
// t_from, leaves it: the parameter and the edge it leaves by.
std::pair<double, int> exit_of(const CellPolygon& poly, Point2 a, Point2 d, double t_from) {
    double t_out = std::numeric_limits<double>::infinity();
    int edge = -1;
    const std::size_t n = poly.vertices.size();
    for (std::size_t k = 0; k < n; ++k) {
        const Point2& p = poly.vertices[k];
        const Point2& q = poly.vertices[(k + 1) % n];
        const double ex = q.x - p.x, ey = q.y - p.y;
        const double c1 = cross(ex, ey, d.x, d.y);
        if (c1 >= 0) continue;  // moving inward or along this edge
        const double c0 = cross(ex, ey, a.x - p.x, a.y - p.y);
        const double t = -c0 / c1;
        if (t < t_out) {
            t_out = t;
            edge = int(k);
        }
    }
    return {std::max(t_out, t_from), edge};
}

}  // namespace

double cell_amount(double height, double jitter, std::uint64_t seed, int site) {
    if (jitter == 0.0) return height;
    const float u = random::symmetric_float(random::hash(seed, std::uint64_t(site), kJitterStream));
    return height * (1.0 + jitter * double(u));
}

std::vector<int> crossed_cells(const SiteIndex& index, Point2 a, Point2 b, std::vector<CellPolygon>* polygons) {
    std::vector<int> order;
    std::vector<CellPolygon> polys;
    std::unordered_map<int, std::size_t> seen;
    auto add = [&](int s) -> const CellPolygon& {
        auto [it, inserted] = seen.emplace(s, order.size());
        if (inserted) {
            order.push_back(s);
            polys.push_back(index.cell(s));
        }
        return polys[it->second];
    };

    // (1) The continuous segment, cell by cell: leave a cell by an edge, and
    // the site that made that edge owns the next cell.
    const Point2 d{b.x - a.x, b.y - a.y};
    const int max_steps = int(index.sites().size()) + 8;
    int s = index.nearest(a.x, a.y);
    double t = 0.0;
    for (int step = 0; step < max_steps; ++step) {
        const CellPolygon& poly = add(s);
        if (d.x == 0.0 && d.y == 0.0) break;
        auto [t_out, edge] = exit_of(poly, a, d, t);
        if (t_out >= 1.0 || edge < 0) break;
        int next = poly.edge_site[std::size_t(edge)];
        if (next < 0 || seen.count(next)) {
            // Rounding at a Voronoi vertex: probe just past the exit instead.
            next = -1;
            for (double probe = 1e-9; t_out + probe < 1.0 && next < 0; probe *= 10.0) {
                const double tp = t_out + probe;
                const int c = index.nearest(a.x + tp * d.x, a.y + tp * d.y);
                if (!seen.count(c)) next = c;
            }
            if (next < 0) break;
        }
        t = t_out;
        s = next;
    }

    // (2) The thesis's Bresenham line over the vertex labels.
    int x0 = int(std::lround(a.x)), y0 = int(std::lround(a.y));
    const int x1 = int(std::lround(b.x)), y1 = int(std::lround(b.y));
    const int dx = std::abs(x1 - x0), dy = -std::abs(y1 - y0);
    const int sx = x0 < x1 ? 1 : -1, sy = y0 < y1 ? 1 : -1;
    int err = dx + dy;
    while (true) {
        add(index.nearest(x0, y0));
        if (x0 == x1 && y0 == y1) break;
        const int e2 = 2 * err;
        if (e2 >= dy) {
            err += dy;
            x0 += sx;
        }
        if (e2 <= dx) {
            err += dx;
            y0 += sy;
        }
    }
    if (polygons) *polygons = std::move(polys);
    return order;
}

int raise_range(GridView terrain, Point2 a, Point2 b, const RangeParams& params, std::uint64_t seed, GridView* uplift) {
    return raise_range(terrain, GridWindow{terrain.width, terrain.height, 0, 0}, a, b, params, seed, uplift);
}

int raise_range(GridView terrain, GridWindow grid, Point2 a, Point2 b, const RangeParams& params, std::uint64_t seed,
                GridView* uplift) {
    const int width = grid.width, height = grid.height, wx0 = grid.x0, wy0 = grid.y0;
    if (params.cones < 1) throw BadInput("range: cones must be at least 1 (got " + std::to_string(params.cones) + ")");
    if (width < 1 || height < 1 || !terrain.data) throw BadInput("range: the terrain grid is empty");
    if (wx0 < 0 || wy0 < 0 || wx0 + terrain.width > width || wy0 + terrain.height > height)
        throw BadInput("range: the window must lie inside the grid");
    if (!std::isfinite(a.x) || !std::isfinite(a.y) || !std::isfinite(b.x) || !std::isfinite(b.y))
        throw BadInput("range: the end points must be finite numbers");
    if (uplift && (uplift->width != terrain.width || uplift->height != terrain.height))
        throw BadInput("range: the uplift grid must have the terrain's size");
    const double ex = width - 1, ey = height - 1;
    a = {std::clamp(a.x, 0.0, ex), std::clamp(a.y, 0.0, ey)};
    b = {std::clamp(b.x, 0.0, ex), std::clamp(b.y, 0.0, ey)};

    // The diagram and the crossed cells of the whole grid (O(cones + cells crossed)), then only the
    // window's part of each cell's spans.
    const std::vector<Point2> sites = random_sites(params.cones, width, height, seed);
    const SiteIndex index(sites, width, height);
    std::vector<CellPolygon> polygons;
    const std::vector<int> cells = crossed_cells(index, a, b, &polygons);
    std::vector<SiteIndex::Span> spans;
    for (std::size_t k = 0; k < cells.size(); ++k) {
        index.spans_of(cells[k], polygons[k], spans);
        add_spans({terrain, wx0, wy0}, spans, float(cell_amount(params.height, params.jitter, seed, cells[k])), uplift);
    }
    return int(cells.size());
}

}  // namespace orogen::relief
