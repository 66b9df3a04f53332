#include <orogen/formats/image_srgb.hpp>

#include <orogen/error.hpp>
#include <orogen/parallel.hpp>

#include <algorithm>
#include <cmath>
#include <string>

namespace orogen::formats::srgb {

Tonemap parse_tonemap(std::string_view name) {
    if (name == "clamp") return Tonemap::clamp;
    if (name == "reinhard") return Tonemap::reinhard;
    if (name == "aces") return Tonemap::aces;
    throw BadInput("unknown tone curve '" + std::string(name) + "'; use clamp, reinhard or aces");
}

namespace {

// The sRGB encoding of a linear value in [0, 1] as an 8-bit code, from a
// 4096-entry table (finer than 8-bit steps everywhere but the darkest codes,
// which take the exact formula).
struct SrgbTable {
    std::uint8_t codes[4097];
    SrgbTable() {
        for (int i = 0; i <= 4096; ++i) codes[i] = exact(i / 4096.0);
    }
    static std::uint8_t exact(double v) {
        const double s = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
        return std::uint8_t(std::clamp(std::lround(s * 255.0), 0L, 255L));
    }
    std::uint8_t operator()(float v) const {
        if (!(v > 0)) return 0;
        if (v >= 1) return 255;
        if (v < 0.01f) return exact(v);
        return codes[int(v * 4096.0f + 0.5f)];
    }
};

}  // namespace

std::vector<std::uint8_t> to_srgb8(const Image& image, Tonemap tonemap, double exposure_stops) {
    if (image.format == Image::Format::rgba8) return image.rgba8;
    static const SrgbTable table;
    const std::size_t n = std::size_t(image.width) * std::size_t(image.height);
    if (image.rgba32f.size() != 4 * n) throw Error("internal error: the image's pixels do not match its size");
    std::vector<std::uint8_t> out(4 * n);
    const float scale = float(std::exp2(exposure_stops));
    parallel_for(0, std::int64_t(n), 1 << 14, [&](std::int64_t b, std::int64_t e) {
        for (std::int64_t i = b; i < e; ++i) {
            const float* p = &image.rgba32f[4 * std::size_t(i)];
            float c[3] = {p[0] * scale, p[1] * scale, p[2] * scale};
            if (tonemap == Tonemap::reinhard) {
                const float l = 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2];
                const float k = l > 0 ? 1.0f / (1.0f + l) : 1.0f;
                for (float& v : c) v *= k;
            } else if (tonemap == Tonemap::aces) {
                for (float& v : c) {
                    v = std::max(v, 0.0f);
                    v = (v * (2.51f * v + 0.03f)) / (v * (2.43f * v + 0.59f) + 0.14f);
                }
            }
            std::uint8_t* q = &out[4 * std::size_t(i)];
            for (int k = 0; k < 3; ++k) q[k] = table(c[k]);
            q[3] = std::uint8_t(std::lround(std::clamp(p[3], 0.0f, 1.0f) * 255.0f));
        }
    });
    return out;
}

}  // namespace orogen::formats::srgb
