// Internals of orogen_analysis: the figure groups measure() calls, each filling its part of Figures.
#pragma once

#include <orogen/analysis/figures.hpp>

#include <cstdint>
#include <span>
#include <vector>

namespace orogen::analysis::detail {

/// The grid as the figures see it: heights in double (terrain_stats.py works in float64) and the
/// valid mask folded with finiteness.
struct Terrain {
    int width = 0, height = 0;
    double cell = 0.0;
    std::vector<double> z;  ///< heights, m; nodata samples hold the minimum (never read as heights)
    std::vector<std::uint8_t> valid;  ///< 1 measured, 0 nodata
    std::size_t samples = 0;  ///< valid samples
    double minimum = 0.0, maximum = 0.0;
    std::size_t size() const { return z.size(); }
    std::size_t at(int x, int y) const { return std::size_t(y) * std::size_t(width) + std::size_t(x); }
};

/// Least squares y = slope·x + intercept (numpy.polyfit degree 1), summed in index order.
LineFit fit_line(std::span<const double> x, std::span<const double> y);
/// Geometric means of y in bins of log10 x, `per_decade` bins a decade, bins with fewer than `min_count` dropped.
LogBins log_bins(std::span<const double> x, std::span<const double> y, int per_decade, std::size_t min_count);
/// numpy.percentile's default (linear interpolation between order statistics); q in 0..100. Reorders `values`.
double percentile(std::vector<double>& values, double q);

void measure_slopes(const Terrain& t, Figures& f);
void measure_hypsometry(const Terrain& t, Figures& f);
void measure_pits(const Terrain& t, Figures& f);
void measure_relief(const Terrain& t, const Options& o, Figures& f);
void measure_curvature(const Terrain& t, Figures& f);
void measure_spectrum(const Terrain& t, Figures& f);
void measure_drainage(const Terrain& t, const Options& o, Figures& f);
/// Channel curvature and valley width, over the cells draining more than o.channel_area (m², `area`).
void measure_valleys(const Terrain& t, const Options& o, std::span<const double> area, Figures& f);

}  // namespace orogen::analysis::detail
