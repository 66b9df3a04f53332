// Figures of the heights and their derivatives: slopes, hypsometry, pits, local relief, curvature.
#include "detail.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <numbers>
#include <string>

namespace orogen::analysis::detail {

namespace {

std::string too_small(const Terrain& t, std::string_view need) {
    return "the terrain (" + std::to_string(t.width) + "x" + std::to_string(t.height) + ") " + std::string(need);
}

/// dz/ds along one axis at sample i as numpy.gradient: central where both neighbours are measured,
/// one-sided where only one is (the edges, the rims of holes); NaN where neither is.
double derivative(const Terrain& t, std::size_t i, bool has_before, std::size_t before, bool has_after,
                  std::size_t after) {
    const bool b = has_before && t.valid[before], a = has_after && t.valid[after];
    if (a && b) return (t.z[after] - t.z[before]) / (2.0 * t.cell);
    if (a) return (t.z[after] - t.z[i]) / t.cell;
    if (b) return (t.z[i] - t.z[before]) / t.cell;
    return std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

void measure_slopes(const Terrain& t, Figures& f) {
    std::vector<double> slopes;
    slopes.reserve(t.samples);
    const std::size_t w = std::size_t(t.width);
    for (int y = 0; y < t.height; ++y)
        for (int x = 0; x < t.width; ++x) {
            const std::size_t i = t.at(x, y);
            if (!t.valid[i]) continue;
            const double gx = derivative(t, i, x > 0, i - 1, x + 1 < t.width, i + 1);
            const double gy = derivative(t, i, y > 0, i - w, y + 1 < t.height, i + w);
            if (std::isnan(gx) || std::isnan(gy)) continue;
            slopes.push_back(std::atan(std::hypot(gx, gy)) * 180.0 / std::numbers::pi);
        }
    if (slopes.empty()) {
        const std::string why = too_small(t, "has no sample with a measured neighbour along both axes");
        for (FigureId id : {FigureId::slope_mean, FigureId::slope_median, FigureId::slope_p90, FigureId::steeper_30,
                            FigureId::steeper_40})
            f[id].why_not = why;
        return;
    }
    f.slope_histogram.assign(90, 0.0);
    double sum = 0.0;
    std::size_t above30 = 0, above40 = 0;
    for (double s : slopes) {
        sum += s;
        above30 += s > 30.0;
        above40 += s > 40.0;
        f.slope_histogram[std::size_t(std::clamp(int(s), 0, 89))] += 1.0;
    }
    const double n = double(slopes.size());
    for (double& b : f.slope_histogram) b /= n;
    f[FigureId::slope_mean].value = sum / n;
    f[FigureId::slope_median].value = percentile(slopes, 50.0);
    f[FigureId::slope_p90].value = percentile(slopes, 90.0);
    f[FigureId::steeper_30].value = 100.0 * double(above30) / n;
    f[FigureId::steeper_40].value = 100.0 * double(above40) / n;
}

void measure_hypsometry(const Terrain& t, Figures& f) {
    const double relief = t.maximum - t.minimum;
    if (!(relief > 0.0)) {
        f[FigureId::hypsometric_integral].why_not =
            "the terrain is flat (no relief between its lowest and highest sample)";
        return;
    }
    double sum = 0.0;
    std::vector<double> relative;
    relative.reserve(t.samples);
    for (std::size_t i = 0; i < t.size(); ++i)
        if (t.valid[i]) {
            sum += t.z[i];
            relative.push_back((t.z[i] - t.minimum) / relief);
        }
    f[FigureId::hypsometric_integral].value = (sum / double(t.samples) - t.minimum) / relief;
    std::sort(relative.begin(), relative.end());
    f.hypsometric_area.resize(101);
    for (int k = 0; k <= 100; ++k) {
        const auto first = std::lower_bound(relative.begin(), relative.end(), k / 100.0);
        f.hypsometric_area[std::size_t(k)] = double(relative.end() - first) / double(relative.size());
    }
}

void measure_pits(const Terrain& t, Figures& f) {
    if (t.width < 3 || t.height < 3) {
        f[FigureId::pits].why_not = too_small(t, "has no interior sample (needs at least 3x3)");
        return;
    }
    std::size_t interior = 0, pits = 0;
    const std::ptrdiff_t w = t.width;
    for (int y = 1; y + 1 < t.height; ++y)
        for (int x = 1; x + 1 < t.width; ++x) {
            const std::size_t i = t.at(x, y);
            bool all_valid = true, lowest = true;
            for (std::ptrdiff_t dy = -1; dy <= 1; ++dy)
                for (std::ptrdiff_t dx = -1; dx <= 1; ++dx) {
                    if (dx == 0 && dy == 0) continue;
                    const std::size_t j = std::size_t(std::ptrdiff_t(i) + dy * w + dx);
                    all_valid = all_valid && t.valid[j];
                    lowest = lowest && t.z[i] < t.z[j];
                }
            if (!t.valid[i] || !all_valid) continue;
            ++interior;
            pits += lowest;
        }
    if (interior == 0) {
        f[FigureId::pits].why_not = "no interior sample has all 8 neighbours measured";
        return;
    }
    f[FigureId::pits].value = 100.0 * double(pits) / double(interior);
}

namespace {

/// Sliding maximum (or minimum, `sign` = −1) over [i − r, i + r] clipped to the line, with nodata as
/// −∞ (+∞): a monotonic deque, O(n) for any radius.
void sliding_extreme(const double* in, double* out, std::size_t n, std::size_t stride, std::size_t r, double sign,
                     std::deque<std::size_t>& q) {
    q.clear();
    for (std::size_t j = 0; j < n + r; ++j) {
        if (j < n) {
            while (!q.empty() && sign * in[q.back() * stride] <= sign * in[j * stride]) q.pop_back();
            q.push_back(j);
        }
        if (j < r) continue;
        const std::size_t c = j - r;
        while (q.front() + r < c) q.pop_front();
        out[c * stride] = in[q.front() * stride];
    }
}

}  // namespace

void measure_relief(const Terrain& t, const Options& o, Figures& f) {
    const double across = double(std::min(t.width, t.height) - 1) * t.cell;
    if (across < 2.0 * o.relief_radius) {
        char why[160];
        std::snprintf(why, sizeof why, "is %.2f km across, less than the %.2f km window", across / 1000.0,
                      2.0 * o.relief_radius / 1000.0);
        f[FigureId::local_relief].why_not = too_small(t, why);
        return;
    }
    const std::size_t r = std::size_t(std::max(1.0, std::round(o.relief_radius / t.cell)));
    const std::size_t w = std::size_t(t.width), h = std::size_t(t.height);
    constexpr double inf = std::numeric_limits<double>::infinity();
    std::vector<double> hi(t.size()), lo(t.size()), tmp(t.size());
    for (std::size_t i = 0; i < t.size(); ++i) hi[i] = t.valid[i] ? t.z[i] : -inf, lo[i] = t.valid[i] ? t.z[i] : inf;
    std::deque<std::size_t> q;
    for (auto [field, sign] : {std::pair{&hi, 1.0}, std::pair{&lo, -1.0}}) {
        for (std::size_t y = 0; y < h; ++y)
            sliding_extreme(field->data() + y * w, tmp.data() + y * w, w, 1, r, sign, q);
        for (std::size_t x = 0; x < w; ++x) sliding_extreme(tmp.data() + x, field->data() + x, h, w, r, sign, q);
    }
    double sum = 0.0;
    for (std::size_t i = 0; i < t.size(); ++i)
        if (t.valid[i]) sum += hi[i] - lo[i];
    f[FigureId::local_relief].value = sum / double(t.samples);
}

void measure_curvature(const Terrain& t, Figures& f) {
    double sum = 0.0, sum2 = 0.0;
    std::size_t n = 0;
    const std::size_t w = std::size_t(t.width);
    const double c2 = t.cell * t.cell;
    for (int y = 1; y + 1 < t.height; ++y)
        for (int x = 1; x + 1 < t.width; ++x) {
            const std::size_t i = t.at(x, y);
            if (!t.valid[i] || !t.valid[i - 1] || !t.valid[i + 1] || !t.valid[i - w] || !t.valid[i + w]) continue;
            const double laplacian = (t.z[i - 1] + t.z[i + 1] + t.z[i - w] + t.z[i + w] - 4.0 * t.z[i]) / c2;  // 1/m
            sum += laplacian;
            sum2 += laplacian * laplacian;
            ++n;
        }
    if (n < 2) {
        f[FigureId::curvature_spread].why_not =
            too_small(t, "has fewer than 2 interior samples with 4 measured neighbours");
        return;
    }
    const double mean = sum / double(n);
    const double variance = std::max(0.0, (sum2 - double(n) * mean * mean) / double(n));
    f[FigureId::curvature_spread].value = 1000.0 * std::sqrt(variance);  // 1/m → 1/km
}

}  // namespace orogen::analysis::detail
