// Figures of the valley bottoms along the channels (cells draining more than Options::channel_area, on
// the drainage routing of drainage.cpp): channel curvature, the mean Laplacian of those that slope more
// than Options::valley_min_slope by central differences (the channels among hillslopes: the flats of
// floodplains and lakes would dilute how sharp the bottoms are); valley width, where the median
// cross-section of all of them stands Options::valley_rise above the river (the floodplains count:
// they are the widest floors); and how fast that width grows with the drainage area.
// tools/figures/texture_figures.py measured the first two first, with D8 on the unfilled heights: every pit
// stopped the area there, so it saw only the channels above the first pit, about half of them and none
// draining more than ~10 km² (the widest valleys).
#include "detail.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>

namespace orogen::analysis::detail {

namespace {

struct ValleyCell {
    std::size_t index;
    bool across_x;  ///< the section runs east–west (the river runs more north–south than east–west)
    double area;  ///< m²
};

std::string degrees(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g°", v);
    return text;
}

/// The median height (m) above the river of the section's two samples d cells to either side, d = 0 … reach.
std::vector<double> valley_section(const Terrain& t, std::span<const ValleyCell> cells, int reach) {
    std::vector<double> section(std::size_t(reach) + 1, 0.0);
    if (cells.empty()) return section;
    std::vector<double> above(cells.size());
    const std::size_t w = std::size_t(t.width);
    for (int d = 1; d <= reach; ++d) {
        for (std::size_t c = 0; c < cells.size(); ++c) {
            const std::size_t i = cells[c].index, step = (cells[c].across_x ? 1 : w) * std::size_t(d);
            above[c] = 0.5 * (t.z[i - step] + t.z[i + step]) - t.z[i];
        }
        section[std::size_t(d)] = percentile(above, 50.0);
    }
    return section;
}

/// Twice the distance (m) at which `section` first stands `rise` above the river, linear between samples;
/// NaN when it stays below.
double width_at_rise(std::span<const double> section, double cell, double rise) {
    for (std::size_t d = 1; d < section.size(); ++d)
        if (section[d] >= rise) {
            const double below = section[d - 1], above = section[d];
            return 2.0 * cell * (double(d - 1) + (rise - below) / (above - below));
        }
    return std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

void measure_valleys(const Terrain& t, const Options& o, std::span<const double> area, Figures& f) {
    const std::size_t w = std::size_t(t.width);
    const double c2 = t.cell * t.cell, steep = std::tan(o.valley_min_slope * std::numbers::pi / 180.0);
    const int reach = o.valley_reach;
    double curvature = 0.0;
    std::size_t channels = 0;
    std::vector<ValleyCell> sections;  // the channel cells with a whole section on both sides
    for (int y = 1; y + 1 < t.height; ++y)
        for (int x = 1; x + 1 < t.width; ++x) {
            const std::size_t i = t.at(x, y);
            if (!t.valid[i] || !(area[i] > o.channel_area)) continue;
            if (!t.valid[i - 1] || !t.valid[i + 1] || !t.valid[i - w] || !t.valid[i + w]) continue;
            const double gx = (t.z[i + 1] - t.z[i - 1]) / (2.0 * t.cell),
                         gy = (t.z[i + w] - t.z[i - w]) / (2.0 * t.cell);
            if (std::hypot(gx, gy) > steep) {
                curvature += (t.z[i - 1] + t.z[i + 1] + t.z[i - w] + t.z[i + w] - 4.0 * t.z[i]) / c2;  // 1/m
                ++channels;
            }
            // Across the river: along the axis on which the heights change less.
            const bool across_x = std::abs(gx) <= std::abs(gy);
            if (across_x ? x < reach || x + reach >= t.width : y < reach || y + reach >= t.height) continue;
            bool whole = true;
            const std::size_t step = across_x ? 1 : w;
            for (int d = 1; d <= reach && whole; ++d)
                whole = t.valid[i - step * std::size_t(d)] && t.valid[i + step * std::size_t(d)];
            if (whole) sections.push_back({i, across_x, area[i]});
        }
    char text[160];
    if (channels == 0) {
        std::snprintf(text, sizeof text, "no channel cell (draining more than %g km²) slopes more than %s",
                      o.channel_area / 1e6, degrees(o.valley_min_slope).c_str());
        f[FigureId::channel_curvature].why_not = text;
    } else {
        f[FigureId::channel_curvature].value = 1000.0 * curvature / double(channels);  // 1/m → 1/km
    }
    if (sections.empty()) {
        std::snprintf(text, sizeof text,
                      "no channel cell (draining more than %g km²) has %d measured samples on both sides across it",
                      o.channel_area / 1e6, reach);
        f[FigureId::valley_width].why_not = text;
        f[FigureId::valley_widening].why_not = text;
        return;
    }
    f.valley_section = valley_section(t, sections, reach);
    f[FigureId::valley_width].value = width_at_rise(f.valley_section, t.cell, o.valley_rise);
    if (std::isnan(f[FigureId::valley_width].value)) {
        std::snprintf(text, sizeof text,
                      "the valleys are wider than %g m: %g m from the river they stand %.1f m above it",
                      2.0 * reach * t.cell, reach * t.cell, f.valley_section.back());
        f[FigureId::valley_width].why_not = text;
    }

    // Width against drainage area: the same section and rise over the channel cells in each bin of
    // log10 A (4 bins a decade), bins of fewer than 30 cells dropped.
    constexpr int per_decade = 4;
    constexpr std::size_t min_count = 30;
    std::vector<std::vector<ValleyCell>> bins;
    int first = 0;
    for (const auto& c : sections) {
        const int b = int(std::floor(std::log10(c.area) * per_decade));
        if (bins.empty()) first = b;
        if (b < first) {
            bins.insert(bins.begin(), std::size_t(first - b), {});
            first = b;
        }
        if (std::size_t(b - first) >= bins.size()) bins.resize(std::size_t(b - first) + 1);
        bins[std::size_t(b - first)].push_back(c);
    }
    for (std::size_t b = 0; b < bins.size(); ++b) {
        if (bins[b].size() < min_count) continue;
        const double width = width_at_rise(valley_section(t, bins[b], reach), t.cell, o.valley_rise);
        if (std::isnan(width)) continue;
        f.valley_widths.x.push_back(std::pow(10.0, (double(first) + double(b) + 0.5) / per_decade));
        f.valley_widths.y.push_back(width);
        f.valley_widths.count.push_back(bins[b].size());
    }
    constexpr std::size_t min_bins = 3;
    if (f.valley_widths.x.size() < min_bins) {
        std::snprintf(text, sizeof text,
                      "the widths of %zu quarter decades of drainage area are measured (%zu or more cells each); "
                      "the fit needs %zu: the terrain's rivers are too short",
                      f.valley_widths.x.size(), min_count, min_bins);
        f[FigureId::valley_widening].why_not = text;
        return;
    }
    std::vector<double> la, lw;
    for (std::size_t b = 0; b < f.valley_widths.x.size(); ++b) {
        la.push_back(std::log(f.valley_widths.x[b]));
        lw.push_back(std::log(f.valley_widths.y[b]));
    }
    f.valley_widths_fit = fit_line(la, lw);
    f[FigureId::valley_widening].value = f.valley_widths_fit.slope;
}

}  // namespace orogen::analysis::detail
