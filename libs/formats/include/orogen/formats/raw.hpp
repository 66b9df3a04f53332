// raw.hpp — heightmaps as headerless RAW files for engines and terrain tools.
//
//   .r16  unsigned 16-bit little-endian; 0 = low, 65535 = high (the terrain's
//         own min–max unless a range is given), as World Machine, Unity and
//         Unreal read them;
//   .r32  32-bit float little-endian, metres.
// Rows run north to south (sample (x, y) at index y·width + x), no header.
// A sidecar JSON (<file>.json) gives width, height, cell size, height range
// and format, since the RAW file itself says nothing.
#pragma once

#include <orogen/grid.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace orogen::formats::raw {

enum class Format { r16, r32 };

/// .r16 → r16, .r32 → r32; throws orogen::BadInput for anything else.
Format format_of(const std::filesystem::path& file);

/// Heights in metres: the lowest and highest sample.
struct Range {
    double low = 0.0, high = 0.0;
};
Range min_max(ConstGridView heights);

/// round((h − low) / (high − low) · 65535), clamped to 0..65535; all 0 if high == low.
std::vector<std::uint16_t> quantize16(ConstGridView heights, Range range, std::size_t* clamped = nullptr);
/// The height a 16-bit sample stands for.
inline double dequantize16(std::uint16_t v, Range range) { return range.low + (range.high - range.low) * v / 65535.0; }

struct Written {
    Range range;  ///< the range written to the sidecar
    std::size_t clamped = 0;  ///< samples outside a given range (r16 only)
    std::filesystem::path sidecar;
};

/// Write `heights` to `target` (.r16 or .r32) and the sidecar `target`.json,
/// both atomically and together. `range` (r16 only): the heights mapped to 0
/// and 65535; nullopt = the terrain's own min–max.
Written write_raw(ConstGridView heights, const std::filesystem::path& target,
                  std::optional<Range> range = std::nullopt);

/// The sidecar's text (JSON).
std::string sidecar_json(Format format, int width, int height, double cell, Range range);

// ------------------------------------------------------------------ reading

/// What a sidecar declares.
struct Sidecar {
    Format format = Format::r16;
    int width = 0, height = 0;
    double cell = 1.0;  ///< metres
    Range range;  ///< r16: heights of 0 and 65535, metres
};

/// Parse a sidecar's text. Throws orogen::BadInput naming `name` and the field that is wrong (not JSON,
/// missing, wrong type, out of range), so hostile text ends in one clear message.
Sidecar parse_sidecar(std::string_view json, const std::string& name);

/// Read `file`'s sidecar (`file`.json) and check, before anything is allocated: the format matches the
/// extension, the declared size fits the memory budget (orogen::heightmap_memory_problem), and `file` holds
/// exactly width × height samples (a short file is refused, not padded). Throws orogen::BadInput.
Sidecar read_raw_header(const std::filesystem::path& file);

/// read_raw_header(), then the samples, a row at a time, as heights in metres (r16 dequantised).
std::vector<float> read_raw(const std::filesystem::path& file, Sidecar& info);

}  // namespace orogen::formats::raw
