#include "raw.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/parallel.hpp>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <iomanip>
#include <limits>
#include <sstream>

namespace fs = std::filesystem;

namespace orogen::raw {

Format format_of(const fs::path& file) {
    const std::string ext = file.extension().string();
    if (ext == ".r16") return Format::r16;
    if (ext == ".r32") return Format::r32;
    throw BadInput("export:raw writes .r16 or .r32 files; '" + file.filename().string() + "' has another extension");
}

Range min_max(ConstGridView h) {
    if (h.size() == 0) return {};
    const auto [lo, hi] = std::minmax_element(h.data, h.data + h.size());
    return {double(*lo), double(*hi)};
}

std::vector<std::uint16_t> quantize16(ConstGridView h, Range range, std::size_t* clamped) {
    std::vector<std::uint16_t> out(h.size(), 0);
    const double span = range.high - range.low;
    if (!(span > 0)) return out;
    const double k = 65535.0 / span;
    std::atomic<std::size_t> outside{0};
    parallel_for(0, std::int64_t(h.size()), 1 << 16, [&](std::int64_t b, std::int64_t e) {
        std::size_t n = 0;
        for (std::int64_t i = b; i < e; ++i) {
            const double v = (double(h.data[i]) - range.low) * k;
            if (v < -0.5 || v > 65535.5) ++n;
            out[std::size_t(i)] = std::uint16_t(std::clamp(std::lround(v), 0L, 65535L));
        }
        outside += n;
    });
    if (clamped) *clamped = outside;
    return out;
}

namespace {
std::string number(double v) {
    std::ostringstream s;
    s << std::setprecision(std::numeric_limits<double>::max_digits10) << v;
    return s.str();
}
}  // namespace

std::string sidecar_json(Format format, int width, int height, double cell, Range range) {
    std::ostringstream s;
    s << "{\n"
      << "  \"format\": \"" << (format == Format::r16 ? "r16" : "r32") << "\",\n"
      << "  \"sample_type\": \"" << (format == Format::r16 ? "uint16" : "float32") << "\",\n"
      << "  \"byte_order\": \"little-endian\",\n"
      << "  \"width\": " << width << ",\n"
      << "  \"height\": " << height << ",\n"
      << "  \"cell_size\": " << number(cell) << ",\n"
      << "  \"height_min\": " << number(range.low) << ",\n"
      << "  \"height_max\": " << number(range.high) << ",\n"
      << "  \"units\": \"m\",\n"
      << "  \"layout\": \"rows north to south, samples west to east, no header\"";
    if (format == Format::r16) s << ",\n  \"height_of_sample\": \"height_min + (height_max - height_min) * value / 65535\"";
    s << "\n}\n";
    return s.str();
}

Written write_raw(ConstGridView h, const fs::path& target, std::optional<Range> range) {
    const Format format = format_of(target);
    if (range && !(range->high > range->low))
        throw BadInput("the height range must have high > low, got low=" + number(range->low) +
                       " high=" + number(range->high));
    Written w;
    w.range = range ? *range : min_max(h);
    w.sidecar = fs::path(target.string() + ".json");
    AtomicFile file(target);
    AtomicFile sidecar(w.sidecar);
    if (format == Format::r16) {
        auto q = quantize16(h, w.range, &w.clamped);
        if constexpr (std::endian::native != std::endian::little)
            for (auto& v : q) v = std::uint16_t((v >> 8) | (v << 8));
        file.write({reinterpret_cast<const std::uint8_t*>(q.data()), q.size() * 2});
    } else {
        static_assert(std::endian::native == std::endian::little, "r32 writing assumes a little-endian machine");
        file.write({reinterpret_cast<const std::uint8_t*>(h.data), h.size() * 4});
    }
    const std::string json = sidecar_json(format, h.width, h.height, h.cell, w.range);
    sidecar.write({reinterpret_cast<const std::uint8_t*>(json.data()), json.size()});
    AtomicFile* files[] = {&file, &sidecar};
    commit_all(files);
    return w;
}

}  // namespace orogen::raw
