// The .f32 + .json reader (f32_reader.hpp).
#include "f32_reader.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>

#include <bit>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <numbers>
#include <optional>
#include <string>

namespace orogen::f32 {

namespace {

/// The number after "key": in flat JSON, or nullopt if the key is absent. Throws if it is not a number.
std::optional<double> number(std::string_view json, std::string_view key, const std::string& name) {
    std::string quoted(1, '"');  // (not "\"" + key + "\"": GCC 12 warns falsely of an overlapping memcpy there)
    quoted.append(key).push_back('"');
    const auto at = json.find(quoted);
    if (at == std::string_view::npos) return std::nullopt;
    std::size_t i = at + quoted.size();
    while (i < json.size() && (json[i] == ' ' || json[i] == '\t' || json[i] == '\n' || json[i] == '\r')) ++i;
    if (i >= json.size() || json[i] != ':') throw BadInput(name + ": '" + std::string(key) + "' has no value");
    ++i;
    const std::string rest(json.substr(i, std::min<std::size_t>(64, json.size() - i)));
    char* end = nullptr;
    const double v = std::strtod(rest.c_str(), &end);
    if (end == rest.c_str() || !std::isfinite(v)) throw BadInput(name + ": '" + std::string(key) + "' is not a number");
    return v;
}

int side(std::string_view json, std::string_view key, const std::string& name) {
    const auto v = number(json, key, name);
    if (!v) throw BadInput(name + ": no '" + std::string(key) + "' (the number of samples along that axis)");
    if (*v < 1 || *v > 1e7 || *v != std::floor(*v))
        throw BadInput(name + ": '" + std::string(key) + "' must be a whole number of samples from 1 to 10000000");
    return int(*v);
}

}  // namespace

Description parse_description(std::string_view json, const std::string& name) {
    Description d;
    d.width = side(json, "nx", name);
    d.height = side(json, "ny", name);
    if (const auto dx = number(json, "dx_m", name)) {
        if (!(*dx > 0.0) || *dx > 1e6)
            throw BadInput(name + ": 'dx_m' must be a number of metres above 0, at most 1e6");
        d.cell = *dx;
    } else if (const auto lat0 = number(json, "lat0", name), dlat = number(json, "dlat", name),
               dlon = number(json, "dlon", name);
               lat0 && dlat && dlon) {
        const double lat = *lat0 + *dlat * d.height / 2.0;
        d.cell = std::abs(*dlon) * 111320.0 * std::cos(lat * std::numbers::pi / 180.0);
        if (!(d.cell > 0.0) || d.cell > 1e6)
            throw BadInput(name + ": 'dlon' and the latitude give no cell size between 0 and 1e6 m");
    }
    return d;
}

Description read_description(const std::filesystem::path& file) {
    std::filesystem::path json = file;
    json.replace_extension(".json");
    std::error_code ec;
    if (!std::filesystem::exists(json, ec))
        throw BadInput(file.string() + " needs its description " + json.string() +
                       " (nx, ny, dx_m), which does not exist");
    if (std::filesystem::file_size(json, ec) > (1u << 20))
        throw BadInput(json.string() + " is larger than 1 MiB: not the description of a grid");
    const auto bytes = read_file(json);
    const Description d =
        parse_description(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), json.string());
    if (const std::string problem = heightmap_memory_problem(d.width, d.height); !problem.empty())
        throw BadInput(json.string() + " declares " + std::to_string(d.width) + "x" + std::to_string(d.height) +
                       " samples, which " + problem);
    if (const std::string problem = regular_file_problem(file); !problem.empty())
        throw BadInput(file.string() + " " + problem);
    const auto size = std::filesystem::file_size(file, ec);
    const std::uintmax_t expected = std::uintmax_t(d.width) * std::uintmax_t(d.height) * 4u;
    if (ec || size != expected)
        throw BadInput(file.string() + " holds " + std::to_string(size) + " bytes, but " + json.filename().string() +
                       " declares " + std::to_string(d.width) + "x" + std::to_string(d.height) + " float32 samples (" +
                       std::to_string(expected) + " bytes)");
    return d;
}

std::vector<float> read_heights(const std::filesystem::path& file, const Description& d) {
    static_assert(std::endian::native == std::endian::little, "the .f32 samples are little-endian");
    std::vector<float> heights(std::size_t(d.width) * std::size_t(d.height));
    std::ifstream in(file, std::ios::binary);
    in.read(reinterpret_cast<char*>(heights.data()), std::streamsize(heights.size() * sizeof(float)));
    if (!in) throw BadInput("cannot read " + file.string() + ": it ended early or could not be read");
    return heights;
}

}  // namespace orogen::f32
