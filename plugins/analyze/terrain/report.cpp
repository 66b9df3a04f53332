// The report's text forms: the comparison with the references, the terminal table, analysis.json and the
// Markdown page (report.hpp). The charts are in charts.cpp.
#include "report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace orogen::analyze {

namespace {

using analysis::figure_count;
using analysis::FigureId;

std::string format(double v, int decimals) {
    if (!std::isfinite(v)) return "-";
    char text[64];
    std::snprintf(text, sizeof text, "%.*f", decimals, v);
    return text;
}

std::string json_number(double v) {
    if (!std::isfinite(v)) return "null";
    char text[64];
    std::snprintf(text, sizeof text, "%.10g", v);
    return text;
}

std::string json_string(std::string_view s) {
    std::string out = "\"";
    for (char c : s) {
        switch (c) {
            case '"': out += "\\\""; break;
            case '\\': out += "\\\\"; break;
            case '\n': out += "\\n"; break;
            case '\t': out += "\\t"; break;
            default:
                if (static_cast<unsigned char>(c) < 0x20) {
                    char esc[8];
                    std::snprintf(esc, sizeof esc, "\\u%04x", unsigned(static_cast<unsigned char>(c)));
                    out += esc;
                } else {
                    out += c;
                }
        }
    }
    return out + "\"";
}

/// Display width of UTF-8 text: code points, not bytes (°, θ, β, ² are one column each).
std::size_t columns(std::string_view s) {
    std::size_t n = 0;
    for (char c : s) n += (static_cast<unsigned char>(c) & 0xC0) != 0x80;
    return n;
}

std::string pad(std::string_view s, std::size_t width, bool right = false) {
    const std::size_t w = columns(s);
    const std::string fill(width > w ? width - w : 0, ' ');
    return right ? fill + std::string(s) : std::string(s) + fill;
}

bool inside(const analysis::Band& band, double v) { return band.contains(v); }

}  // namespace

Comparison compare(const std::vector<Terrain>& terrains) {
    Comparison c;
    std::vector<const analysis::Figures*> references;
    for (const auto& t : terrains)
        if (t.reference) references.push_back(&t.figures);
    c.bands = analysis::reference_bands(references);
    c.nearest.resize(terrains.size());
    for (std::size_t i = 0; i < terrains.size(); ++i) {
        auto& best = c.nearest[i];
        for (std::size_t r = 0; r < terrains.size(); ++r) {
            if (!terrains[r].reference || r == i) continue;
            const analysis::Distance d = analysis::distance(terrains[i].figures, terrains[r].figures, c.bands);
            if (d.used == 0) continue;
            if (!best.reference || d.value < best.distance) {
                best.reference = r;
                best.distance = d.value;
                best.figures = d.used;
            }
        }
    }
    return c;
}

std::string table_text(const std::vector<Terrain>& terrains, const Comparison& comparison) {
    const bool have_references =
        std::any_of(terrains.begin(), terrains.end(), [](const Terrain& t) { return t.reference; });
    std::vector<std::string> head = {"figure", "unit"};
    for (const auto& t : terrains) head.push_back(t.reference ? t.name + "*" : t.name);
    if (have_references) {
        head.push_back("references");
        for (const auto& t : terrains)
            if (!t.reference) head.push_back(t.name);
    }
    std::vector<std::vector<std::string>> rows = {head};
    for (const auto& info : analysis::figure_table()) {
        const std::size_t f = std::size_t(info.id);
        std::vector<std::string> row = {std::string(info.label), std::string(info.unit)};
        for (const auto& t : terrains) row.push_back(format(t.figures.values[f].value, info.decimals));
        if (have_references) {
            const analysis::Band& band = comparison.bands[f];
            row.push_back(band.known ? format(band.low, info.decimals) + "–" + format(band.high, info.decimals) : "-");
            for (const auto& t : terrains) {
                if (t.reference) continue;
                const auto& m = t.figures.values[f];
                row.push_back(!band.known || !m.ok() ? "-" : inside(band, m.value) ? "in" : "OUT");
            }
        }
        rows.push_back(std::move(row));
    }
    std::vector<std::size_t> widths(head.size(), 0);
    for (const auto& row : rows)
        for (std::size_t c = 0; c < row.size(); ++c) widths[c] = std::max(widths[c], columns(row[c]));
    std::ostringstream out;
    for (const auto& row : rows) {
        std::string line;
        for (std::size_t c = 0; c < row.size(); ++c) {
            if (c > 0) line += "  ";
            line += pad(row[c], widths[c], c >= 2);
        }
        while (!line.empty() && line.back() == ' ') line.pop_back();
        out << line << '\n';
    }
    if (have_references) out << "(* a reference; 'references' is their min–max, 'in' a terrain inside it)\n";

    bool any_missing = false;
    for (const auto& t : terrains)
        for (const auto& info : analysis::figure_table()) {
            const auto& m = t.figures[info.id];
            if (m.ok()) continue;
            if (!any_missing) out << "\nnot measured:\n";
            any_missing = true;
            out << "  " << t.name << ": " << info.label << ": " << m.why_not << '\n';
        }
    bool any_nodata = false;
    for (const auto& t : terrains) {
        if (t.figures.nodata == 0) continue;
        if (!any_nodata) out << "\nnodata (masked, no figure reads them):\n";
        any_nodata = true;
        const double all = double(t.figures.samples + t.figures.nodata);
        char line[160];
        std::snprintf(line, sizeof line, "  %s: %zu of %.0f samples (%.2f %%)\n", t.name.c_str(), t.figures.nodata, all,
                      100.0 * double(t.figures.nodata) / all);
        out << line;
    }
    double smallest = 0.0, largest = 0.0;
    for (const auto& t : terrains) {
        smallest = smallest == 0.0 ? t.figures.cell : std::min(smallest, t.figures.cell);
        largest = std::max(largest, t.figures.cell);
    }
    if (terrains.size() > 1 && largest > 1.25 * smallest)
        out << "\nnote: the cell sizes differ (" << format(smallest, 1) << " m to " << format(largest, 1)
            << " m); slopes, pits, curvature and the network's figures depend on the cell size: compare "
               "terrains at the same cell size\n";
    const auto references =
        std::count_if(terrains.begin(), terrains.end(), [](const Terrain& t) { return t.reference; });
    if (references == 1 && std::size_t(references) < terrains.size())
        out << "\n(one reference: no spread to measure the distance to it by; give two or more to see which a "
               "terrain resembles most)\n";
    bool any_nearest = false;
    for (std::size_t i = 0; i < terrains.size(); ++i) {
        const auto& n = comparison.nearest[i];
        if (terrains[i].reference || !n.reference) continue;
        if (!any_nearest)
            out << "\nresembles most (RMS distance over the figures, in units of the references' spread):\n";
        any_nearest = true;
        out << "  " << terrains[i].name << ": " << terrains[*n.reference].name << " (" << format(n.distance, 2)
            << " over " << n.figures << " figures)\n";
    }
    return out.str();
}

std::string json_text(const std::vector<Terrain>& terrains, const Comparison& comparison) {
    std::ostringstream out;
    out << "{\n  \"format\": \"orogen-analysis 1\",\n  \"figures\": [\n";
    const auto table = analysis::figure_table();
    for (std::size_t f = 0; f < table.size(); ++f) {
        const auto& info = table[f];
        out << "    {\"key\": " << json_string(info.key) << ", \"label\": " << json_string(info.label)
            << ", \"unit\": " << json_string(info.unit) << ", \"definition\": " << json_string(info.definition)
            << ", \"source\": " << json_string(info.source) << "}" << (f + 1 < table.size() ? "," : "") << "\n";
    }
    out << "  ],\n  \"terrains\": [\n";
    for (std::size_t i = 0; i < terrains.size(); ++i) {
        const auto& t = terrains[i];
        const auto& g = t.figures;
        out << "    {\n      \"name\": " << json_string(t.name)
            << ",\n      \"reference\": " << (t.reference ? "true" : "false") << ",\n      \"width\": " << g.width
            << ", \"height\": " << g.height << ", \"cell_m\": " << json_number(g.cell)
            << ",\n      \"samples\": " << g.samples << ", \"nodata\": " << g.nodata
            << ", \"min_m\": " << json_number(g.minimum) << ", \"max_m\": " << json_number(g.maximum)
            << ",\n      \"figures\": {\n";
        for (std::size_t f = 0; f < table.size(); ++f) {
            const auto& m = g.values[f];
            out << "        " << json_string(table[f].key) << ": {\"value\": " << json_number(m.value)
                << ", \"unit\": " << json_string(table[f].unit);
            if (!m.ok()) out << ", \"why_not\": " << json_string(m.why_not);
            const analysis::Band& band = comparison.bands[f];
            if (!t.reference && band.known && m.ok())
                out << ", \"inside_references\": " << (inside(band, m.value) ? "true" : "false");
            out << "}" << (f + 1 < table.size() ? "," : "") << "\n";
        }
        out << "      }";
        const auto& n = comparison.nearest[i];
        if (n.reference)
            out << ",\n      \"nearest_reference\": {\"name\": " << json_string(terrains[*n.reference].name)
                << ", \"distance\": " << json_number(n.distance) << ", \"figures\": " << n.figures << "}";
        out << "\n    }" << (i + 1 < terrains.size() ? "," : "") << "\n";
    }
    out << "  ],\n  \"reference_bands\": {";
    bool first = true;
    for (std::size_t f = 0; f < table.size(); ++f) {
        const analysis::Band& band = comparison.bands[f];
        if (!band.known) continue;
        out << (first ? "\n" : ",\n") << "    " << json_string(table[f].key) << ": {\"min\": " << json_number(band.low)
            << ", \"max\": " << json_number(band.high) << ", \"sd\": " << json_number(band.spread) << "}";
        first = false;
    }
    out << (first ? "}\n}\n" : "\n  }\n}\n");
    return out.str();
}

std::string markdown_text(const std::vector<Terrain>& terrains, const Comparison& comparison,
                          const std::vector<Chart>& charts, const std::string& json_file) {
    std::ostringstream out;
    out << "# Terrain analysis\n\n";
    out << "Measured by `orogen analyze` (analyze:terrain); every figure with its definition and units is in [`"
        << json_file << "`](" << json_file << ").";
    if (std::any_of(terrains.begin(), terrains.end(), [](const Terrain& t) { return t.reference; }))
        out << " References (real DEMs) are marked *.";
    out << "\n\n";
    if (std::any_of(terrains.begin(), terrains.end(), [](const Terrain& t) { return !t.image.empty(); })) {
        out << "|";
        for (const auto& t : terrains) out << " " << t.name << (t.reference ? "*" : "") << " |";
        out << "\n|";
        for (std::size_t i = 0; i < terrains.size(); ++i) out << "---|";
        out << "\n|";
        for (const auto& t : terrains) {
            if (t.image.empty()) out << "  |";
            else out << " ![" << t.name << "](" << t.image << ") |";
        }
        out << "\n\n*Rendered by render:terrain, one camera for all.*\n\n";
    }
    out << "## Figures\n\n```\n" << table_text(terrains, comparison) << "```\n\n";
    if (!charts.empty()) {
        out << "## Charts\n\n";
        for (const auto& c : charts) out << "![" << c.title << "](" << c.file << ")\n\n";
    }
    out << "## Definitions\n\n| figure | unit | definition | source |\n|---|---|---|---|\n";
    for (const auto& info : analysis::figure_table())
        out << "| " << info.label << " | " << info.unit << " | " << info.definition << " | " << info.source << " |\n";
    return out.str();
}

}  // namespace orogen::analyze
