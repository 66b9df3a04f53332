// f32_reader.hpp — NAME.f32 (little-endian float32, rows north to south) described by NAME.json: `nx`,
// `ny` and either `dx_m` (metres) or a geographic grid's `lat0`, `dlat`, `dlon` (degrees; the cell is
// dlon converted at the mid latitude, 111 320 m a degree times its cosine, as terrain_stats.py does).
#pragma once

#include <filesystem>
#include <string_view>
#include <vector>

namespace orogen::f32 {

struct Description {
    int width = 0, height = 0;
    double cell = 0.0;  ///< metres; 0 if the description gives none
};

/// Parses the JSON description's text; `name` only names it in messages. Throws orogen::BadInput naming
/// the field that is missing or wrong.
Description parse_description(std::string_view json, const std::string& name);

/// NAME.json beside `file`, checked against the memory budget and `file`'s length before anything is read.
/// Throws orogen::BadInput.
Description read_description(const std::filesystem::path& file);

/// The heights, width × height floats, rows north to south.
std::vector<float> read_heights(const std::filesystem::path& file, const Description& d);

}  // namespace orogen::f32
