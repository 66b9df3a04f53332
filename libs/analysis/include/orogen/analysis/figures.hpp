// orogen/analysis/figures.hpp — geomorphometry: the figures that tell a real
// mountain range from a generated one.
//
// Plain C++ over a plain view of heights (no kernel types): `measure()` takes
// a Grid (row-major float heights in metres, the cell size in metres, an
// optional nodata mask) and returns every figure of `figure_table()` with the
// data a chart of it needs. The definitions follow
// `shared/realism/README.md` and its `terrain_stats.py` exactly, so the numbers
// agree with that script on the reference DEMs; docs/analysis.md cites each
// figure's source. Deterministic whatever the thread count: parallel loops
// (the kernel's orogen::parallel_for) write each element from one iteration
// and every sum runs in index order.
//
//   orogen::analysis::Grid grid{heights.data(), width, height, 30.0};
//   const auto figures = orogen::analysis::measure(grid);
//   double beta = figures[orogen::analysis::FigureId::spectral_exponent].value;
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace orogen::analysis {

/// A read-only view of `width` × `height` heights in metres, row-major
/// (sample (x, y) is heights[y·width + x], y grows south), `cell` metres apart.
struct Grid {
    const float* heights = nullptr;
    int width = 0;
    int height = 0;
    double cell = 0.0;  ///< metres between neighbouring samples (> 0)
    /// Optional, width·height bytes: 0 marks a nodata sample (a hole), anything else a measured one.
    /// Non-finite heights count as nodata too, mask or not.
    const std::uint8_t* valid = nullptr;
};

/// Thresholds of the figures. The defaults are those of terrain_stats.py, but for fit_filled_cells.
struct Options {
    double channel_area = 1e6;  ///< m²: drainage area above which a cell is a channel for θ, k_sn and Hack
    double channel_min_slope = 1e-4;  ///< m/m: channel cells at least this steep enter the slope–area fit
    /// Whether the channel cells the priority flood raised (filled flats: their slope is the fill's gradient,
    /// ε/cell = 1e-4, which the test S > channel_min_slope keeps or drops by rounding, about half of them) enter
    /// the fits of θ, k_sn and Hack's h. false (the default) leaves them out, so the fits do not swing with the
    /// cell size or a reprojection; true is terrain_stats.py's definition (docs/analysis.md, "Real-world
    /// rasters").
    bool fit_filled_cells = false;
    double reference_concavity = 0.45;  ///< θ_ref of the normalised steepness k_sn = S·A^θ_ref (Wobus et al. 2006)
    double network_area =
        1e5;  ///< m²: drainage area above which a cell is on the drainage network (density, hillslopes)
    double relief_radius = 1000.0;  ///< m: half-width of the square window of the local relief
    double sinuosity_reach = 1000.0;  ///< m: length of flow path over which a channel's sinuosity is taken
    /// °: channel cells at least this steep (central differences) enter the channel curvature (channels
    /// among hillslopes, not the flats of floodplains, lakes and filled pits)
    double valley_min_slope = 6.0;
    double valley_rise = 10.0;  ///< m: the valley's width is taken this high above the river
    int valley_reach = 8;  ///< samples: how far to either side of the river its cross-section is taken
};

/// Every figure, in the order of figure_table() (and of the report's columns).
enum class FigureId : std::size_t {
    slope_mean,
    slope_median,
    slope_p90,
    steeper_30,
    steeper_40,
    hypsometric_integral,
    spectral_exponent,
    pits,
    concavity,
    steepness,
    hack_exponent,
    drainage_density,
    network_share,
    local_relief,
    hillslope_length,
    curvature_spread,
    channel_sinuosity,
    channel_curvature,
    valley_width,
    valley_widening,
    count_
};
inline constexpr std::size_t figure_count = std::size_t(FigureId::count_);

/// How a figure is described, once, for the JSON report, the terminal table and `orogen help`.
struct FigureInfo {
    FigureId id;
    std::string_view key;  ///< snake_case, the JSON key: "slope_median"
    std::string_view label;  ///< short, for a table column: "median slope"
    std::string_view unit;  ///< "°", "%", "m^0.9", "" for none
    std::string_view definition;  ///< one sentence: how it is computed
    std::string_view source;  ///< the citation the definition comes from
    int decimals;  ///< digits after the point when printed
};

/// The figures' descriptions, indexed by FigureId.
std::span<const FigureInfo> figure_table();
const FigureInfo& info(FigureId id);
/// The figure whose key is `key`, or nullopt.
std::optional<FigureId> find_figure(std::string_view key);

/// One figure's value, or why it could not be measured on this terrain.
struct Measured {
    double value = std::numeric_limits<double>::quiet_NaN();
    std::string why_not;  ///< non-empty exactly when the value is NaN: "fewer than 51 channel cells ..."
    bool ok() const { return why_not.empty(); }
};

/// A least-squares line y = slope·x + intercept, and over how many points.
struct LineFit {
    double slope = std::numeric_limits<double>::quiet_NaN();
    double intercept = std::numeric_limits<double>::quiet_NaN();
    std::size_t points = 0;
};

/// log10(x) against log10(y) means in bins of log10 x (for charts of clouds of points).
struct LogBins {
    std::vector<double> x;  ///< bin centres (linear units)
    std::vector<double> y;  ///< geometric means of y in the bin
    std::vector<std::size_t> count;
};

struct Figures {
    std::array<Measured, figure_count> values;
    const Measured& operator[](FigureId id) const { return values[std::size_t(id)]; }
    Measured& operator[](FigureId id) { return values[std::size_t(id)]; }

    // What was measured.
    int width = 0, height = 0;
    double cell = 0.0;  ///< m
    std::size_t samples = 0;  ///< measured samples (not nodata)
    std::size_t nodata = 0;  ///< samples masked as nodata
    double minimum = 0.0, maximum = 0.0;  ///< m, over measured samples

    // Chart data.
    /// Share of the sloped samples in 1° bins, [0°, 1°) … [89°, 90°]: 90 entries summing to 1.
    std::vector<double> slope_histogram;
    /// Hypsometric curve: share of the area (0..1) above each relative height h = 0, 0.01, … 1.
    std::vector<double> hypsometric_area;
    /// Radially averaged power spectrum: integer wavenumbers k = 1 … n/2 (cycles per crop side) and their
    /// mean power (m² · samples², unnormalised as in terrain_stats.py); `spectrum_fit` over k = 4 … n/4.
    std::vector<double> spectrum_k, spectrum_power;
    int spectrum_side = 0;  ///< n, the square crop's side
    LineFit spectrum_fit;  ///< ln P against ln k; β = −slope
    /// Slope–area: channel cells binned by area (m², m/m); fit of ln S against ln A (θ = −slope).
    LogBins slope_area;
    LineFit slope_area_fit;
    /// Hack's law: channel cells binned by area (m², longest upstream flow length m); fit of ln L against ln A.
    LogBins hack;
    LineFit hack_fit;
    /// The valleys' median cross-section: height (m) above the river d = 0 … valley_reach samples to either
    /// side, over the channel cells (A > channel_area, any slope; empty when there are none).
    std::vector<double> valley_section;
    /// Valley width against drainage area: the width (m, as the figure) over the channel cells in each
    /// quarter decade of A (m²) with 30 cells or more; y is the width, not a mean.
    LogBins valley_widths;
    LineFit valley_widths_fit;  ///< ln width against ln A over those bins; the widening exponent is its slope
};

/// Measures every figure. A figure this terrain is too small (or too flat, or too holed) for is
/// NaN with `why_not` saying which condition failed; the others are measured. Throws
/// std::invalid_argument if `grid` is malformed (no heights, a side < 1, a cell size ≤ 0 or
/// not finite); a grid with no measured sample gives every figure NaN with a reason.
Figures measure(const Grid& grid, const Options& options = {});

}  // namespace orogen::analysis
