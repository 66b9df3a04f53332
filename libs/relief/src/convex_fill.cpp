#include <orogen/relief/convex_fill.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace orogen::relief {

void convex_row_spans(std::span<const Point2> v, int width, int height, std::vector<RowSpan>& out) {
    constexpr double eps = 1e-7;  // samples: a vertex on the border belongs to the polygon
    out.clear();
    if (v.empty()) return;
    double ymin = v[0].y, ymax = v[0].y;
    for (const Point2& p : v) {
        ymin = std::min(ymin, p.y);
        ymax = std::max(ymax, p.y);
    }
    const int y0 = std::max(0, int(std::ceil(ymin - eps)));
    const int y1 = std::min(height - 1, int(std::floor(ymax + eps)));
    const std::size_t n = v.size();
    for (int y = y0; y <= y1; ++y) {
        double xl = std::numeric_limits<double>::infinity(), xr = -xl;
        for (std::size_t k = 0; k < n; ++k) {
            const Point2& a = v[k];
            const Point2& b = v[(k + 1) % n];
            const double lo = std::min(a.y, b.y), hi = std::max(a.y, b.y);
            if (y < lo - eps || y > hi + eps) continue;
            if (hi - lo < 1e-12) {
                xl = std::min({xl, a.x, b.x});
                xr = std::max({xr, a.x, b.x});
                continue;
            }
            const double u = std::clamp((double(y) - a.y) / (b.y - a.y), 0.0, 1.0);
            const double x = a.x + u * (b.x - a.x);
            xl = std::min(xl, x);
            xr = std::max(xr, x);
        }
        const int x0 = std::max(0, int(std::ceil(xl - eps)));
        const int x1 = std::min(width - 1, int(std::floor(xr + eps)));
        if (x0 <= x1) out.push_back({y, x0, x1});
    }
}

void add_spans(Window w, std::span<const RowSpan> spans, float amount, GridView* also) {
    const int wx1 = w.x0 + w.view.width, wy1 = w.y0 + w.view.height;
    for (const RowSpan& sp : spans) {
        if (sp.y < w.y0 || sp.y >= wy1) continue;
        const int x0 = std::max(sp.x0, w.x0), x1 = std::min(sp.x1, wx1 - 1);
        float* row = w.view.row(sp.y - w.y0);
        for (int x = x0; x <= x1; ++x) row[x - w.x0] += amount;
        if (also) {
            float* urow = also->row(sp.y - w.y0);
            for (int x = x0; x <= x1; ++x) urow[x - w.x0] += amount;
        }
    }
}

}  // namespace orogen::relief
