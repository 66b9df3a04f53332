#include <orogen/formats/raw.hpp>

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
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

namespace fs = std::filesystem;

namespace orogen::formats::raw {

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
    if (format == Format::r16)
        s << ",\n  \"height_of_sample\": \"height_min + (height_max - height_min) * value / 65535\"";
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

}  // namespace orogen::formats::raw

// ------------------------------------------------------------------ reading

namespace orogen::formats::raw {

Sidecar parse_sidecar(std::string_view text, const std::string& name) {
    const nlohmann::json j = nlohmann::json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/false);
    if (j.is_discarded())
        throw BadInput("cannot read " + name + ": it is not valid JSON; export:raw writes it beside the RAW file");
    if (!j.is_object()) throw BadInput("cannot read " + name + ": a sidecar is a JSON object { \"width\": ..., ... }");
    auto field = [&](const char* key) -> const nlohmann::json& {
        auto it = j.find(key);
        if (it == j.end()) throw BadInput("cannot read " + name + ": \"" + key + "\" is missing");
        return *it;
    };
    auto size = [&](const char* key) {
        const auto& v = field(key);
        if (!v.is_number_integer() || v.get<std::int64_t>() < 1 || v.get<std::int64_t>() > 1000000)
            throw BadInput("cannot read " + name + ": \"" + key + "\" must be a whole number from 1 to 1000000, got " +
                           v.dump().substr(0, 40));
        return int(v.get<std::int64_t>());
    };
    auto real = [&](const char* key) {
        const auto& v = field(key);
        if (!v.is_number() || !std::isfinite(v.get<double>()))
            throw BadInput("cannot read " + name + ": \"" + key + "\" must be a finite number, got " +
                           v.dump().substr(0, 40));
        return v.get<double>();
    };
    Sidecar s;
    const auto& format = field("format");
    if (format == "r16") s.format = Format::r16;
    else if (format == "r32") s.format = Format::r32;
    else
        throw BadInput("cannot read " + name + ": \"format\" must be \"r16\" or \"r32\", got " +
                       format.dump().substr(0, 40));
    if (auto it = j.find("byte_order"); it != j.end() && *it != "little-endian")
        throw BadInput("cannot read " + name + ": \"byte_order\" must be \"little-endian\", got " +
                       it->dump().substr(0, 40));
    s.width = size("width");
    s.height = size("height");
    s.cell = real("cell_size");
    if (!(s.cell > 0))
        throw BadInput("cannot read " + name + ": \"cell_size\" must be above 0 m, got " + number(s.cell));
    s.range.low = real("height_min");
    s.range.high = real("height_max");
    if (s.range.high < s.range.low)
        throw BadInput("cannot read " + name + ": \"height_max\" (" + number(s.range.high) +
                       ") is below \"height_min\" (" + number(s.range.low) + ")");
    return s;
}

Sidecar read_raw_header(const fs::path& file) {
    const Format format = format_of(file);
    const fs::path sidecar = fs::path(file.string() + ".json");
    if (const std::string problem = regular_file_problem(sidecar); !problem.empty())
        throw BadInput("cannot read " + file.string() + ": its sidecar " + sidecar.string() + " " + problem +
                       "; a RAW file says nothing of its size, so the sidecar export:raw writes must sit beside it");
    const auto bytes = read_file(sidecar);
    if (bytes.size() > (1u << 20))
        throw BadInput("cannot read " + sidecar.string() + ": " + human_bytes(double(bytes.size())) +
                       " is far too big for a sidecar (at most 1 MiB)");
    Sidecar s =
        parse_sidecar(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), sidecar.string());
    if (s.format != format)
        throw BadInput("cannot read " + file.string() + ": the sidecar says " +
                       (s.format == Format::r16 ? "r16" : "r32") + ", but the file's extension says " +
                       file.extension().string());
    if (const std::string problem = heightmap_memory_problem(s.width, s.height); !problem.empty())
        throw BadInput("cannot read " + file.string() + ": its sidecar declares " + std::to_string(s.width) + "x" +
                       std::to_string(s.height) + " samples, which " + problem);
    if (const std::string problem = regular_file_problem(file); !problem.empty())
        throw BadInput("cannot read " + file.string() + ": it " + problem);
    const std::uint64_t want = std::uint64_t(s.width) * std::uint64_t(s.height) * (format == Format::r16 ? 2 : 4);
    std::error_code ec;
    const std::uint64_t have = fs::file_size(file, ec);
    if (ec || have != want)
        throw BadInput("cannot read " + file.string() + ": it holds " + std::to_string(have) +
                       " bytes, but its sidecar's " + std::to_string(s.width) + "x" + std::to_string(s.height) + " " +
                       (format == Format::r16 ? "16-bit" : "32-bit") + " samples need exactly " + std::to_string(want) +
                       (have < want ? "; it is truncated" : "; the sidecar belongs to another file"));
    return s;
}

std::vector<float> read_raw(const fs::path& file, Sidecar& info) {
    info = read_raw_header(file);
    std::ifstream in(file, std::ios::binary);
    if (!in) throw BadInput("cannot read " + file.string() + ": " + std::strerror(errno));
    const std::size_t w = std::size_t(info.width), h = std::size_t(info.height);
    std::vector<float> heights(w * h);
    const std::size_t sample = info.format == Format::r16 ? 2 : 4;
    std::vector<std::uint8_t> row(w * sample);
    for (std::size_t y = 0; y < h; ++y) {
        if (!in.read(reinterpret_cast<char*>(row.data()), std::streamsize(row.size())))
            throw BadInput("cannot read " + file.string() + ": it ends in row " + std::to_string(y) + " of " +
                           std::to_string(h) + " (it changed while being read?)");
        float* dst = heights.data() + y * w;
        for (std::size_t x = 0; x < w; ++x) {
            const std::uint8_t* b = &row[x * sample];
            if (info.format == Format::r16) {
                dst[x] = float(dequantize16(std::uint16_t(b[0] | (b[1] << 8)), info.range));
            } else {
                const std::uint32_t bits = std::uint32_t(b[0]) | (std::uint32_t(b[1]) << 8) |
                    (std::uint32_t(b[2]) << 16) | (std::uint32_t(b[3]) << 24);
                dst[x] = std::bit_cast<float>(bits);
                if (!std::isfinite(dst[x]))
                    throw BadInput("cannot read " + file.string() + ": sample (" + std::to_string(x) + ", " +
                                   std::to_string(y) + ") is not a finite number");
            }
        }
    }
    return heights;
}

}  // namespace orogen::formats::raw
