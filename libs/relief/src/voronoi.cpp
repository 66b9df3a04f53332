#include <orogen/relief/voronoi.hpp>

#include <orogen/error.hpp>
#include <orogen/parallel.hpp>
#include <orogen/random.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace orogen::relief {

namespace {

double dist2(double ax, double ay, const Point2& b) {
    const double dx = ax - b.x, dy = ay - b.y;
    return dx * dx + dy * dy;
}

}  // namespace

std::vector<Point2> random_sites(int count, int width, int height, std::uint64_t seed) {
    if (count < 1) throw BadInput("the number of Voronoi sites (cones) must be at least 1");
    std::vector<Point2> sites(static_cast<std::size_t>(count));
    const double ex = std::max(width - 1, 1), ey = std::max(height - 1, 1);
    parallel_for(0, count, 4096, [&](std::int64_t b, std::int64_t e) {
        for (std::int64_t i = b; i < e; ++i)
            sites[std::size_t(i)] = {random::uniform(seed, std::uint64_t(i), 0u) * ex,
                                     random::uniform(seed, std::uint64_t(i), 1u) * ey};
    });
    return sites;
}

SiteIndex::SiteIndex(std::span<const Point2> sites, int width, int height)
    : sites_(sites), width_(width), height_(height) {
    if (sites.empty()) throw BadInput("a Voronoi diagram needs at least one site");
    if (width < 1 || height < 1) throw BadInput("a Voronoi diagram needs a grid of at least 1 × 1 vertices");
    extent_x_ = std::max(width - 1, 1);
    extent_y_ = std::max(height - 1, 1);
    // About one site per bucket: a nearest query then looks at a handful of sites.
    bucket_size_ = std::sqrt(extent_x_ * extent_y_ / double(sites.size()));
    bucket_size_ = std::max(bucket_size_, 1e-3);
    buckets_x_ = std::max(1, int(std::ceil(extent_x_ / bucket_size_)));
    buckets_y_ = std::max(1, int(std::ceil(extent_y_ / bucket_size_)));
    // Counting sort of the sites into buckets: O(sites + buckets), ascending index within a bucket.
    const std::size_t nb = std::size_t(buckets_x_) * std::size_t(buckets_y_);
    bucket_start_.assign(nb + 1, 0);
    std::vector<int> bucket_of(sites.size());
    for (std::size_t i = 0; i < sites.size(); ++i) {
        const int b = bucket_y(sites[i].y) * buckets_x_ + bucket_x(sites[i].x);
        bucket_of[i] = b;
        ++bucket_start_[std::size_t(b) + 1];
    }
    for (std::size_t b = 0; b < nb; ++b) bucket_start_[b + 1] += bucket_start_[b];
    bucket_items_.resize(sites.size());
    std::vector<int> fill(bucket_start_.begin(), bucket_start_.end() - 1);
    for (std::size_t i = 0; i < sites.size(); ++i)
        bucket_items_[std::size_t(fill[std::size_t(bucket_of[i])]++)] = int(i);
}

int SiteIndex::bucket_x(double x) const { return std::clamp(int(std::floor(x / bucket_size_)), 0, buckets_x_ - 1); }
int SiteIndex::bucket_y(double y) const { return std::clamp(int(std::floor(y / bucket_size_)), 0, buckets_y_ - 1); }

namespace {

// Visit the buckets at Chebyshev distance exactly r from (bx, by), inside the grid.
template <typename Fn>
void for_ring(int bx, int by, int r, int nx, int ny, Fn&& fn) {
    if (r == 0) {
        fn(bx, by);
        return;
    }
    const int x0 = std::max(bx - r, 0), x1 = std::min(bx + r, nx - 1);
    if (by - r >= 0)
        for (int x = x0; x <= x1; ++x) fn(x, by - r);
    if (by + r < ny)
        for (int x = x0; x <= x1; ++x) fn(x, by + r);
    const int y0 = std::max(by - r + 1, 0), y1 = std::min(by + r - 1, ny - 1);
    if (bx - r >= 0)
        for (int y = y0; y <= y1; ++y) fn(bx - r, y);
    if (bx + r < nx)
        for (int y = y0; y <= y1; ++y) fn(bx + r, y);
}

// A lower bound of the distance from (x, y), in bucket (bx, by), to any point
// of the buckets at Chebyshev distance ≥ r (r ≥ 1). Negative if none can be given.
double ring_lower_bound(double x, double y, int bx, int by, int r, double size) {
    const double left = x - double(bx - r + 1) * size;
    const double right = double(bx + r) * size - x;
    const double top = y - double(by - r + 1) * size;
    const double bottom = double(by + r) * size - y;
    return std::min({left, right, top, bottom});
}

}  // namespace

int SiteIndex::nearest(double x, double y) const {
    const int bx = bucket_x(x), by = bucket_y(y);
    const int max_r = std::max({bx, buckets_x_ - 1 - bx, by, buckets_y_ - 1 - by});
    int best = -1;
    double best_d2 = std::numeric_limits<double>::infinity();
    for (int r = 0; r <= max_r; ++r) {
        if (r > 0 && best >= 0) {
            const double lb = ring_lower_bound(x, y, bx, by, r, bucket_size_);
            // Strict: a site exactly at the bound with a lower index could still tie.
            if (lb > 0 && best_d2 < lb * lb) break;
        }
        for_ring(bx, by, r, buckets_x_, buckets_y_, [&](int cx, int cy) {
            const std::size_t b = std::size_t(cy) * std::size_t(buckets_x_) + std::size_t(cx);
            for (int k = bucket_start_[b]; k < bucket_start_[b + 1]; ++k) {
                const int i = bucket_items_[std::size_t(k)];
                const double d2 = dist2(x, y, sites_[std::size_t(i)]);
                if (d2 < best_d2 || (d2 == best_d2 && i < best)) {
                    best_d2 = d2;
                    best = i;
                }
            }
        });
    }
    return best;
}

namespace {

// Keep the part of `poly` nearer to s than to t (the bisector half-plane);
// new edges along the bisector are labelled t.
void clip_by_bisector(CellPolygon& poly, const Point2& s, const Point2& t, int t_index, CellPolygon& scratch) {
    const double nx = t.x - s.x, ny = t.y - s.y;
    const double mx = 0.5 * (s.x + t.x), my = 0.5 * (s.y + t.y);
    auto side = [&](const Point2& p) { return nx * (p.x - mx) + ny * (p.y - my); };  // > 0: nearer t
    const std::size_t n = poly.vertices.size();
    bool any_out = false;
    for (const Point2& p : poly.vertices)
        if (side(p) > 0) {
            any_out = true;
            break;
        }
    if (!any_out) return;
    scratch.vertices.clear();
    scratch.edge_site.clear();
    auto push = [&](const Point2& p, int e) {
        if (!scratch.vertices.empty()) {
            const Point2& q = scratch.vertices.back();
            if (std::abs(q.x - p.x) < 1e-12 && std::abs(q.y - p.y) < 1e-12) {
                scratch.edge_site.back() = e;
                return;
            }
        }
        scratch.vertices.push_back(p);
        scratch.edge_site.push_back(e);
    };
    for (std::size_t k = 0; k < n; ++k) {
        const Point2& a = poly.vertices[k];
        const Point2& b = poly.vertices[(k + 1) % n];
        const double fa = side(a), fb = side(b);
        const bool ina = fa <= 0, inb = fb <= 0;
        if (ina) push(a, poly.edge_site[k]);
        if (ina != inb) {
            const double u = fa / (fa - fb);
            const Point2 p{a.x + u * (b.x - a.x), a.y + u * (b.y - a.y)};
            push(p, ina ? t_index : poly.edge_site[k]);
        }
    }
    if (scratch.vertices.size() > 1) {
        const Point2& f = scratch.vertices.front();
        const Point2& l = scratch.vertices.back();
        if (std::abs(f.x - l.x) < 1e-12 && std::abs(f.y - l.y) < 1e-12) {
            scratch.vertices.pop_back();
            scratch.edge_site.pop_back();
        }
    }
    std::swap(poly, scratch);
}

}  // namespace

CellPolygon SiteIndex::cell(int s) const {
    const Point2 site = sites_[std::size_t(s)];
    CellPolygon poly;
    poly.vertices = {{0, 0}, {extent_x_, 0}, {extent_x_, extent_y_}, {0, extent_y_}};
    poly.edge_site = {-1, -1, -1, -1};
    CellPolygon scratch;
    auto radius = [&] {  // farthest polygon vertex from the site
        double r2 = 0;
        for (const Point2& p : poly.vertices) r2 = std::max(r2, dist2(p.x, p.y, site));
        return std::sqrt(r2);
    };
    double reach = radius();
    const int bx = bucket_x(site.x), by = bucket_y(site.y);
    const int max_r = std::max({bx, buckets_x_ - 1 - bx, by, buckets_y_ - 1 - by});
    for (int r = 0; r <= max_r; ++r) {
        // A site t can cut the cell only if |t - s| < 2 · reach.
        if (r > 0) {
            const double lb = ring_lower_bound(site.x, site.y, bx, by, r, bucket_size_);
            if (lb > 0 && lb >= 2.0 * reach) break;
        }
        for_ring(bx, by, r, buckets_x_, buckets_y_, [&](int cx, int cy) {
            const std::size_t b = std::size_t(cy) * std::size_t(buckets_x_) + std::size_t(cx);
            for (int k = bucket_start_[b]; k < bucket_start_[b + 1]; ++k) {
                const int i = bucket_items_[std::size_t(k)];
                const Point2& t = sites_[std::size_t(i)];
                if (i == s || (t.x == site.x && t.y == site.y)) continue;
                if (dist2(t.x, t.y, site) >= 4.0 * reach * reach) continue;
                clip_by_bisector(poly, site, t, i, scratch);
                if (poly.vertices.empty()) return;
            }
        });
        if (poly.vertices.empty()) break;
        reach = radius();
    }
    return poly;
}

void SiteIndex::spans_of(int s, const CellPolygon& polygon, std::vector<Span>& out) const {
    // The polygon's spans, then both ends settled with exact queries (ties and rounding on the border).
    thread_local std::vector<RowSpan> rough;
    convex_row_spans(polygon.vertices, width_, height_, rough);
    out.clear();
    for (auto [y, x0, x1] : rough) {
        while (x0 <= x1 && nearest(x0, y) != s) ++x0;
        while (x1 >= x0 && nearest(x1, y) != s) --x1;
        if (x0 > x1) continue;
        while (x0 > 0 && nearest(x0 - 1, y) == s) --x0;
        while (x1 < width_ - 1 && nearest(x1 + 1, y) == s) ++x1;
        out.push_back({y, x0, x1});
    }
}

namespace {

// A grid of tiles over the grid rectangle and, per tile, a bound of the
// distance to the nearest site over the tile. That distance is 1-Lipschitz:
// within a tile it is at most its value at the centre plus the half diagonal.
// Tiles are finer than the buckets (half a bucket, and at most 1/32 of the
// map) so the bound stays tight when there are few sites.
struct TileBounds {
    int nx = 0, ny = 0;
    double size = 1;
    std::vector<double> bound;
    int tile_x(double x) const { return std::clamp(int(std::floor(x / size)), 0, nx - 1); }
    int tile_y(double y) const { return std::clamp(int(std::floor(y / size)), 0, ny - 1); }
};

TileBounds tile_bounds(const SiteIndex& index, double bucket_size, double ex, double ey) {
    TileBounds t;
    t.size = std::max(std::min(bucket_size / 2, std::max(ex, ey) / 32), 0.25);
    t.nx = std::max(1, int(std::ceil(ex / t.size)));
    t.ny = std::max(1, int(std::ceil(ey / t.size)));
    t.bound.resize(std::size_t(t.nx) * std::size_t(t.ny));
    parallel_for(0, t.ny, 4, [&](std::int64_t j0, std::int64_t j1) {
        for (std::int64_t j = j0; j < j1; ++j) {
            const double y0 = double(j) * t.size, y1 = std::min(double(j + 1) * t.size, ey);
            for (int i = 0; i < t.nx; ++i) {
                const double x0 = i * t.size, x1 = std::min((i + 1) * t.size, ex);
                const double cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1);
                const Point2& s = index.sites()[std::size_t(index.nearest(cx, cy))];
                t.bound[std::size_t(j) * std::size_t(t.nx) + std::size_t(i)] =
                    std::sqrt(dist2(cx, cy, s)) + 0.5 * std::hypot(x1 - x0, y1 - y0);
            }
        }
    });
    return t;
}

}  // namespace

double SiteIndex::covering_radius() const {
    const TileBounds t = tile_bounds(*this, bucket_size_, extent_x_, extent_y_);
    return std::min(*std::max_element(t.bound.begin(), t.bound.end()), std::hypot(extent_x_, extent_y_));
}

std::vector<double> SiteIndex::cell_radius_bounds() const {
    const TileBounds t = tile_bounds(*this, bucket_size_, extent_x_, extent_y_);
    const double cap = std::hypot(extent_x_, extent_y_);
    std::vector<double> radius(sites_.size());
    parallel_for(0, std::int64_t(sites_.size()), 1024, [&](std::int64_t b, std::int64_t e) {
        for (std::int64_t k = b; k < e; ++k) {
            const Point2 s = sites_[std::size_t(k)];
            double r = t.bound[std::size_t(t.tile_y(s.y)) * std::size_t(t.nx) + std::size_t(t.tile_x(s.x))];
            while (r < cap) {  // grow to the least fixed point
                const int i0 = t.tile_x(s.x - r), i1 = t.tile_x(s.x + r);
                const int j0 = t.tile_y(s.y - r), j1 = t.tile_y(s.y + r);
                double next = r;
                for (int j = j0; j <= j1; ++j) {
                    const double dy = std::max({0.0, j * t.size - s.y, s.y - (j + 1) * t.size});
                    for (int i = i0; i <= i1; ++i) {
                        const double dx = std::max({0.0, i * t.size - s.x, s.x - (i + 1) * t.size});
                        if (dx * dx + dy * dy > r * r) continue;  // tile beyond the disc
                        next = std::max(next, t.bound[std::size_t(j) * std::size_t(t.nx) + std::size_t(i)]);
                    }
                }
                if (next <= r) break;
                r = next;
            }
            radius[std::size_t(k)] = std::min(r, cap);
        }
    });
    return radius;
}

std::vector<std::int32_t> label_grid(const SiteIndex& index) {
    const int w = index.width(), h = index.height();
    std::vector<std::int32_t> labels(std::size_t(w) * std::size_t(h));
    parallel_for(0, h, 8, [&](std::int64_t b, std::int64_t e) {
        for (std::int64_t y = b; y < e; ++y)
            for (int x = 0; x < w; ++x)
                labels[std::size_t(y) * std::size_t(w) + std::size_t(x)] = index.nearest(x, double(y));
    });
    return labels;
}

}  // namespace orogen::relief
