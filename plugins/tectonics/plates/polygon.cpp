// polygon.cpp — convex polygon helpers for the plate simulation.
#include "polygon.hpp"

#include <algorithm>
#include <cmath>

namespace orogen::plates {

double signed_area(std::span<const Point2> polygon) {
    const std::size_t n = polygon.size();
    double twice = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        const Point2& a = polygon[i];
        const Point2& b = polygon[(i + 1) % n];
        twice += a.x * b.y - b.x * a.y;
    }
    return 0.5 * twice;
}

Point2 centroid(std::span<const Point2> polygon) {
    // Triangle fan from the first vertex: exact for any simple polygon and
    // better conditioned than the shoelace sum about the origin.
    const std::size_t n = polygon.size();
    const Point2 o = polygon[0];
    double area = 0.0, cx = 0.0, cy = 0.0;
    for (std::size_t i = 1; i + 1 < n; ++i) {
        const double ax = polygon[i].x - o.x, ay = polygon[i].y - o.y;
        const double bx = polygon[i + 1].x - o.x, by = polygon[i + 1].y - o.y;
        const double a = 0.5 * (ax * by - bx * ay);
        area += a;
        cx += a * (ax + bx) / 3.0;
        cy += a * (ay + by) / 3.0;
    }
    if (area == 0.0) return o;
    return {o.x + cx / area, o.y + cy / area};
}

bool is_convex_ccw(std::span<const Point2> polygon, double tolerance) {
    const std::size_t n = polygon.size();
    if (n < 3) return false;
    double scale = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        const Point2& a = polygon[i];
        const Point2& b = polygon[(i + 1) % n];
        scale = std::max(scale, std::hypot(b.x - a.x, b.y - a.y));
    }
    if (!(scale > 0.0) || !(signed_area(polygon) > 0.0)) return false;
    for (std::size_t i = 0; i < n; ++i) {
        const Point2& a = polygon[i];
        const Point2& b = polygon[(i + 1) % n];
        const Point2& c = polygon[(i + 2) % n];
        const double turn = (b.x - a.x) * (c.y - b.y) - (b.y - a.y) * (c.x - b.x);
        if (!(turn > tolerance * scale * scale)) return false;
    }
    return true;
}

bool contains(std::span<const Point2> polygon, Point2 p) {
    const std::size_t n = polygon.size();
    for (std::size_t i = 0; i < n; ++i) {
        const Point2& a = polygon[i];
        const Point2& b = polygon[(i + 1) % n];
        if ((b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x) < 0.0) return false;
    }
    return n >= 3;
}

namespace {

Point2 unit(Point2 d) {
    const double len = std::hypot(d.x, d.y);
    return len > 0.0 ? Point2{d.x / len, d.y / len} : Point2{};
}

Point2 crossing(Point2 a, Point2 b, double sa, double sb) {
    const double t = sa / (sa - sb);
    return {a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)};
}

}  // namespace

std::optional<std::pair<Point2, Point2>> line_entry_exit(std::span<const Point2> polygon, Point2 p, Point2 d) {
    d = unit(d);
    const std::size_t n = polygon.size();
    if (n < 3 || (d.x == 0.0 && d.y == 0.0)) return std::nullopt;
    std::vector<Point2> hits;
    for (std::size_t i = 0; i < n; ++i) {
        const Point2& a = polygon[i];
        const Point2& b = polygon[(i + 1) % n];
        const double sa = side_of(p, d, a), sb = side_of(p, d, b);
        if ((sa > 0.0 && sb <= 0.0) || (sa <= 0.0 && sb > 0.0)) hits.push_back(crossing(a, b, sa, sb));
    }
    if (hits.size() != 2) return std::nullopt;
    const auto along = [&](Point2 q) { return (q.x - p.x) * d.x + (q.y - p.y) * d.y; };
    if (along(hits[0]) > along(hits[1])) std::swap(hits[0], hits[1]);
    return std::pair{hits[0], hits[1]};
}

std::optional<std::pair<Polygon, Polygon>> split_convex(std::span<const Point2> polygon, Point2 p, Point2 d,
                                                        double min_gap) {
    d = unit(d);
    const std::size_t n = polygon.size();
    if (n < 3 || (d.x == 0.0 && d.y == 0.0)) return std::nullopt;
    std::vector<double> side(n);
    for (std::size_t i = 0; i < n; ++i) {
        side[i] = side_of(p, d, polygon[i]);  // signed distance: d is a unit vector
        // A vertex on (or next to) the cut would give a zero-length edge or a
        // near-collinear corner that Box2D welds away: let the caller re-cut.
        if (std::abs(side[i]) < min_gap) return std::nullopt;
    }
    Polygon left, right;
    int changes = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const std::size_t j = (i + 1) % n;
        (side[i] > 0.0 ? left : right).push_back(polygon[i]);
        if ((side[i] > 0.0) != (side[j] > 0.0)) {
            const Point2 x = crossing(polygon[i], polygon[j], side[i], side[j]);
            left.push_back(x);
            right.push_back(x);
            ++changes;
        }
    }
    if (changes != 2 || left.size() < 3 || right.size() < 3) return std::nullopt;
    return std::pair{std::move(left), std::move(right)};
}

}  // namespace orogen::plates
