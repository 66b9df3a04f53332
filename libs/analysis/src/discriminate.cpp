// Telling generated windows from real ones (discriminate.hpp): the window figures, and the leave-one-source-out
// cross-validation of an XGBoost classifier through its C API (kept to this file).
#include <orogen/analysis/discriminate.hpp>

#include "detail.hpp"

#include <orogen/parallel.hpp>

#include <xgboost/c_api.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace orogen::analysis {

namespace {

using enum WindowFigureId;

constexpr double nan = std::numeric_limits<double>::quiet_NaN();
constexpr int minimum_window = 16;  ///< samples a side

constexpr WindowFigureInfo table[] = {
    {slope_p10, "slope_p10", "p10 slope", "°",
     "10th percentile of the window's slopes atan|grad z| (central differences, interior samples): how flat "
     "its flattest tenth is (valley floors)",
     "Strahler 1950, Am. J. Sci. 248:673", 1},
    {slope_p50, "slope_p50", "median slope", "°", "median of the window's slopes", "Strahler 1950, Am. J. Sci. 248:673",
     1},
    {slope_p90, "slope_p90", "p90 slope", "°", "90th percentile of the window's slopes (threshold hillslopes)",
     "Strahler 1950; Montgomery & Brandon 2002, Earth Planet. Sci. Lett. 201:481", 1},
    {slope_spread, "slope_spread", "slope IQR/median", "",
     "interquartile range of the slopes over their median: flat floors beside steep walls give a wide spread",
     "Strahler 1950; Evans 1972, in Chorley (ed.) Spatial Analysis in Geomorphology, 17", 2},
    {curvature_spread, "curvature_spread", "curvature sd", "1/km",
     "standard deviation of the Laplacian (5-point stencil) over the interior samples",
     "Zevenbergen & Thorne 1987, Earth Surf. Proc. Landf. 12:47; Hurst et al. 2012, J. Geophys. Res. 117:F02017", 2},
    {curvature_skew, "curvature_skew", "curvature skew", "",
     "skewness (third standardised moment) of the Laplacian: sharp valleys and rounded crests, or the reverse",
     "Evans 1972; Hurst et al. 2012", 2},
    {convex_share, "convex_share", "convex ground", "%",
     "share of the interior samples whose Laplacian is negative (convex ground: crests and spurs)",
     "Roering, Perron & Kirchner 2007, Earth Planet. Sci. Lett. 264:245", 1},
    {roughness_ratio, "roughness_ratio", "roughness ratio", "",
     "ln(σ(8)/σ(1))/ln 8, σ(h) the root-mean-square height difference between samples h apart along rows and "
     "columns: the local Hurst exponent between one and eight cells (a plane 1, white noise 0)",
     "Mark & Aronson 1984, Math. Geol. 16:671; Turcotte 1997, Fractals and Chaos in Geology", 2},
    {spectral_exponent, "spectral_exponent", "spectral β", "",
     "the window's spectral exponent, as analyze's β (Hann-windowed radial power spectrum, k = 4 … n/4)",
     "Perron, Kirchner & Dietrich 2008, J. Geophys. Res. 113:F04003", 2},
    {orientation_coherence, "orientation_coherence", "orientation coh.", "",
     "mean over the samples of the coherence √((Jxx−Jyy)²+4Jxy²)/(Jxx+Jyy) of the gradient's structure tensor "
     "J summed over 7 × 7 samples: 1 where slopes all face one way (parallel gullies), 0 where they face all "
     "ways",
     "Bigün & Granlund 1987, Proc. ICCV 433; Kass & Witkin 1987, Comput. Vis. Graph. Image Proc. 37:362", 3},
    {elevation_skew, "elevation_skew", "height skew", "",
     "skewness of the window's heights (positive: low ground with a few high peaks)",
     "Evans 1972; Luo 1998, Geomorphology 25:1 (hypsometric skewness)", 2},
    {hypsometric_integral, "hypsometric_integral", "hypsometric int.", "",
     "(mean − min)/(max − min) of the window's heights", "Strahler 1952, Geol. Soc. Am. Bull. 63:1117", 3},
    {network_share, "network_share", "net. >0.1km²", "%",
     "share of the window's samples draining more than 0.1 km² (D8 on the priority-flood-filled window)",
     "O'Callaghan & Mark 1984; Montgomery & Dietrich 1988, Nature 336:232 (channel heads)", 1},
    {hillslope_length, "hillslope_length", "hillslope L", "m",
     "mean D8 flow distance from each sample off the network down to the network, within the window",
     "Roering, Perron & Kirchner 2007, Earth Planet. Sci. Lett. 264:245", 0},
    {drainage_density, "drainage_density", "drainage dens.", "1/km",
     "D8 length of the network (> 0.1 km²) over the window's area", "Horton 1945, Geol. Soc. Am. Bull. 56:275", 2},
};
static_assert(std::size(table) == window_figure_count);

/// Mean, standard deviation and skewness of `v` (sums in index order); NaN when fewer than 3 values.
std::array<double, 3> moments(const std::vector<double>& v) {
    if (v.size() < 3) return {nan, nan, nan};
    double sum = 0.0;
    for (const double x : v) sum += x;
    const double mean = sum / double(v.size());
    double m2 = 0.0, m3 = 0.0;
    for (const double x : v) {
        const double d = x - mean;
        m2 += d * d;
        m3 += d * d * d;
    }
    m2 /= double(v.size());
    m3 /= double(v.size());
    const double sd = std::sqrt(m2);
    return {mean, sd, sd > 0.0 ? m3 / (sd * sd * sd) : nan};
}

/// The figures that need only the heights: slopes, curvature, roughness, orientation, height skew.
void local_figures(const detail::Terrain& t, WindowFigures& f) {
    const int w = t.width, h = t.height;
    const double c = t.cell;
    auto ok = [&](int x, int y) { return t.valid[t.at(x, y)] != 0; };
    std::vector<double> slopes, laplacians, gx(t.size(), nan), gy(t.size(), nan);
    for (int y = 1; y + 1 < h; ++y)
        for (int x = 1; x + 1 < w; ++x) {
            if (!ok(x, y) || !ok(x - 1, y) || !ok(x + 1, y) || !ok(x, y - 1) || !ok(x, y + 1)) continue;
            const std::size_t i = t.at(x, y), row = std::size_t(w);
            const double dx = (t.z[i + 1] - t.z[i - 1]) / (2.0 * c), dy = (t.z[i + row] - t.z[i - row]) / (2.0 * c);
            gx[i] = dx, gy[i] = dy;
            slopes.push_back(std::atan(std::hypot(dx, dy)) * 180.0 / 3.14159265358979323846);
            laplacians.push_back((t.z[i - 1] + t.z[i + 1] + t.z[i - row] + t.z[i + row] - 4.0 * t.z[i]) / (c * c) *
                                 1000.0);  // 1/km
        }
    if (slopes.size() >= 16) {
        auto s = slopes;
        f[std::size_t(slope_p10)] = detail::percentile(s, 10.0);
        f[std::size_t(slope_p50)] = detail::percentile(s, 50.0);
        f[std::size_t(slope_p90)] = detail::percentile(s, 90.0);
        const double p25 = detail::percentile(s, 25.0), p75 = detail::percentile(s, 75.0);
        const double p50 = f[std::size_t(slope_p50)];
        f[std::size_t(slope_spread)] = p50 > 0.0 ? (p75 - p25) / p50 : nan;
        const auto m = moments(laplacians);
        f[std::size_t(curvature_spread)] = m[1];
        f[std::size_t(curvature_skew)] = m[2];
        std::size_t convex = 0;
        for (const double l : laplacians) convex += l < 0.0;
        f[std::size_t(convex_share)] = 100.0 * double(convex) / double(laplacians.size());
    }
    // σ(h): height differences h apart along rows and columns.
    auto rms_difference = [&](int lag) {
        double sum = 0.0;
        std::size_t n = 0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                if (!ok(x, y)) continue;
                const double z = t.z[t.at(x, y)];
                if (x + lag < w && ok(x + lag, y)) sum += std::pow(t.z[t.at(x + lag, y)] - z, 2), ++n;
                if (y + lag < h && ok(x, y + lag)) sum += std::pow(t.z[t.at(x, y + lag)] - z, 2), ++n;
            }
        return n ? std::sqrt(sum / double(n)) : nan;
    };
    const double s1 = rms_difference(1), s8 = rms_difference(8);
    if (s1 > 0.0 && s8 > 0.0) f[std::size_t(roughness_ratio)] = std::log(s8 / s1) / std::log(8.0);
    // Orientation coherence over 7 × 7 boxes of gradients.
    constexpr int r = 3;
    double coherence = 0.0;
    std::size_t boxes = 0;
    for (int y = 1 + r; y + 1 + r < h; ++y)
        for (int x = 1 + r; x + 1 + r < w; ++x) {
            double jxx = 0.0, jyy = 0.0, jxy = 0.0;
            for (int v = y - r; v <= y + r; ++v)
                for (int u = x - r; u <= x + r; ++u) {
                    const std::size_t i = t.at(u, v);
                    if (std::isnan(gx[i])) continue;
                    jxx += gx[i] * gx[i], jyy += gy[i] * gy[i], jxy += gx[i] * gy[i];
                }
            if (jxx + jyy <= 0.0) continue;
            coherence += std::sqrt((jxx - jyy) * (jxx - jyy) + 4.0 * jxy * jxy) / (jxx + jyy);
            ++boxes;
        }
    if (boxes) f[std::size_t(orientation_coherence)] = coherence / double(boxes);
    std::vector<double> heights;
    for (std::size_t i = 0; i < t.size(); ++i)
        if (t.valid[i]) heights.push_back(t.z[i]);
    f[std::size_t(elevation_skew)] = moments(heights)[2];
}

/// An XGBoost call that must succeed.
void xgb(int rc, const char* what) {
    if (rc != 0) throw std::runtime_error(std::string("XGBoost: ") + what + ": " + XGBGetLastError());
}

/// A DMatrix of `rows` × window_figure_count floats (NaN = missing), freed on scope exit.
class Matrix {
public:
    Matrix(const std::vector<float>& data, std::size_t rows) {
        xgb(XGDMatrixCreateFromMat(data.data(), rows, window_figure_count, std::numeric_limits<float>::quiet_NaN(),
                                   &handle_),
            "creating a matrix");
    }
    ~Matrix() { XGDMatrixFree(handle_); }
    Matrix(const Matrix&) = delete;
    Matrix& operator=(const Matrix&) = delete;
    DMatrixHandle get() const { return handle_; }
    void set(const char* field, const std::vector<float>& values) const {
        xgb(XGDMatrixSetFloatInfo(handle_, field, values.data(), values.size()), field);
    }

private:
    DMatrixHandle handle_ = nullptr;
};

/// A booster trained on `rows` (indices into the windows) with class-balanced weights.
class Booster {
public:
    Booster(const std::vector<float>& features, const std::vector<float>& labels, const std::vector<std::size_t>& rows,
            const DiscriminateOptions& o) {
        std::vector<float> data, label, weight;
        double real = 0.0;
        for (const std::size_t r : rows) {
            data.insert(data.end(), features.begin() + std::ptrdiff_t(r * window_figure_count),
                        features.begin() + std::ptrdiff_t((r + 1) * window_figure_count));
            label.push_back(labels[r]);
            real += labels[r];
        }
        // Each class weighs half of the training set, whatever its number of windows.
        const double all = double(rows.size()), generated = all - real;
        if (real < 1.0 || generated < 1.0)
            throw std::invalid_argument(
                "leaving a source out leaves no " + std::string(real < 1.0 ? "real" : "generated") +
                " window to learn from (the others' windows were all skipped for holes, more than 1 % nodata); "
                "give sources with fewer holes or a smaller --window-m");
        for (const float l : label) weight.push_back(float(l > 0.5f ? 0.5 * all / real : 0.5 * all / generated));
        Matrix train(data, rows.size());
        train.set("label", label);
        train.set("weight", weight);
        const DMatrixHandle handles[] = {train.get()};
        xgb(XGBoosterCreate(handles, 1, &handle_), "creating the booster");
        const std::string depth = std::to_string(o.max_depth), eta = std::to_string(o.eta),
                          seed = std::to_string(o.seed);
        const std::pair<const char*, const char*> params[] = {{"objective", "binary:logistic"},
                                                              {"tree_method", "hist"},
                                                              {"nthread", "1"},
                                                              {"max_depth", depth.c_str()},
                                                              {"eta", eta.c_str()},
                                                              {"seed", seed.c_str()},
                                                              {"subsample", "0.8"},
                                                              {"colsample_bytree", "0.8"},
                                                              {"min_child_weight", "2"},
                                                              {"verbosity", "0"}};
        for (const auto& [key, value] : params) xgb(XGBoosterSetParam(handle_, key, value), key);
        for (int i = 0; i < o.rounds; ++i) xgb(XGBoosterUpdateOneIter(handle_, i, train.get()), "training");
    }
    ~Booster() { XGBoosterFree(handle_); }
    Booster(const Booster&) = delete;
    Booster& operator=(const Booster&) = delete;

    /// The probability that each row is real.
    std::vector<double> predict(const std::vector<float>& data, std::size_t rows) const {
        Matrix m(data, rows);
        const bst_ulong* shape = nullptr;
        bst_ulong dim = 0;
        const float* result = nullptr;
        xgb(XGBoosterPredictFromDMatrix(handle_, m.get(),
                                        R"({"type": 0, "training": false, "iteration_begin": 0, )"
                                        R"("iteration_end": 0, "strict_shape": false})",
                                        &shape, &dim, &result),
            "predicting");
        return std::vector<double>(result, result + rows);
    }

    /// Total gain per figure (0 for a figure no split used).
    std::array<double, window_figure_count> gains() const {
        std::array<double, window_figure_count> g{};
        bst_ulong n = 0, dim = 0;
        const char** names = nullptr;
        const bst_ulong* shape = nullptr;
        const float* scores = nullptr;
        xgb(XGBoosterFeatureScore(handle_, R"({"importance_type": "total_gain"})", &n, &names, &dim, &shape, &scores),
            "feature importance");
        for (bst_ulong i = 0; i < n; ++i) {
            // Unnamed features are "f0", "f1", ...
            const std::size_t k = std::size_t(std::strtoul(names[i] + 1, nullptr, 10));
            if (names[i][0] == 'f' && k < window_figure_count) g[k] = double(scores[i]);
        }
        return g;
    }

private:
    BoosterHandle handle_ = nullptr;
};

/// The median of the finite values, or NaN.
double median(std::vector<double> v) {
    std::erase_if(v, [](double x) { return !std::isfinite(x); });
    return v.empty() ? nan : detail::percentile(v, 50.0);
}

/// Every window of every source: a grid of whole windows of window_m metres (in the source's own cells) centred
/// on each source, rows then columns, skipping windows with more than max_hole_share holes.
std::vector<Window> cut_windows(const std::vector<Source>& sources, const DiscriminateOptions& o) {
    std::vector<Window> windows;
    for (std::size_t s = 0; s < sources.size(); ++s) {
        const Grid& g = sources[s].grid;
        const int n = window_cells(o.window_m, g.cell);
        const int across = g.width / n, down = g.height / n;
        const int x0 = (g.width - across * n) / 2, y0 = (g.height - down * n) / 2;
        for (int j = 0; j < down; ++j)
            for (int i = 0; i < across; ++i) {
                std::size_t holes = 0;
                for (int y = y0 + j * n; y < y0 + (j + 1) * n; ++y)
                    for (int x = x0 + i * n; x < x0 + (i + 1) * n; ++x) {
                        const std::size_t k = std::size_t(y) * std::size_t(g.width) + std::size_t(x);
                        holes += !std::isfinite(g.heights[k]) || (g.valid && !g.valid[k]);
                    }
                if (double(holes) > o.max_hole_share * double(n) * double(n)) continue;
                windows.push_back({s, x0 + i * n, y0 + j * n, n, {}, 0.0});
            }
    }
    // Each window's figures, from its own copy of the heights: one iteration's alone, so any thread count.
    orogen::parallel_for(0, std::int64_t(windows.size()), 1, [&](std::int64_t begin, std::int64_t end) {
        std::vector<float> z;
        std::vector<std::uint8_t> valid;
        for (auto k = std::size_t(begin); k < std::size_t(end); ++k) {
            Window& win = windows[k];
            const Grid& g = sources[win.source].grid;
            const int n = win.cells;
            z.resize(std::size_t(n) * std::size_t(n));
            valid.resize(z.size());
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    const std::size_t from = std::size_t(win.y + y) * std::size_t(g.width) + std::size_t(win.x + x);
                    const std::size_t to = std::size_t(y) * std::size_t(n) + std::size_t(x);
                    z[to] = g.heights[from];
                    valid[to] = g.valid ? g.valid[from] : 1;
                }
            win.figures = measure_window({z.data(), n, n, g.cell, valid.data()});
        }
    });
    return windows;
}

}  // namespace

std::span<const WindowFigureInfo> window_figure_table() { return table; }

int window_cells(double window_m, double cell) {
    if (!(cell > 0.0) || !(window_m > 0.0)) return 0;
    return int(std::lround(window_m / cell));
}

WindowFigures measure_window(const Grid& grid) {
    WindowFigures f;
    f.fill(nan);
    detail::Terrain t;
    t.width = grid.width, t.height = grid.height, t.cell = grid.cell;
    t.z.resize(std::size_t(grid.width) * std::size_t(grid.height));
    t.valid.resize(t.z.size());
    for (std::size_t i = 0; i < t.z.size(); ++i) {
        t.valid[i] = std::isfinite(grid.heights[i]) && (!grid.valid || grid.valid[i]);
        t.z[i] = t.valid[i] ? double(grid.heights[i]) : 0.0;
        t.samples += t.valid[i];
    }
    local_figures(t, f);
    // The figures analyze measures over a whole terrain, here over the window.
    Options options;
    const Figures whole = measure(grid, options);
    auto take = [&](WindowFigureId to, FigureId from) {
        if (whole[from].ok()) f[std::size_t(to)] = whole[from].value;
    };
    take(spectral_exponent, FigureId::spectral_exponent);
    take(hypsometric_integral, FigureId::hypsometric_integral);
    take(network_share, FigureId::network_share);
    take(hillslope_length, FigureId::hillslope_length);
    take(drainage_density, FigureId::drainage_density);
    return f;
}

std::string check_sources(const std::vector<Source>& sources, const DiscriminateOptions& o) {
    std::size_t real = 0, generated = 0;
    for (const auto& s : sources) (s.real ? real : generated) += 1;
    if (real < 2 || generated < 2)
        return "telling real from generated windows leaving one source out needs at least two real DEMs and two "
               "generated terrains (got " +
            std::to_string(real) + " real and " + std::to_string(generated) +
            "); give more, e.g. the same pipeline run with other seeds";
    for (const auto& s : sources)
        if (!(s.grid.cell > 0.0) || !s.grid.heights) return s.name + ": no heights or no cell size";
    // The finest and the coarsest cells, compared with each other: the order of the sources does not matter.
    const auto [fine, coarse] = std::minmax_element(
        sources.begin(), sources.end(), [](const Source& a, const Source& b) { return a.grid.cell < b.grid.cell; });
    if (coarse->grid.cell - fine->grid.cell > o.cell_tolerance * coarse->grid.cell) {
        char text[500];
        std::snprintf(text, sizeof text,
                      "%s has %.4g m cells and %s %.4g m: more than %.0f %% apart, and slopes and curvature depend "
                      "on the cell size; compare terrains at the same cell size, or resample the finer one first "
                      "(gdalwarp -tr %.4g %.4g -r average IN.tif OUT.tif)",
                      coarse->name.c_str(), coarse->grid.cell, fine->name.c_str(), fine->grid.cell,
                      100.0 * o.cell_tolerance, coarse->grid.cell, coarse->grid.cell);
        return text;
    }
    const double cell = coarse->grid.cell;
    const int n = window_cells(o.window_m, cell);  // the fewest samples a window has, in the coarsest cells
    if (n < minimum_window) {
        char text[300];
        std::snprintf(
            text, sizeof text,
            "the window of %.4g m is %d cells of %.4g m, fewer than %d; give a larger window (--window-m %.0f "
            "or more)",
            o.window_m, n, cell, minimum_window, minimum_window * cell);
        return text;
    }
    for (const auto& s : sources)
        if (const int cells = window_cells(o.window_m, s.grid.cell); s.grid.width < cells || s.grid.height < cells) {
            char text[400];
            std::snprintf(text, sizeof text,
                          "%s (%dx%d samples of %.4g m) is smaller than one window of %.4g m (%d samples); give a "
                          "smaller window (--window-m %.0f or less) or leave it out",
                          s.name.c_str(), s.grid.width, s.grid.height, s.grid.cell, o.window_m, cells,
                          std::floor(double(std::min(s.grid.width, s.grid.height)) * s.grid.cell));
            return text;
        }
    return {};
}

Discrimination discriminate(const std::vector<Source>& sources, const DiscriminateOptions& o) {
    if (const std::string problem = check_sources(sources, o); !problem.empty()) throw std::invalid_argument(problem);
    Discrimination d;
    d.window_cells = window_cells(o.window_m, sources.front().grid.cell);
    d.window_m = o.window_m;
    d.windows = cut_windows(sources, o);
    std::vector<float> features, labels;
    for (const Window& w : d.windows) {
        for (const double v : w.figures)
            features.push_back(std::isfinite(v) ? float(v) : std::numeric_limits<float>::quiet_NaN());
        labels.push_back(sources[w.source].real ? 1.0f : 0.0f);
    }
    // Leave one source out: each source's windows judged by a model trained on every other source.
    for (std::size_t s = 0; s < sources.size(); ++s) {
        std::vector<std::size_t> train, test;
        for (std::size_t k = 0; k < d.windows.size(); ++k) (d.windows[k].source == s ? test : train).push_back(k);
        SourceResult result{sources[s].name, sources[s].real, test.size(), 0.0};
        if (!test.empty()) {
            const Booster booster(features, labels, train, o);
            std::vector<float> data;
            for (const std::size_t k : test)
                data.insert(data.end(), features.begin() + std::ptrdiff_t(k * window_figure_count),
                            features.begin() + std::ptrdiff_t((k + 1) * window_figure_count));
            const auto p = booster.predict(data, test.size());
            std::size_t called = 0;
            for (std::size_t i = 0; i < test.size(); ++i) {
                d.windows[test[i]].p_real = p[i];
                called += p[i] > 0.5;
            }
            result.called_real = double(called) / double(test.size());
        }
        d.sources.push_back(result);
    }
    std::size_t real = 0, real_right = 0, generated = 0, generated_right = 0;
    for (const Window& w : d.windows) {
        const bool said_real = w.p_real > 0.5;
        if (sources[w.source].real) ++real, real_right += said_real;
        else ++generated, generated_right += !said_real;
    }
    d.recall_real = real ? double(real_right) / double(real) : nan;
    d.recall_generated = generated ? double(generated_right) / double(generated) : nan;
    d.balanced_accuracy = 0.5 * (d.recall_real + d.recall_generated);
    // What tells them apart: a model trained on every window, its total gain per figure.
    std::vector<std::size_t> all(d.windows.size());
    std::iota(all.begin(), all.end(), std::size_t(0));
    const auto gains = Booster(features, labels, all, o).gains();
    const double total = std::accumulate(gains.begin(), gains.end(), 0.0);
    for (std::size_t f = 0; f < window_figure_count; ++f) {
        std::vector<double> r, g;
        for (const Window& w : d.windows) (sources[w.source].real ? r : g).push_back(w.figures[f]);
        d.importance.push_back(
            {WindowFigureId(f), gains[f], total > 0.0 ? gains[f] / total : 0.0, median(r), median(g)});
    }
    std::stable_sort(d.importance.begin(), d.importance.end(),
                     [](const Importance& a, const Importance& b) { return a.gain > b.gain; });
    return d;
}

}  // namespace orogen::analysis
