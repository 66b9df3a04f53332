// profiles.cpp — boundary relief: activity fields per feature, composed once
// with saturation and fixed textures (see profiles.hpp).
#include "profiles.hpp"

#include <orogen/error.hpp>
#include <orogen/parallel.hpp>
#include <orogen/random.hpp>

#include <algorithm>
#include <cmath>
#include <functional>

namespace orogen::plates {

namespace {

constexpr double rift_blocks = 3.0;  // fault blocks down each rift flank

// What each texture's random numbers are for.
enum Purpose : std::uint64_t {
    purpose_peaks = 101,
    purpose_fine_peaks,
    purpose_vents,
    purpose_wobble,
    purpose_ridge,
};

double smoothstep(double t) {
    t = std::clamp(t, 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

// Three uniforms in [0, 1) from one hash: 21 bits each.
struct Three {
    double a, b, c;
};
Three three(std::uint64_t bits) {
    constexpr double scale = 1.0 / double(1u << 21);
    return {double(bits & 0x1fffff) * scale, double((bits >> 21) & 0x1fffff) * scale,
            double((bits >> 42) & 0x1fffff) * scale};
}

// Value noise in [−1, 1] on a lattice `spacing` samples apart, smooth (C¹).
double value_noise(double x, double y, double spacing, std::uint64_t seed) {
    const double fx = x / spacing, fy = y / spacing;
    const double ix = std::floor(fx), iy = std::floor(fy);
    const double tx = smoothstep(fx - ix), ty = smoothstep(fy - iy);
    auto at = [&](double i, double j) {
        return 2.0 * random::uniform(seed, std::uint64_t(std::int64_t(i)), std::uint64_t(std::int64_t(j))) - 1.0;
    };
    const double v00 = at(ix, iy), v10 = at(ix + 1, iy), v01 = at(ix, iy + 1), v11 = at(ix + 1, iy + 1);
    return (v00 + tx * (v10 - v00)) + ty * ((v01 + tx * (v11 - v01)) - (v00 + tx * (v10 - v00)));
}

// Gradient (Perlin) noise in about [−0.7, 0.7], lattice 1 apart.
double gradient_noise(double x, double y, std::uint64_t seed) {
    const double ix = std::floor(x), iy = std::floor(y);
    const double fx = x - ix, fy = y - iy;
    // One of 16 unit gradients per lattice point (no trigonometry per sample).
    static constexpr double gx[16] = {1,  0.92388,  0.70711,  0.38268,  0, -0.38268, -0.70711, -0.92388,
                                      -1, -0.92388, -0.70711, -0.38268, 0, 0.38268,  0.70711,  0.92388};
    auto grad = [&](double i, double j, double dx, double dy) {
        const auto k = random::hash(seed, std::uint64_t(std::int64_t(i)), std::uint64_t(std::int64_t(j))) & 15u;
        return gx[k] * dx + gx[(k + 12) & 15u] * dy;  // (cos, sin) = (gx[k], gx[k − 4])
    };
    const double n00 = grad(ix, iy, fx, fy), n10 = grad(ix + 1, iy, fx - 1, fy);
    const double n01 = grad(ix, iy + 1, fx, fy - 1), n11 = grad(ix + 1, iy + 1, fx - 1, fy - 1);
    const double u = fx * fx * fx * (fx * (fx * 6 - 15) + 10), v = fy * fy * fy * (fy * (fy * 6 - 15) + 10);
    const double a = n00 + u * (n10 - n00), b = n01 + u * (n11 - n01);
    return a + v * (b - a);
}

// A profile across a boundary sampled every 1/4 sample, read back with
// linear interpolation (an exp or pow per cell and event is too slow).
class Table {
public:
    Table() = default;
    Table(double lo, double hi, const std::function<double(double)>& f) : lo_(lo), hi_(hi) {
        const int n = int(std::ceil((hi - lo) * per_sample)) + 2;
        values_.resize(std::size_t(n));
        for (int i = 0; i < n; ++i) values_[std::size_t(i)] = f(lo + i / per_sample);
    }
    double operator()(double x) const {
        const double f = std::clamp((x - lo_) * per_sample, 0.0, double(values_.size() - 2));
        const auto i = std::size_t(f);
        const double w = f - double(i);
        return values_[i] + w * (values_[i + 1] - values_[i]);
    }
    double lo() const { return lo_; }
    double hi() const { return hi_; }

private:
    static constexpr double per_sample = 4.0;
    double lo_ = 0.0, hi_ = 0.0;
    std::vector<double> values_;
};

Point2 unit_normal_of(Point2 a, Point2 b) {
    const double dx = b.x - a.x, dy = b.y - a.y;
    const double len = std::hypot(dx, dy);
    if (len == 0.0) return {1.0, 0.0};
    return {-dy / len, dx / len};
}

// A band across segment a–b: its unit `normal`, how far past the ends it
// reaches, its profile across and its taper past the ends.
struct Band {
    Point2 a, b, normal;
    double end_reach;
    const Table& profile;
    const Table& taper;
};

// Add profile(s)·taper(beyond) to every sample of the band s ∈ [profile.lo,
// profile.hi] across segment a–b (s the signed distance along the unit
// `normal`) and u ∈ [−end_reach, len + end_reach] along it; `beyond` is how
// far past an end the sample lies. Rows are walked over the band's exact
// x-interval, so the cost is the band's area, not its bounding box's.
template <typename Op>
void stamp_with(std::vector<float>& field, TileRect window, const Band& band, Op op) {
    const Point2 a = band.a, b = band.b, normal = band.normal;
    const double end_reach = band.end_reach;
    const Table& profile = band.profile;
    const Table& taper = band.taper;
    const double s_lo = profile.lo(), s_hi = profile.hi();
    const double dx = b.x - a.x, dy = b.y - a.y;
    const double len = std::hypot(dx, dy);
    const Point2 t = len > 0.0 ? Point2{dx / len, dy / len} : Point2{-normal.y, normal.x};
    const auto at = [&](double u, double s) {
        return Point2{a.x + u * t.x + s * normal.x, a.y + u * t.y + s * normal.y};
    };
    const Point2 quad[4] = {at(-end_reach, s_lo), at(len + end_reach, s_lo), at(len + end_reach, s_hi),
                            at(-end_reach, s_hi)};
    double ymin = quad[0].y, ymax = quad[0].y;
    for (const Point2& q : quad) ymin = std::min(ymin, q.y), ymax = std::max(ymax, q.y);
    // Only the window's rows and columns; every sample's value is computed from its global position alone.
    const int y0 = std::max(window.y0, int(std::ceil(ymin))), y1 = std::min(window.y1() - 1, int(std::floor(ymax)));
    if (y0 > y1) return;
    parallel_for(y0, y1 + 1, 8, [&](std::int64_t r0, std::int64_t r1) {
        for (std::int64_t yy = r0; yy < r1; ++yy) {
            const double y = double(yy);
            double lo = 1e300, hi = -1e300;  // the band (a convex quad) meets a row in one interval
            for (int i = 0; i < 4; ++i) {
                const Point2 p = quad[i], q = quad[(i + 1) % 4];
                if ((p.y <= y && q.y >= y) || (q.y <= y && p.y >= y)) {
                    if (p.y == q.y) {
                        lo = std::min({lo, p.x, q.x}), hi = std::max({hi, p.x, q.x});
                    } else {
                        const double x = p.x + (y - p.y) * (q.x - p.x) / (q.y - p.y);
                        lo = std::min(lo, x), hi = std::max(hi, x);
                    }
                }
            }
            if (!(lo <= hi)) continue;
            const int x0 = std::max(window.x0, int(std::ceil(lo))), x1 = std::min(window.x1() - 1, int(std::floor(hi)));
            float* row = field.data() + std::size_t(yy - window.y0) * std::size_t(window.width);
            for (int x = x0; x <= x1; ++x) {
                const double px = x - a.x, py = y - a.y;
                const double u = px * t.x + py * t.y;
                const double s = px * normal.x + py * normal.y;
                if (s < s_lo || s > s_hi) continue;
                const double beyond = u < 0.0 ? -u : (u > len ? u - len : 0.0);
                op(row[x - window.x0], float(beyond > 0.0 ? profile(s) * taper(beyond) : profile(s)));
            }
        }
    });
}

void stamp(std::vector<float>& field, TileRect window, Point2 a, Point2 b, Point2 normal, double end_reach,
           const Table& profile, const Table& taper) {
    stamp_with(field, window, {a, b, normal, end_reach, profile, taper}, [](float& v, float d) { v += d; });
}

// The same band, keeping the largest value: order-independent, so repeated
// contacts at one place keep one shape instead of summing into a smear.
void stamp_max(std::vector<float>& field, TileRect window, Point2 a, Point2 b, Point2 normal, double end_reach,
               const Table& profile, const Table& taper) {
    stamp_with(field, window, {a, b, normal, end_reach, profile, taper}, [](float& v, float d) { v = std::max(v, d); });
}

// The tables of one relief: per-contact profiles across each kind of
// boundary (m) and the taper past a segment's ends.
struct Tables {
    Table range, trench, arc, rift, ridge, taper;
};

}  // namespace

ReliefWidths relief_widths(double c) {
    ReliefWidths w;
    w.range_half = 0.8 * c;
    w.peak_spacing = 0.5 * c;
    w.trench_offset = 0.12 * c;
    w.trench_outer = 0.3 * c;
    w.trench_inner = 0.12 * c;
    w.arc_offset = 0.6 * c;
    w.arc_band = 0.2 * c;
    w.vent_spacing = 0.4 * c;
    w.vent_radius = 0.3 * c;
    w.rift_floor = 0.15 * c;
    w.rift_half = 0.6 * c;
    w.ridge_half = std::max(0.08 * c, 1.5);
    w.end_reach = 0.3 * c;
    return w;
}

double saturate(double a, double cap) {
    if (!(cap > 0.0)) return 0.0;
    return cap * -std::expm1(-a / cap);
}

double terrace(double d, double step) {
    if (!(d > 0.0)) return 0.0;
    if (!(step > 0.0)) return d;
    const double q = d / step;
    const double k = std::floor(q), f = q - k;
    constexpr double scarp = 0.25;  // the last quarter of each step is the fault scarp
    constexpr double tilt = 0.2;  // the tread descends 20 % of a step over its width
    const double within =
        f < 1.0 - scarp ? tilt * f / (1.0 - scarp) : tilt + (1.0 - tilt) * smoothstep((f - (1.0 - scarp)) / scarp);
    return step * (k + within);
}

double peak_field(double x, double y, double spacing, double jitter, std::uint64_t seed) {
    const double fx = x / spacing, fy = y / spacing;
    const double ix = std::floor(fx), iy = std::floor(fy);
    double best = 0.0;
    for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
            const double i = ix + di, j = iy + dj;
            const Three u = three(random::hash(seed, std::uint64_t(std::int64_t(i)), std::uint64_t(std::int64_t(j))));
            // Sites in the middle 70 % of their lattice cell: neighbours never merge into one peak.
            const double sx = i + 0.15 + 0.7 * u.a, sy = j + 0.15 + 0.7 * u.b;
            const double d = std::hypot(fx - sx, fy - sy) / 0.95;  // radius 0.95 spacing: 3 × 3 cells suffice
            if (d >= 1.0) continue;
            const double h = 1.0 + jitter * (2.0 * u.c - 1.0);
            best = std::max(best, h * std::pow(1.0 - d, 1.2));  // slightly concave flanks, sharp summits
        }
    return best;
}

double ridged_field(double x, double y, double spacing, std::uint64_t seed) {
    double sum = 0.0, norm = 0.0, amp = 1.0, weight = 1.0, f = 1.0 / spacing;
    for (int octave = 0; octave < 4; ++octave) {
        const double n = gradient_noise(x * f, y * f, random::hash(seed, std::uint64_t(octave)));
        double r = std::clamp(1.0 - 1.5 * std::abs(n), 0.0, 1.0);
        r = r * r * weight;  // sharp crests where the noise crosses zero
        weight = std::clamp(2.0 * r, 0.0, 1.0);  // finer ridges ride on the crests of coarser ones
        sum += amp * r;
        norm += amp;
        amp *= 0.5;
        f *= 2.0;
    }
    return sum / norm;
}

BoundaryRelief::BoundaryRelief(int width, int height, const ReliefShape& shape, std::uint64_t seed)
    : BoundaryRelief(width, height, TileRect{0, 0, width, height}, shape, seed) {}

BoundaryRelief::BoundaryRelief(int width, int height, TileRect window, const ReliefShape& shape, std::uint64_t seed)
    : width_(width), height_(height), window_(window), shape_(shape),
      widths_(relief_widths(std::max(shape.cell, 1e-6))), seed_(seed) {
    if (width < 1 || height < 1) throw BadInput("boundary relief needs a grid of at least 1 × 1 samples");
    if (window.x0 < 0 || window.y0 < 0 || window.width < 1 || window.height < 1 || window.x1() > width ||
        window.y1() > height)
        throw BadInput("boundary relief: the window must lie inside the grid");
}

int BoundaryRelief::vent_margin() const { return int(std::ceil(2.0 * widths_.vent_spacing)) + 2; }

std::vector<float>& BoundaryRelief::field(std::vector<float>& f) {
    if (f.empty()) f.assign(std::size_t(window_.width) * std::size_t(window_.height), 0.0f);
    return f;
}

namespace {

Table taper_table(const ReliefWidths& w) {
    return Table(0.0, w.end_reach, [&](double beyond) { return 1.0 - smoothstep(beyond / w.end_reach); });
}

}  // namespace

void BoundaryRelief::add_range(Point2 a, Point2 b) {
    const ReliefWidths& w = widths_;
    const double h = shape_.range_height;
    // A tent with concave flanks across the contact: the crest on the
    // contact line, the peaks come from the texture at compose time.
    const Table profile(-w.range_half, w.range_half, [&](double s) {
        const double t = 1.0 - std::abs(s) / w.range_half;
        return t > 0.0 ? h * t * t : 0.0;
    });
    stamp(field(range_), window_, a, b, unit_normal_of(a, b), w.end_reach, profile, taper_table(w));
}

void BoundaryRelief::add_subduction(Point2 a, Point2 b, Point2 toward_light) {
    const ReliefWidths& w = widths_;
    Point2 n = unit_normal_of(a, b);
    if (n.x * toward_light.x + n.y * toward_light.y < 0.0) n = {-n.x, -n.y};
    // The trench: a V with a gentle outer wall on the dense plate and a steep
    // inner wall toward the boundary, its floor 0.12 c off the boundary.
    const double st = -w.trench_offset;
    const double depth = shape_.trench_depth;
    const Table trench(st - w.trench_outer, st + w.trench_inner, [&](double s) {
        const double q = s - st;
        const double t = 1.0 - (q < 0.0 ? -q / w.trench_outer : q / w.trench_inner);
        return t > 0.0 ? depth * std::pow(t, 1.5) : 0.0;
    });
    stamp(field(trench_), window_, a, b, n, w.end_reach, trench, taper_table(w));
    // The volcanic line: a band inland whose activity lights up the vents in it.
    const double sa = w.arc_offset, ah = shape_.arc_height;
    const Table arc(sa - w.arc_band, sa + w.arc_band, [&](double s) {
        const double q = (s - sa) / w.arc_band;
        return q * q < 1.0 ? ah * (1.0 - q * q) : 0.0;
    });
    stamp(field(arc_), window_, a, b, n, w.end_reach, arc, taper_table(w));
}

void BoundaryRelief::add_rift(Point2 a, Point2 b) {
    const ReliefWidths& w = widths_;
    const Point2 n = unit_normal_of(a, b);
    const double depth = shape_.rift_depth;
    // How deep (summed, saturated at compose time): the same across the
    // whole rift, fading just outside it.
    const double edge = 0.1 * shape_.cell;
    const Table rift(-w.rift_half - edge, w.rift_half + edge,
                     [&](double s) { return depth * (1.0 - smoothstep((std::abs(s) - w.rift_half) / edge)); });
    stamp(field(rift_), window_, a, b, n, w.end_reach, rift, taper_table(w));
    // Where on the flank (the largest over contacts): 1 on the floor, 0 at
    // the rim; terraced at compose time into three fault blocks.
    const Table flank(-w.rift_half, w.rift_half, [&](double s) {
        return std::clamp((w.rift_half - std::abs(s)) / (w.rift_half - w.rift_floor), 0.0, 1.0);
    });
    stamp_max(field(flank_), window_, a, b, n, w.end_reach, flank, taper_table(w));
    const double rh = shape_.ridge_height;
    const Table ridge(-w.ridge_half, w.ridge_half, [&](double s) {
        const double t = 1.0 - std::abs(s) / w.ridge_half;
        return t > 0.0 ? rh * t : 0.0;
    });
    stamp(field(ridge_), window_, a, b, n, w.end_reach, ridge, taper_table(w));
}

BoundaryRelief::Vents BoundaryRelief::vents() const {
    // Vents on a jittered lattice (one per lattice cell, in its middle 80 %);
    // a vent erupts as much as the arc band's saturated activity at its site.
    Vents v;
    v.spacing = widths_.vent_spacing;
    v.nx = int(std::ceil(width_ / v.spacing)) + 2;  // lattice cells −1 … nx − 2
    v.ny = int(std::ceil(height_ / v.spacing)) + 2;
    v.vents.resize(std::size_t(v.nx) * std::size_t(v.ny));
    if (arc_.empty()) return v;
    const std::uint64_t seed = random::hash(seed_, purpose_vents);
    const double cap = shape_.saturation * shape_.arc_height;
    for (int cj = -1; cj < v.ny - 1; ++cj)
        for (int ci = -1; ci < v.nx - 1; ++ci) {
            const Three u = three(random::hash(seed, std::uint64_t(std::int64_t(ci)), std::uint64_t(std::int64_t(cj))));
            Vent& vent = v.at(ci, cj);
            vent.x = (ci + 0.1 + 0.8 * u.a) * v.spacing;
            vent.y = (cj + 0.1 + 0.8 * u.b) * v.spacing;
            vent.radius = widths_.vent_radius * (0.8 + 0.4 * u.c);
            const int px = int(std::lround(vent.x)), py = int(std::lround(vent.y));
            // A vent outside the window stays dormant here: no sample apply() composes reaches it.
            if (px < window_.x0 || py < window_.y0 || px >= window_.x1() || py >= window_.y1()) continue;
            const float act =
                arc_[std::size_t(py - window_.y0) * std::size_t(window_.width) + std::size_t(px - window_.x0)];
            if (!(act > 0.0f)) continue;
            const double u_height =
                random::uniform(seed, std::uint64_t(std::int64_t(ci)), std::uint64_t(std::int64_t(cj)), 1u);
            vent.height = saturate(act, cap) * (1.0 + shape_.jitter * (2.0 * u_height - 1.0));
        }
    return v;
}

float BoundaryRelief::relief_at(int x, int y, const Vents& vents) const {
    const std::size_t i = std::size_t(y - window_.y0) * std::size_t(window_.width) + std::size_t(x - window_.x0);
    const double sat = shape_.saturation;
    const double jitter = shape_.jitter;
    const ReliefWidths& w = widths_;
    double dh = 0.0;
    if (!range_.empty() && range_[i] > 0.0f) {
        const double r = saturate(range_[i], sat * shape_.range_height);
        // Two octaves of peaks over a floor: the range's per-peak heights.
        // Peaks with their own heights (the RMP's per-cell heights), carved by ridges and valleys.
        const double peaks = 0.35 + 0.65 * peak_field(x, y, w.peak_spacing, jitter, random::hash(seed_, purpose_peaks));
        const double ridges = ridged_field(x, y, w.peak_spacing, random::hash(seed_, purpose_fine_peaks));
        const double texture = peaks * (0.45 + 0.8 * ridges);
        dh += r * texture;
    }
    if (!trench_.empty() && trench_[i] > 0.0f) dh -= saturate(trench_[i], sat * shape_.trench_depth);
    if (!arc_.empty()) {
        const double cap = sat * shape_.arc_height;
        dh += 0.2 * saturate(arc_[i], cap);  // the arc's low swell the volcanoes stand on
        // Volcanoes (see vents()): the tallest cone over a sample wins.
        const double fx = x / vents.spacing, fy = y / vents.spacing;
        const int ix = int(std::floor(fx)), iy = int(std::floor(fy));
        double best = 0.0;
        for (int cj = iy - 1; cj <= iy + 1; ++cj)
            for (int ci = ix - 1; ci <= ix + 1; ++ci) {
                if (ci < -1 || cj < -1 || ci > vents.nx - 2 || cj > vents.ny - 2) continue;
                const Vent& v = vents.at(ci, cj);
                if (!(v.height > 0.0)) continue;
                const double d = std::hypot(x - v.x, y - v.y) / v.radius;
                if (d >= 1.0) continue;
                // Concave flanks steepening to the summit, and a small crater.
                double cone = (1.0 - d) * (1.0 - d);
                if (d < 0.12) cone -= 0.15 * (1.0 - d / 0.12) * 0.88 * 0.88;
                best = std::max(best, v.height * cone);
            }
        dh += best;
    }
    if (!rift_.empty() && rift_[i] > 0.0f && flank_[i] > 0.0f) {
        // Wobble the fault scarps along strike: real faults are segmented, not offset copies of the axis.
        const double t = std::clamp(
            double(flank_[i]) + 0.08 * value_noise(x, y, 0.4 * shape_.cell, random::hash(seed_, purpose_wobble)), 0.0,
            1.0);
        const double valley = saturate(rift_[i], sat * shape_.rift_depth) * terrace(t * rift_blocks, 1.0) / rift_blocks;
        double ridge = 0.0;
        if (!ridge_.empty() && ridge_[i] > 0.0f) {
            const double rough = 0.6 +
                0.5 * peak_field(x, y, std::max(2.0, 0.15 * shape_.cell), jitter, random::hash(seed_, purpose_ridge)) /
                    (1.0 + jitter);
            ridge = std::min(saturate(ridge_[i], sat * shape_.ridge_height) * rough, valley);  // never above the land
        }
        dh += ridge - valley;
    }
    return float(dh);
}

void BoundaryRelief::apply(GridView terrain, GridView* uplift) const {
    if (terrain.width != window_.width || terrain.height != window_.height)
        throw BadInput("boundary relief: the terrain grid must be the size the relief was accumulated on");
    apply(terrain, window_, uplift);
}

void BoundaryRelief::apply(GridView terrain, TileRect at, GridView* uplift) const {
    if (terrain.width != at.width || terrain.height != at.height ||
        (uplift && (uplift->width != at.width || uplift->height != at.height)))
        throw BadInput("boundary relief: the terrain grid must be the size of the rectangle it covers");
    const int m = vent_margin();
    const bool inside = at.x0 >= (window_.x0 > 0 ? window_.x0 + m : 0) &&
        at.y0 >= (window_.y0 > 0 ? window_.y0 + m : 0) &&
        at.x1() <= (window_.x1() < width_ ? window_.x1() - m : width_) &&
        at.y1() <= (window_.y1() < height_ ? window_.y1() - m : height_);
    if (!inside) throw BadInput("boundary relief: the rectangle to compose reaches too near the window's edge");
    if (range_.empty() && trench_.empty() && arc_.empty() && rift_.empty()) return;
    const Vents vent_lattice = vents();
    parallel_for(0, at.height, 4, [&](std::int64_t r0, std::int64_t r1) {
        for (std::int64_t y = r0; y < r1; ++y) {
            float* row = terrain.row(int(y));
            float* urow = uplift ? uplift->row(int(y)) : nullptr;
            for (int x = 0; x < at.width; ++x) {
                const float dh = relief_at(at.x0 + x, at.y0 + int(y), vent_lattice);
                if (dh == 0.0f) continue;
                row[x] += dh;
                if (urow) urow[x] += dh;
            }
        }
    });
}

std::vector<float> BoundaryRelief::relief() const {
    std::vector<float> out(std::size_t(window_.width) * std::size_t(window_.height), 0.0f);
    GridView view{out.data(), window_.width, window_.height, 1.0};
    apply(view);
    return out;
}

}  // namespace orogen::plates
