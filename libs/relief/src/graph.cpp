#include <orogen/relief/graph.hpp>

#include <orogen/error.hpp>
#include <orogen/random.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <unordered_map>

namespace orogen::relief {

namespace {

double cross(const Point2& a, const Point2& b) { return a.x * b.y - a.y * b.x; }
Point2 sub(const Point2& a, const Point2& b) { return {a.x - b.x, a.y - b.y}; }

struct Segment {
    Point2 a, b;
    std::vector<std::pair<double, int>> stops;  // (parameter along a→b, vertex)
};

// Clip the infinite line to the rectangle (Liang–Barsky); false if it misses.
bool clip_line(const Line& line, double w, double h, double eps, Segment& out) {
    const Point2 p = line.point, d = line.direction;
    double t0 = -std::numeric_limits<double>::infinity(), t1 = std::numeric_limits<double>::infinity();
    auto edge = [&](double q, double dp) {  // constraint q + t·dp >= 0
        if (dp == 0.0) return q >= 0.0;
        const double t = -q / dp;
        if (dp > 0) t0 = std::max(t0, t);
        else t1 = std::min(t1, t);
        return true;
    };
    if (!edge(p.x, d.x) || !edge(w - p.x, -d.x) || !edge(p.y, d.y) || !edge(h - p.y, -d.y)) return false;
    if (!(t0 < t1)) return false;
    out.a = {std::clamp(p.x + t0 * d.x, 0.0, w), std::clamp(p.y + t0 * d.y, 0.0, h)};
    out.b = {std::clamp(p.x + t1 * d.x, 0.0, w), std::clamp(p.y + t1 * d.y, 0.0, h)};
    if (std::hypot(out.b.x - out.a.x, out.b.y - out.a.y) < 16 * eps) return false;  // touches a corner only
    // A cut along the border adds nothing but overlapping edges.
    const bool on_border = (std::abs(out.a.x - out.b.x) < eps && (out.a.x < eps || out.a.x > w - eps)) ||
        (std::abs(out.a.y - out.b.y) < eps && (out.a.y < eps || out.a.y > h - eps));
    return !on_border;
}

// Vertices merged within eps, found through a hash of eps-sized cells.
class VertexPool {
public:
    explicit VertexPool(double eps) : eps_(eps) {}
    int add(Point2 p) {
        const std::int64_t cx = std::int64_t(std::floor(p.x / eps_)), cy = std::int64_t(std::floor(p.y / eps_));
        for (std::int64_t dy = -1; dy <= 1; ++dy)
            for (std::int64_t dx = -1; dx <= 1; ++dx) {
                auto it = cells_.find(key(cx + dx, cy + dy));
                if (it == cells_.end()) continue;
                for (int v : it->second)
                    if (std::hypot(points[std::size_t(v)].x - p.x, points[std::size_t(v)].y - p.y) <= eps_) return v;
            }
        points.push_back(p);
        cells_[key(cx, cy)].push_back(int(points.size() - 1));
        return int(points.size() - 1);
    }
    std::vector<Point2> points;

private:
    static std::uint64_t key(std::int64_t x, std::int64_t y) {
        return std::uint64_t(x) * 0x9E3779B97F4A7C15ull ^ std::uint64_t(y);
    }
    double eps_;
    std::unordered_map<std::uint64_t, std::vector<int>> cells_;
};

}  // namespace

std::vector<Line> random_cuts(int count, double width, double height, std::uint64_t seed) {
    if (count < 0) throw BadInput("the number of cuts must not be negative");
    std::vector<Line> lines(static_cast<std::size_t>(count));
    for (int i = 0; i < count; ++i) {
        const double angle = random::uniform(seed, std::uint64_t(i), 2u) * std::numbers::pi;
        lines[std::size_t(i)] = {
            {random::uniform(seed, std::uint64_t(i), 0u) * width, random::uniform(seed, std::uint64_t(i), 1u) * height},
            {std::cos(angle), std::sin(angle)}};
    }
    return lines;
}

std::vector<Point2> Arrangement::polygon(int face) const {
    std::vector<Point2> p;
    for (int v : faces[std::size_t(face)]) p.push_back(vertices[std::size_t(v)]);
    return p;
}

Arrangement build_arrangement(std::span<const Line> cuts, double w, double h) {
    if (!(w > 0) || !(h > 0)) throw BadInput("a line arrangement needs a rectangle of positive size");
    const double eps = 1e-7 * std::max(w, h);  // samples: merge distance for intersection points
    std::vector<Segment> segs;
    segs.push_back({{0, 0}, {w, 0}, {}});
    segs.push_back({{w, 0}, {w, h}, {}});
    segs.push_back({{w, h}, {0, h}, {}});
    segs.push_back({{0, h}, {0, 0}, {}});
    for (const Line& line : cuts) {
        if (line.direction.x == 0.0 && line.direction.y == 0.0) continue;
        Segment s;
        if (clip_line(line, w, h, eps, s)) segs.push_back(s);
    }

    VertexPool pool(eps);
    for (Segment& s : segs) {
        s.stops.push_back({0.0, pool.add(s.a)});
        s.stops.push_back({1.0, pool.add(s.b)});
    }
    // Pairwise intersections (the thesis's equations 3.1–3.11).
    for (std::size_t i = 0; i < segs.size(); ++i) {
        const Point2 d = sub(segs[i].b, segs[i].a);
        const double ld = std::hypot(d.x, d.y);
        for (std::size_t j = i + 1; j < segs.size(); ++j) {
            const Point2 e = sub(segs[j].b, segs[j].a);
            const double le = std::hypot(e.x, e.y);
            const double denom = cross(d, e);
            if (std::abs(denom) <= 1e-13 * ld * le) continue;  // parallel
            const Point2 ca = sub(segs[j].a, segs[i].a);
            const double u = cross(ca, e) / denom;
            const double v = cross(ca, d) / denom;
            const double tu = eps / ld, tv = eps / le;
            if (u < -tu || u > 1 + tu || v < -tv || v > 1 + tv) continue;
            const Point2 p{std::clamp(segs[i].a.x + u * d.x, 0.0, w), std::clamp(segs[i].a.y + u * d.y, 0.0, h)};
            const int id = pool.add(p);
            segs[i].stops.push_back({u, id});
            segs[j].stops.push_back({v, id});
        }
    }

    Arrangement g;
    g.vertices = std::move(pool.points);
    const std::size_t nv = g.vertices.size();
    // Edges: consecutive distinct vertices along each segment.
    std::vector<std::pair<int, int>> edges;
    for (Segment& s : segs) {
        std::sort(s.stops.begin(), s.stops.end());
        std::vector<int> seq;
        for (const auto& [t, v] : s.stops)
            if (std::find(seq.begin(), seq.end(), v) == seq.end()) seq.push_back(v);
        for (std::size_t k = 1; k < seq.size(); ++k)
            edges.push_back({std::min(seq[k - 1], seq[k]), std::max(seq[k - 1], seq[k])});
    }
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    g.edges = edges;

    // Half-edges 2k (u→v) and 2k+1 (v→u); outgoing ones sorted by angle at each vertex.
    const std::size_t nh = edges.size() * 2;
    auto origin = [&](std::size_t he) { return he % 2 == 0 ? edges[he / 2].first : edges[he / 2].second; };
    auto target = [&](std::size_t he) { return he % 2 == 0 ? edges[he / 2].second : edges[he / 2].first; };
    std::vector<std::vector<std::size_t>> out(nv);
    for (std::size_t he = 0; he < nh; ++he) out[std::size_t(origin(he))].push_back(he);
    std::vector<double> angle(nh);
    for (std::size_t he = 0; he < nh; ++he) {
        const Point2 d = sub(g.vertices[std::size_t(target(he))], g.vertices[std::size_t(origin(he))]);
        angle[he] = std::atan2(d.y, d.x);
    }
    std::vector<std::size_t> position(nh);
    for (auto& list : out) {
        std::sort(list.begin(), list.end(), [&](std::size_t a, std::size_t b) { return angle[a] < angle[b]; });
        for (std::size_t k = 0; k < list.size(); ++k) position[list[k]] = k;
    }
    // Walk each face with the face on the left: arriving at v by u→v, leave by
    // the outgoing edge just clockwise of v→u.
    auto next = [&](std::size_t he) {
        const std::size_t twin = he ^ 1u;
        const auto& list = out[std::size_t(target(he))];
        return list[(position[twin] + list.size() - 1) % list.size()];
    };
    std::vector<int> face_of(nh, -2);
    for (std::size_t start = 0; start < nh; ++start) {
        if (face_of[start] != -2) continue;
        std::vector<int> cycle;
        std::vector<std::size_t> hes;
        std::size_t he = start;
        double area = 0;
        do {
            face_of[he] = -1;
            hes.push_back(he);
            cycle.push_back(origin(he));
            area += cross(g.vertices[std::size_t(origin(he))], g.vertices[std::size_t(target(he))]);
            he = next(he);
        } while (he != start && hes.size() <= nh);
        if (area > 0) {  // bounded; the outer face runs clockwise
            const int f = int(g.faces.size());
            for (std::size_t x : hes) face_of[x] = f;
            g.faces.push_back(std::move(cycle));
        }
    }
    g.adjacency.assign(g.faces.size(), {});
    for (std::size_t he = 0; he < nh; ++he) {
        const int f = face_of[he], o = face_of[he ^ 1u];
        if (f >= 0 && o >= 0 && f != o) g.adjacency[std::size_t(f)].push_back(o);
    }
    for (auto& a : g.adjacency) {
        std::sort(a.begin(), a.end());
        a.erase(std::unique(a.begin(), a.end()), a.end());
    }
    return g;
}

bool pnpoly(std::span<const Point2> poly, Point2 p) {
    bool inside = false;
    const std::size_t n = poly.size();
    for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
        if (((poly[i].y > p.y) != (poly[j].y > p.y)) &&
            (p.x < (poly[j].x - poly[i].x) * (p.y - poly[i].y) / (poly[j].y - poly[i].y) + poly[i].x))
            inside = !inside;
    }
    return inside;
}

int face_containing(const Arrangement& g, Point2 p) {
    for (std::size_t f = 0; f < g.faces.size(); ++f)
        if (pnpoly(g.polygon(int(f)), p)) return int(f);
    // On the far border PNPOLY's half-open rule says "outside": nudge the point inward.
    double cx = 0, cy = 0;
    for (const Point2& v : g.vertices) {
        cx = std::max(cx, v.x);
        cy = std::max(cy, v.y);
    }
    const Point2 q{p.x + (cx / 2 - p.x) * 1e-9, p.y + (cy / 2 - p.y) * 1e-9};
    for (std::size_t f = 0; f < g.faces.size(); ++f)
        if (pnpoly(g.polygon(int(f)), q)) return int(f);
    return -1;
}

std::vector<int> depth_first_order(const Arrangement& g, int start) {
    std::vector<int> order;
    if (start < 0 || std::size_t(start) >= g.faces.size()) return order;
    std::vector<bool> seen(g.faces.size(), false);
    std::vector<std::pair<int, std::size_t>> stack{{start, 0}};
    seen[std::size_t(start)] = true;
    order.push_back(start);
    while (!stack.empty()) {
        auto& [f, k] = stack.back();
        const auto& nbrs = g.adjacency[std::size_t(f)];
        if (k == nbrs.size()) {
            stack.pop_back();
            continue;
        }
        const int n = nbrs[k++];
        if (seen[std::size_t(n)]) continue;
        seen[std::size_t(n)] = true;
        order.push_back(n);
        stack.push_back({n, 0});
    }
    return order;
}

}  // namespace orogen::relief
