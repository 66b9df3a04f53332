// The table, JSON and picture of analyze:discriminate (report.hpp).
#include "report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <sstream>

namespace orogen::analyze {

namespace {

constexpr int gap = 8;  ///< white samples between the picture's thumbnails

std::string fixed(double v, int decimals) {
    if (!std::isfinite(v)) return "-";
    char text[64];
    std::snprintf(text, sizeof text, "%.*f", decimals, v);
    return text;
}

/// A JSON number (null for NaN), round-trippable.
std::string number(double v) {
    if (!std::isfinite(v)) return "null";
    char text[40];
    std::snprintf(text, sizeof text, "%.10g", v);
    return text;
}

std::string quoted(std::string_view s) {
    std::string out = "\"";
    for (const char c : s) {
        if (c == '"' || c == '\\') out += '\\';
        if (static_cast<unsigned char>(c) < 0x20) {
            char esc[8];
            std::snprintf(esc, sizeof esc, "\\u%04x", c);
            out += esc;
            continue;
        }
        out += c;
    }
    return out + "\"";
}

std::string pad(const std::string& s, std::size_t width) {
    // Count code points, not bytes, so "°" pads as one column.
    std::size_t columns = 0;
    for (const char c : s) columns += (static_cast<unsigned char>(c) & 0xC0) != 0x80;
    return s + std::string(width > columns ? width - columns : 0, ' ');
}

const analysis::WindowFigureInfo& info(analysis::WindowFigureId id) {
    return analysis::window_figure_table()[std::size_t(id)];
}

std::string window_line(const analysis::Discrimination& d, std::size_t k) {
    const auto& w = d.windows[k];
    char text[200];
    std::snprintf(text, sizeof text, "%s at x %d, y %d (p real %.2f)", d.sources[w.source].name.c_str(), w.x, w.y,
                  w.p_real);
    return text;
}

/// Lambertian hillshade of an n × n window (0..255): light from the north-west, 45° up, heights true to scale,
/// central differences (one-sided at the edges), the same for every window so that they compare.
std::vector<std::uint16_t> hillshade(const std::vector<float>& z, int n, double cell) {
    const double light[3] = {-0.5, 0.5, std::sqrt(0.5)};  // x east, y north, z up: from the north-west
    std::vector<std::uint16_t> shade(z.size());
    auto at = [&](int x, int y) { return double(z[std::size_t(y) * std::size_t(n) + std::size_t(x)]); };
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const int x0 = std::max(0, x - 1), x1 = std::min(n - 1, x + 1);
            const int y0 = std::max(0, y - 1), y1 = std::min(n - 1, y + 1);
            const double dzdx = (at(x1, y) - at(x0, y)) / (double(x1 - x0) * cell);
            const double dzdn = -(at(x, y1) - at(x, y0)) / (double(y1 - y0) * cell);  // rows run south
            const double norm = std::sqrt(dzdx * dzdx + dzdn * dzdn + 1.0);
            const double lit = (-dzdx * light[0] - dzdn * light[1] + light[2]) / norm;
            shade[std::size_t(y) * std::size_t(n) + std::size_t(x)] =
                std::uint16_t(std::lround(255.0 * std::clamp(lit, 0.0, 1.0)));
        }
    return shade;
}

}  // namespace

Shown shown_windows(const analysis::Discrimination& d, std::size_t count) {
    std::vector<std::size_t> order(d.windows.size());
    std::iota(order.begin(), order.end(), std::size_t(0));
    // Ties (equal probabilities) keep the windows' order: the same picture every run.
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return d.windows[a].p_real < d.windows[b].p_real; });
    Shown s;
    const std::size_t n = std::min(count, order.size() / 2);
    s.generated_looking.assign(order.begin(), order.begin() + std::ptrdiff_t(n));
    s.real_looking.assign(order.rbegin(), order.rbegin() + std::ptrdiff_t(n));
    return s;
}

std::string discrimination_text(const analysis::Discrimination& d, std::size_t top_figures) {
    std::ostringstream s;
    std::size_t real = 0, generated = 0;
    for (const auto& src : d.sources) (src.real ? real : generated) += 1;
    s << "telling real from generated terrain, window by window (leave one source out; " << real << " real, "
      << generated << " generated)\n";
    // Each source's windows in its own cells: list every distinct side.
    std::vector<int> sides;
    for (const auto& w : d.windows)
        if (std::find(sides.begin(), sides.end(), w.cells) == sides.end()) sides.push_back(w.cells);
    s << "windows of " << fixed(d.window_m, 0) << " m (";
    for (std::size_t i = 0; i < sides.size(); ++i) s << (i ? ", " : "") << sides[i] << " x " << sides[i] << " samples";
    s << "), " << d.windows.size() << " in all\n\n";
    s << "balanced accuracy  " << fixed(100.0 * d.balanced_accuracy, 1)
      << " %   (50 %: not told apart; real windows called real " << fixed(100.0 * d.recall_real, 1)
      << " %, generated called generated " << fixed(100.0 * d.recall_generated, 1) << " %)\n\n";
    std::size_t name_width = 6;
    for (const auto& src : d.sources) name_width = std::max(name_width, src.name.size());
    s << pad("source", name_width) << "  kind       windows  called real\n";
    for (const auto& src : d.sources)
        s << pad(src.name, name_width) << "  " << pad(src.real ? "real" : "generated", 9) << "  "
          << pad(std::to_string(src.windows), 7) << "  " << fixed(100.0 * src.called_real, 1) << " %\n";
    s << "\nthe figures that tell apart most (XGBoost total gain, model on every window):\n";
    s << pad("figure", 18) << pad("unit", 6) << pad("gain %", 8) << pad("real median", 13) << "generated median\n";
    for (std::size_t i = 0; i < std::min(top_figures, d.importance.size()); ++i) {
        const auto& imp = d.importance[i];
        const auto& fi = info(imp.figure);
        s << pad(std::string(fi.label), 18) << pad(std::string(fi.unit), 6) << pad(fixed(100.0 * imp.share, 1), 8)
          << pad(fixed(imp.median_real, fi.decimals), 13) << fixed(imp.median_generated, fi.decimals) << "\n";
    }
    const Shown shown = shown_windows(d);
    s << "\nthe picture: top row the most generated-looking windows, bottom row the most real-looking, left to "
         "right:\n";
    for (const std::size_t k : shown.generated_looking) s << "  top     " << window_line(d, k) << "\n";
    for (const std::size_t k : shown.real_looking) s << "  bottom  " << window_line(d, k) << "\n";
    return s.str();
}

std::string discrimination_json(const analysis::Discrimination& d) {
    std::ostringstream s;
    s << "{\n  \"window_cells\": " << d.window_cells << ",\n  \"window_m\": " << number(d.window_m)
      << ",\n  \"windows_count\": " << d.windows.size() << ",\n  \"balanced_accuracy\": " << number(d.balanced_accuracy)
      << ",\n  \"recall_real\": " << number(d.recall_real)
      << ",\n  \"recall_generated\": " << number(d.recall_generated)
      << ",\n  \"classifier\": \"XGBoost (binary:logistic, hist, class-balanced weights, one thread, fixed seed), "
         "leave one source out\",\n  \"sources\": [";
    for (std::size_t i = 0; i < d.sources.size(); ++i) {
        const auto& src = d.sources[i];
        s << (i ? "," : "") << "\n    {\"name\": " << quoted(src.name)
          << ", \"real\": " << (src.real ? "true" : "false") << ", \"windows\": " << src.windows
          << ", \"called_real\": " << number(src.called_real) << "}";
    }
    s << "\n  ],\n  \"figures\": [";
    for (std::size_t i = 0; i < d.importance.size(); ++i) {
        const auto& imp = d.importance[i];
        const auto& fi = info(imp.figure);
        s << (i ? "," : "") << "\n    {\"key\": " << quoted(fi.key) << ", \"label\": " << quoted(fi.label)
          << ", \"unit\": " << quoted(fi.unit) << ", \"gain\": " << number(imp.gain)
          << ", \"gain_share\": " << number(imp.share) << ", \"median_real\": " << number(imp.median_real)
          << ", \"median_generated\": " << number(imp.median_generated) << ", \"definition\": " << quoted(fi.definition)
          << ", \"source\": " << quoted(fi.source) << "}";
    }
    s << "\n  ],\n  \"windows\": [";
    for (std::size_t k = 0; k < d.windows.size(); ++k) {
        const auto& w = d.windows[k];
        s << (k ? "," : "") << "\n    {\"source\": " << quoted(d.sources[w.source].name) << ", \"x\": " << w.x
          << ", \"y\": " << w.y << ", \"p_real\": " << number(w.p_real) << ", \"figures\": [";
        for (std::size_t f = 0; f < w.figures.size(); ++f) s << (f ? ", " : "") << number(w.figures[f]);
        s << "]}";
    }
    const Shown shown = shown_windows(d);
    s << "\n  ],\n  \"picture\": {\"top_generated_looking\": [";
    for (std::size_t i = 0; i < shown.generated_looking.size(); ++i) s << (i ? ", " : "") << shown.generated_looking[i];
    s << "], \"bottom_real_looking\": [";
    for (std::size_t i = 0; i < shown.real_looking.size(); ++i) s << (i ? ", " : "") << shown.real_looking[i];
    s << "]}\n}\n";
    return s.str();
}

std::vector<std::uint16_t> discrimination_picture(const analysis::Discrimination& d,
                                                  const std::vector<analysis::Source>& sources, const Shown& shown,
                                                  int& width, int& height) {
    int n = 0;  // the thumbnails' slot: the largest window shown
    for (const auto* row : {&shown.generated_looking, &shown.real_looking})
        for (const std::size_t k : *row) n = std::max(n, d.windows[k].cells);
    const int columns = int(std::max(shown.generated_looking.size(), shown.real_looking.size()));
    width = std::max(1, columns * n + (columns + 1) * gap);
    height = 2 * n + 3 * gap;
    std::vector<std::uint16_t> picture(std::size_t(width) * std::size_t(height), 255);
    auto draw = [&](const std::vector<std::size_t>& row, int top) {
        for (std::size_t c = 0; c < row.size(); ++c) {
            const auto& w = d.windows[row[c]];
            const auto& g = sources[w.source].grid;
            const int m = w.cells;  // this window's side, drawn in the top-left of its slot
            std::vector<float> z(std::size_t(m) * std::size_t(m));
            for (int y = 0; y < m; ++y)
                for (int x = 0; x < m; ++x)
                    z[std::size_t(y) * std::size_t(m) + std::size_t(x)] =
                        g.heights[std::size_t(w.y + y) * std::size_t(g.width) + std::size_t(w.x + x)];
            const auto shade = hillshade(z, m, g.cell);
            const int left = gap + int(c) * (n + gap);
            for (int y = 0; y < m; ++y)
                for (int x = 0; x < m; ++x)
                    picture[std::size_t(top + y) * std::size_t(width) + std::size_t(left + x)] =
                        shade[std::size_t(y) * std::size_t(m) + std::size_t(x)];
        }
    };
    draw(shown.generated_looking, gap);
    draw(shown.real_looking, 2 * gap + n);
    return picture;
}

}  // namespace orogen::analyze
