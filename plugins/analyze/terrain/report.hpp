// report.hpp — the analysis report of analyze:terrain (and so of `orogen analyze`): the terminal table,
// analysis.json, the charts and the Markdown page, from orogen_analysis's figures of several terrains,
// some of them references (real DEMs) that the others are compared with.
//
// Plain C++ over analysis::Figures: no kernel types but the atomic files.
#pragma once

#include <orogen/analysis/compare.hpp>
#include <orogen/analysis/figures.hpp>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace orogen::analyze {

struct Terrain {
    std::string name;  ///< as the table and the charts label it
    analysis::Figures figures;
    bool reference = false;  ///< one of the --against DEMs
    std::string image;  ///< its rendering, relative to the Markdown page ("" = none)
};

/// What the references say of the terrains: each figure's band, and each terrain's nearest reference.
struct Comparison {
    analysis::Bands bands;  ///< by FigureId
    /// For each terrain (in order; references included, compared with the others): the nearest reference's
    /// index and the distance, the root mean square over the figures both measured and the references
    /// spread over (nonzero standard deviation) of the difference in units of that spread.
    struct Nearest {
        std::optional<std::size_t> reference;
        double distance = 0.0;
        std::size_t figures = 0;  ///< how many figures entered the distance
    };
    std::vector<Nearest> nearest;
};

Comparison compare(const std::vector<Terrain>& terrains);

/// The terminal table: one row per figure, one column per terrain (references marked *), then the
/// references' range and, for each other terrain, whether it is inside; then why figures are missing,
/// nodata counts, and which reference each terrain resembles most.
std::string table_text(const std::vector<Terrain>& terrains, const Comparison& comparison);

/// analysis.json: every figure with its key, label, unit, definition and source, per terrain; the bands.
std::string json_text(const std::vector<Terrain>& terrains, const Comparison& comparison);

/// A chart file, relative to the report's folder, with its title.
struct Chart {
    std::string file;
    std::string title;
};

struct ChartsWritten {
    std::vector<Chart> charts;  ///< those drawn (a chart no terrain has data for is left out)
    std::string problem;  ///< "" or why none was drawn (gnuplot missing: install gnuplot-nox)
};

/// Draws the charts with gnuplot (pngcairo) into `folder` as `stem`-slopes.png, -hypsometry.png,
/// -spectrum.png, -slope-area.png and -hack.png, each through a temporary name and a rename, all committed
/// together once every one is drawn.
ChartsWritten write_charts(const std::vector<Terrain>& terrains, const std::filesystem::path& folder,
                           const std::string& stem);

/// The Markdown page: the renderings side by side, the table, the charts, the definitions.
std::string markdown_text(const std::vector<Terrain>& terrains, const Comparison& comparison,
                          const std::vector<Chart>& charts, const std::string& json_file);

}  // namespace orogen::analyze
