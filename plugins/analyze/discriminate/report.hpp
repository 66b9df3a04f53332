// report.hpp — what analyze:discriminate writes: the terminal table, discriminate.json and the picture of
// the most generated-looking windows beside the most real-looking ones, from orogen_analysis's
// Discrimination. Plain C++ over analysis types (and the hillshade of orogen_formats).
#pragma once

#include <orogen/analysis/discriminate.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace orogen::analyze {

/// The table `orogen analyze --discriminate` prints: the balanced accuracy, each source's share of windows
/// called real, the figures that tell apart most with their medians, and which windows the picture shows.
std::string discrimination_text(const analysis::Discrimination& d, std::size_t top_figures = 8);

/// discriminate.json: everything of the table, every figure with its definition and source, every window's
/// held-out probability of being real.
std::string discrimination_json(const analysis::Discrimination& d);

/// The windows the picture shows: `count` most generated-looking (lowest held-out probability of being real)
/// and `count` most real-looking, as indices into d.windows.
struct Shown {
    std::vector<std::size_t> generated_looking, real_looking;
};
Shown shown_windows(const analysis::Discrimination& d, std::size_t count = 6);

/// An 8-bit grey picture: the generated-looking windows hillshaded in the top row (each at its own samples), the real-looking ones in
/// the bottom row, 8 white samples between them; width and height out.
std::vector<std::uint16_t> discrimination_picture(const analysis::Discrimination& d,
                                                  const std::vector<analysis::Source>& sources, const Shown& shown,
                                                  int& width, int& height);

}  // namespace orogen::analyze
