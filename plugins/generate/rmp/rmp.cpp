#include "rmp.hpp"

#include <orogen/relief/graph.hpp>
#include <orogen/relief/voronoi.hpp>

#include <orogen/error.hpp>
#include <orogen/random.hpp>

#include <algorithm>
#include <cmath>
#include <string>

namespace orogen::rmp {

// The cuts, arrangements, spans and sites these methods raise with (libs/relief).
using namespace orogen::relief;

void validate(const RmpParams& p) {
    if (p.peaks.empty()) throw BadInput("rmp: give at least one peak");
    for (const Point2& q : p.peaks)
        if (!(q.x >= 0 && q.x <= 1 && q.y >= 0 && q.y <= 1))
            throw BadInput("rmp: peak (" + std::to_string(q.x) + ", " + std::to_string(q.y) +
                           ") is outside the grid; peaks are grid-relative, 0..1 on both axes");
    if (p.iterations < 1) throw BadInput("rmp: iterations must be at least 1");
    if (p.cones < 1) throw BadInput("rmp: cones must be at least 1");
    if (p.cuts < 1) throw BadInput("rmp: cuts must be at least 1");
    if (p.regions < 1) throw BadInput("rmp: regions must be at least 1");
    if (!(p.decay > 0 && p.decay <= 1)) throw BadInput("rmp: decay must be in (0, 1]");
    if (!(p.jitter >= 0 && p.jitter <= 1)) throw BadInput("rmp: jitter must be in [0, 1]");
    if (!std::isfinite(p.height)) throw BadInput("rmp: height must be a finite number of metres");
}

Point2 to_samples(Point2 r, int width, int height) { return {r.x * (width - 1), r.y * (height - 1)}; }

Point2 peak_vertex(Point2 r, int width, int height) {
    const Point2 s = to_samples(r, width, height);
    return {double(std::lround(s.x)), double(std::lround(s.y))};
}

std::uint64_t iteration_seed(std::uint64_t seed, int iteration) {
    return random::hash(seed, std::uint64_t(iteration), 0x524d50ull /* "RMP" */);
}

double iteration_height(const RmpParams& p, int iteration) { return p.height * std::pow(p.decay, iteration); }

void rmp_voronoi(GridView terrain, const RmpParams& p, std::uint64_t seed, const IterationHook& hook) {
    rmp_voronoi(Window{terrain}, terrain.width, terrain.height, p, seed, hook);
}

void rmp_voronoi(Window window, int width, int height, const RmpParams& p, std::uint64_t seed,
                 const IterationHook& hook) {
    validate(p);
    std::vector<Point2> peaks;
    for (const Point2& q : p.peaks) peaks.push_back(peak_vertex(q, width, height));
    std::vector<SiteIndex::Span> spans;
    for (int k = 0; k < p.iterations; ++k) {
        const std::uint64_t s = iteration_seed(seed, k);
        const std::vector<Point2> sites = random_sites(p.cones, width, height, s);
        const SiteIndex index(sites, width, height);
        std::vector<int> cells;  // distinct cells under the peaks, in peak order
        for (const Point2& q : peaks) {
            const int c = index.nearest(q.x, q.y);
            if (std::find(cells.begin(), cells.end(), c) == cells.end()) cells.push_back(c);
        }
        const double h = iteration_height(p, k);
        for (int c : cells) {
            index.spans_of(c, index.cell(c), spans);
            add_spans(window, spans, float(cell_amount(h, p.jitter, s, c)));
        }
        if (hook) hook(k);
    }
}

void rmp_graph(GridView terrain, const RmpParams& p, std::uint64_t seed, const IterationHook& hook) {
    rmp_graph(Window{terrain}, terrain.width, terrain.height, p, seed, hook);
}

void rmp_graph(Window window, int width, int height, const RmpParams& p, std::uint64_t seed,
               const IterationHook& hook) {
    validate(p);
    const double w = width - 1, h = height - 1;
    if (!(w > 0 && h > 0)) throw BadInput("rmp: the graph method needs a grid of at least 2 × 2 vertices");
    std::vector<Point2> peaks;
    for (const Point2& q : p.peaks) peaks.push_back(peak_vertex(q, width, height));
    // Stamp of the last iteration that raised a vertex: a vertex on the border
    // of two raised faces rises once, by the first face's amount.
    const GridView& t = window.view;
    std::vector<int> stamp(t.size(), -1);
    std::vector<RowSpan> spans;
    const int wx1 = window.x0 + t.width, wy1 = window.y0 + t.height;
    for (int k = 0; k < p.iterations; ++k) {
        const std::uint64_t s = iteration_seed(seed, k);
        const std::vector<Line> cuts = random_cuts(p.cuts, w, h, s);
        const Arrangement g = build_arrangement(cuts, w, h);
        if (int(g.faces.size()) < p.regions)
            throw BadInput("rmp: iteration " + std::to_string(k + 1) + "'s " + std::to_string(p.cuts) +
                           " cuts made only " + std::to_string(g.faces.size()) +
                           " polygons, fewer than regions=" + std::to_string(p.regions) +
                           "; set regions to at most cuts+1 = " + std::to_string(p.cuts + 1) +
                           " (the fewest polygons " + std::to_string(p.cuts) + " cuts can make) or use more cuts");
        std::vector<int> faces;
        for (const Point2& q : peaks) {
            const std::vector<int> order = depth_first_order(g, face_containing(g, q));
            for (std::size_t i = 0; i < order.size() && int(i) < p.regions; ++i)
                if (std::find(faces.begin(), faces.end(), order[i]) == faces.end()) faces.push_back(order[i]);
        }
        const double hk = iteration_height(p, k);
        for (int f : faces) {
            const float amount = float(cell_amount(hk, p.jitter, s, f));
            convex_row_spans(g.polygon(f), width, height, spans);
            for (const RowSpan& sp : spans) {
                if (sp.y < window.y0 || sp.y >= wy1) continue;
                float* row = t.row(sp.y - window.y0);
                int* st = stamp.data() + std::size_t(sp.y - window.y0) * std::size_t(t.width);
                for (int x = std::max(sp.x0, window.x0) - window.x0, x1 = std::min(sp.x1, wx1 - 1) - window.x0; x <= x1;
                     ++x)
                    if (st[x] != k) {
                        st[x] = k;
                        row[x] += amount;
                    }
            }
        }
        if (hook) hook(k);
    }
}

}  // namespace orogen::rmp
