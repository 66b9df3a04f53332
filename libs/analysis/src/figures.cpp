// The figure table (one description for the JSON report, the terminal table and `orogen help`) and
// measure(), which prepares the terrain once and hands it to each group of figures.
#include "detail.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace orogen::analysis {

namespace {

using enum FigureId;

// The definitions are those of shared/realism/README.md and terrain_stats.py for the figures it prints
// (slopes, HI, β, pits, θ, network share); the others are defined here and in docs/analysis.md.
constexpr FigureInfo table[] = {
    {slope_mean, "slope_mean", "mean slope", "°",
     "mean over every sample of atan|grad z|, grad z by central differences in metres (one-sided at the "
     "edges and beside nodata, as numpy.gradient)",
     "Strahler 1950, Am. J. Sci. 248:673 (slope frequency distributions)", 1},
    {slope_median, "slope_median", "median slope", "°", "median of the slopes defined as for the mean slope",
     "Strahler 1950, Am. J. Sci. 248:673", 1},
    {slope_p90, "slope_p90", "p90 slope", "°",
     "90th percentile of the slopes (linear interpolation between order statistics, as numpy.percentile)",
     "Strahler 1950, Am. J. Sci. 248:673", 1},
    {steeper_30, "steeper_30", ">30° area", "%", "share of the samples whose slope exceeds 30°",
     "Montgomery & Brandon 2002, Earth Planet. Sci. Lett. 201:481 (threshold hillslopes)", 1},
    {steeper_40, "steeper_40", ">40° area", "%", "share of the samples whose slope exceeds 40°",
     "Montgomery & Brandon 2002, Earth Planet. Sci. Lett. 201:481 (threshold hillslopes)", 1},
    {hypsometric_integral, "hypsometric_integral", "hypsometric int.", "",
     "(mean − min) / (max − min) of the heights, the elevation–relief ratio, equal to the area under the "
     "hypsometric curve",
     "Strahler 1952, Geol. Soc. Am. Bull. 63:1117; Pike & Wilson 1971, Geol. Soc. Am. Bull. 82:1079", 3},
    {spectral_exponent, "spectral_exponent", "spectral β", "",
     "−slope of the least-squares line of ln P against ln k, P the radially averaged power spectrum of the "
     "mean-removed, Hann-windowed top-left square crop (integer radial bins), k = 4 … n/4 cycles per side",
     "Perron, Kirchner & Dietrich 2008, J. Geophys. Res. 113:F04003", 2},
    {pits, "pits", "pits", "%",
     "share of the interior samples lower than all 8 neighbours (closed one-cell depressions)",
     "Lindsay & Creed 2005, Hydrol. Process. 19:3113 (depressions in DEMs)", 2},
    {concavity, "concavity", "concavity θ", "",
     "−slope of the least-squares line of ln S against ln A over channel cells (A > 1 km², S > 1e-4) on the "
     "priority-flood-filled DEM (ε = 1e-4·cell), D8 area A and slope S to the steepest receiver",
     "Flint 1974, Water Resour. Res. 10:969; Barnes, Lehman & Mulla 2014, Comput. Geosci. 62:117; "
     "O'Callaghan & Mark 1984",
     2},
    {steepness, "steepness", "k_sn", "m^0.9",
     "normalised channel steepness: geometric mean of S·A^0.45 over the channel cells of the concavity "
     "(reference concavity 0.45)",
     "Wobus et al. 2006, Geol. Soc. Am. Spec. Pap. 398:55; Kirby & Whipple 2012, J. Struct. Geol. 44:54", 1},
    {hack_exponent, "hack_exponent", "Hack h", "",
     "slope of the least-squares line of ln L against ln A over the channel cells, L the longest D8 flow "
     "path upstream of the cell (m)",
     "Hack 1957, USGS Prof. Pap. 294-B", 2},
    {drainage_density, "drainage_density", "drainage dens.", "1/km",
     "total D8 length of the network (cells draining more than 0.1 km², each to its receiver) over the "
     "measured area",
     "Horton 1945, Geol. Soc. Am. Bull. 56:275; Tucker et al. 2001, Water Resour. Res. 37:2671", 2},
    {network_share, "network_share", "net. >0.1km²", "%",
     "share of the samples draining more than 0.1 km² (depends on the cell size)",
     "terrain_stats.py (chan>0.1km2), shared/realism", 1},
    {local_relief, "local_relief", "relief 1 km", "m",
     "mean over every sample of max − min of the heights within 1 km east–west and north–south (a 2 km "
     "square window, clipped at the edges)",
     "Ahnert 1970, Am. J. Sci. 268:243; Montgomery & Brandon 2002, Earth Planet. Sci. Lett. 201:481", 0},
    {hillslope_length, "hillslope_length", "hillslope L", "m",
     "mean D8 flow distance from each sample off the network (A ≤ 0.1 km²) down to the first network cell",
     "Roering, Perron & Kirchner 2007, Earth Planet. Sci. Lett. 264:245; Grieve et al. 2016, Earth Surf. "
     "Dynam. 4:627",
     0},
    {curvature_spread, "curvature_spread", "curvature sd", "1/km",
     "standard deviation of the Laplacian curvature d²z/dx² + d²z/dy² (5-point stencil) over interior samples",
     "Zevenbergen & Thorne 1987, Earth Surf. Proc. Landf. 12:47; Hurst et al. 2012, J. Geophys. Res. "
     "117:F02017",
     2},
    {channel_sinuosity, "channel_sinuosity", "sinuosity", "",
     "mean over the channel cells (A > 1 km²) of the D8 flow length along the next 1 km of flow path over the "
     "straight distance between its ends (D8 reads a straight channel as 1.00–1.08, by its direction)",
     "Mueller 1968, Ann. Assoc. Am. Geogr. 58:371; Schumm 1963, Geol. Soc. Am. Bull. 74:1089", 3},
    {channel_curvature, "channel_curvature", "channel curv.", "1/km",
     "mean Laplacian curvature (5-point stencil) of the channel cells (A > 1 km² on the routing of the "
     "concavity) that slope more than 6° by central differences: how sharp the valley bottoms are (a V of "
     "30° walls at 30 m: 38 /km; a floor or a rounded bottom: less)",
     "Zevenbergen & Thorne 1987, Earth Surf. Proc. Landf. 12:47; Lashermes, Foufoula-Georgiou & Dietrich "
     "2007, Geophys. Res. Lett. 34:L23S04 (valley bottoms by curvature)",
     1},
    {valley_width, "valley_width", "valley width", "m",
     "twice the distance at which the median cross-section of the channel cells (A > 1 km², any slope: "
     "floodplains count) stands 10 m above the river (linear between samples); each section runs along x "
     "or y, whichever the central difference changes less on (across the river), and averages the two "
     "sides d = 1 … 8 samples out",
     "Montgomery & Gran 2001, Water Resour. Res. 37:1841 (width downstream); Whipple 2004, Annu. Rev. "
     "Earth Planet. Sci. 32:151",
     0},
    {valley_widening, "valley_widening", "widening b", "",
     "slope of the least-squares line of ln W against ln A, W the valley width as above over the channel "
     "cells in each quarter decade of drainage area A with 30 cells or more (at least 3 such bins): how "
     "fast valleys widen downstream (W ∝ A^b)",
     "Montgomery & Gran 2001, Water Resour. Res. 37:1841; Leopold & Maddock 1953, USGS Prof. Pap. 252 "
     "(hydraulic geometry)",
     2},
};
static_assert(std::size(table) == figure_count, "one row per FigureId");

constexpr bool in_order() {
    for (std::size_t i = 0; i < figure_count; ++i)
        if (std::size_t(table[i].id) != i) return false;
    return true;
}
static_assert(in_order(), "table rows in FigureId order");

}  // namespace

std::span<const FigureInfo> figure_table() { return table; }

const FigureInfo& info(FigureId id) { return table[std::size_t(id)]; }

std::optional<FigureId> find_figure(std::string_view key) {
    for (const auto& row : table)
        if (row.key == key) return row.id;
    return std::nullopt;
}

namespace detail {

LineFit fit_line(std::span<const double> x, std::span<const double> y) {
    LineFit fit;
    fit.points = x.size();
    if (x.size() < 2) return fit;
    const double n = double(x.size());
    double mx = 0.0, my = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) mx += x[i], my += y[i];
    mx /= n, my /= n;
    double sxy = 0.0, sxx = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) sxy += (x[i] - mx) * (y[i] - my), sxx += (x[i] - mx) * (x[i] - mx);
    if (sxx <= 0.0) return fit;
    fit.slope = sxy / sxx;
    fit.intercept = my - fit.slope * mx;
    return fit;
}

LogBins log_bins(std::span<const double> x, std::span<const double> y, int per_decade, std::size_t min_count) {
    LogBins bins;
    if (x.empty()) return bins;
    const auto [lo, hi] = std::minmax_element(x.begin(), x.end());
    const int first = int(std::floor(std::log10(*lo) * per_decade));
    const int last = int(std::floor(std::log10(*hi) * per_decade));
    std::vector<double> sum(std::size_t(last - first + 1), 0.0);
    std::vector<std::size_t> count(sum.size(), 0);
    for (std::size_t i = 0; i < x.size(); ++i) {
        const int b = std::clamp(int(std::floor(std::log10(x[i]) * per_decade)), first, last) - first;
        sum[std::size_t(b)] += std::log(y[i]);
        ++count[std::size_t(b)];
    }
    for (std::size_t b = 0; b < sum.size(); ++b) {
        if (count[b] < min_count) continue;
        bins.x.push_back(std::pow(10.0, (double(first) + double(b) + 0.5) / per_decade));
        bins.y.push_back(std::exp(sum[b] / double(count[b])));
        bins.count.push_back(count[b]);
    }
    return bins;
}

double percentile(std::vector<double>& values, double q) {
    if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
    const double rank = q / 100.0 * double(values.size() - 1);
    const std::size_t below = std::size_t(std::floor(rank));
    // The two order statistics around the rank, without sorting everything: nth_element puts the
    // below-th in place and only larger values after it.
    const auto at = values.begin() + std::ptrdiff_t(below);
    std::nth_element(values.begin(), at, values.end());
    const double lower = *at;
    const double upper = below + 1 < values.size() ? *std::min_element(at + 1, values.end()) : lower;
    return lower + (upper - lower) * (rank - double(below));
}

}  // namespace detail

Figures measure(const Grid& grid, const Options& options) {
    if (!grid.heights) throw std::invalid_argument("analysis::measure: no heights");
    if (grid.width < 1 || grid.height < 1) throw std::invalid_argument("analysis::measure: empty grid");
    if (!(grid.cell > 0.0) || !std::isfinite(grid.cell))
        throw std::invalid_argument("analysis::measure: the cell size must be a positive number of metres");

    detail::Terrain t;
    t.width = grid.width;
    t.height = grid.height;
    t.cell = grid.cell;
    const std::size_t n = std::size_t(grid.width) * std::size_t(grid.height);
    t.z.resize(n);
    t.valid.resize(n);
    t.minimum = std::numeric_limits<double>::infinity();
    t.maximum = -std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < n; ++i) {
        const float h = grid.heights[i];
        const bool ok = std::isfinite(h) && (!grid.valid || grid.valid[i] != 0);
        t.valid[i] = ok ? 1 : 0;
        if (!ok) continue;
        ++t.samples;
        t.z[i] = double(h);
        t.minimum = std::min(t.minimum, t.z[i]);
        t.maximum = std::max(t.maximum, t.z[i]);
    }

    Figures f;
    f.width = grid.width;
    f.height = grid.height;
    f.cell = grid.cell;
    f.samples = t.samples;
    f.nodata = n - t.samples;
    if (t.samples == 0) {
        for (auto& m : f.values) m.why_not = "the terrain has no measured sample (all nodata)";
        return f;
    }
    for (std::size_t i = 0; i < n; ++i)
        if (!t.valid[i]) t.z[i] = t.minimum;
    f.minimum = t.minimum;
    f.maximum = t.maximum;

    detail::measure_slopes(t, f);
    detail::measure_hypsometry(t, f);
    detail::measure_pits(t, f);
    detail::measure_relief(t, options, f);
    detail::measure_curvature(t, f);
    detail::measure_spectrum(t, f);
    detail::measure_drainage(t, options, f);
    for (auto& m : f.values)
        if (m.ok() && !std::isfinite(m.value)) m.why_not = "not a finite number on this terrain";
    return f;
}

}  // namespace orogen::analysis
