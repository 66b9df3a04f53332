// orogen/analysis/discriminate.hpp — can a classifier tell generated terrain from real terrain, window by
// window?
//
// Every source (one real DEM, or one generated terrain) is cut into square windows of the same size in
// metres; each window is described by scale-free geomorphic figures (window_figure_table(); definitions and
// sources in docs/analysis.md, "Telling windows apart"); a gradient-boosted tree classifier (XGBoost,
// through its C API inside discriminate.cpp only) learns real from generated leaving one whole source out
// at a time, and every window is judged by the model that never saw its source. The balanced accuracy
// of those held-out judgements is the figure of merit: 50 % is a terrain no classifier told apart, 100 %
// one it always told apart.
//
// Plain C++ over analysis::Grid views, no kernel types. Deterministic: XGBoost runs on one thread with a
// fixed seed, the window figures are sums in index order.
//
//   std::vector<orogen::analysis::Source> sources = {{"baspa", baspa_grid, true}, {"mine", mine_grid, false}, ...};
//   const auto problem = orogen::analysis::check_sources(sources, {});   // "" or what is wrong and the fix
//   const auto result = orogen::analysis::discriminate(sources, {});
//   result.balanced_accuracy;  // 0.5 … 1
#pragma once

#include <orogen/analysis/figures.hpp>

#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace orogen::analysis {

/// The figures of one window, in this order (window_figure_table()).
enum class WindowFigureId : std::size_t {
    slope_p10,
    slope_p50,
    slope_p90,
    slope_spread,
    curvature_spread,
    curvature_skew,
    convex_share,
    roughness_ratio,
    spectral_exponent,
    orientation_coherence,
    elevation_skew,
    hypsometric_integral,
    network_share,
    hillslope_length,
    drainage_density,
    count_
};
inline constexpr std::size_t window_figure_count = std::size_t(WindowFigureId::count_);

struct WindowFigureInfo {
    WindowFigureId id;
    std::string_view key;  ///< snake_case, the JSON key
    std::string_view label;  ///< short, for the table
    std::string_view unit;  ///< "°", "%", "" ...
    std::string_view definition;
    std::string_view source;
    int decimals;
};

std::span<const WindowFigureInfo> window_figure_table();

using WindowFigures = std::array<double, window_figure_count>;  ///< NaN: not measurable on this window

/// The figures of one window (the whole of `grid`, which should hold no hole: holes make every figure NaN
/// but the slopes' and drainage's, which skip them).
WindowFigures measure_window(const Grid& grid);

/// One source of windows: a real DEM (real = true) or a generated terrain.
struct Source {
    std::string name;
    Grid grid;
    bool real = false;
};

struct DiscriminateOptions {
    double window_m = 3840.0;  ///< the windows' side in metres (rounded to whole cells of each source)
    /// Sources are refused when the coarsest cell exceeds the finest by more than this share of it: slopes and
    /// curvature depend on the cell size. 12 %: the 27 m Rif goes with the 30 m ranges, 35 m cells do not.
    double cell_tolerance = 0.12;
    int rounds = 200;  ///< boosting rounds
    int max_depth = 4;
    double eta = 0.1;  ///< learning rate
    unsigned seed = 0;  ///< XGBoost's seed (row and column subsampling)
    /// A window with more than this share of holes (nodata, non-finite) is skipped.
    double max_hole_share = 0.01;
};

/// "" if `sources` can be discriminated with `options`, else what is wrong and how to fix it: fewer than two
/// real or two generated sources (leave-one-source-out needs another source of each kind to learn from),
/// cell sizes farther apart than options.cell_tolerance (resample: gdalwarp -tr), a source smaller
/// than one window (a smaller --window-m), a window under 16 cells.
std::string check_sources(const std::vector<Source>& sources, const DiscriminateOptions& options = {});

struct Window {
    std::size_t source = 0;  ///< index into the sources
    int x = 0, y = 0;  ///< its top-left sample in the source
    int cells = 0;  ///< its side in samples: window_m in the source's cells
    WindowFigures figures{};
    double p_real = 0.0;  ///< the held-out model's probability that it is real (never trained on its source)
};

struct SourceResult {
    std::string name;
    bool real = false;
    std::size_t windows = 0;
    double called_real = 0.0;  ///< share of its windows the held-out model called real (p_real > 0.5)
};

struct Importance {
    WindowFigureId figure;
    double gain = 0.0;  ///< XGBoost's total gain over every split on the figure, model trained on all windows
    double share = 0.0;  ///< gain over the sum of all figures' gains
    double median_real = 0.0, median_generated = 0.0;  ///< the figure's median over the real / generated windows
};

struct Discrimination {
    int window_cells = 0;  ///< the windows' side in samples of the first source (each source's: Window::cells)
    double window_m = 0.0;  ///< the windows' side in metres
    std::vector<Window> windows;  ///< every window, source by source, rows then columns
    std::vector<SourceResult> sources;
    double balanced_accuracy = 0.0;  ///< mean of the two recalls below
    double recall_real = 0.0;  ///< share of the real windows called real
    double recall_generated = 0.0;  ///< share of the generated windows called generated
    std::vector<Importance> importance;  ///< every figure, by decreasing gain
};

/// Cuts the windows, measures them, and runs the leave-one-source-out cross-validation. Throws
/// std::invalid_argument with check_sources()'s message if it is not empty, and std::runtime_error if
/// XGBoost fails.
Discrimination discriminate(const std::vector<Source>& sources, const DiscriminateOptions& options = {});

/// The side of the windows in samples for these options and this cell size.
int window_cells(double window_m, double cell);

}  // namespace orogen::analysis
