// image_srgb.hpp — a linear float frame (render passes) as 8-bit sRGB: an
// exposure, a tone curve for what exceeds 1, then the sRGB transfer function
// (IEC 61966-2-1). Shared by export:png and export:video, so a video frame and
// the PNG of the same frame hold the same colours.
#pragma once

#include <orogen/values.hpp>

#include <cstdint>
#include <string_view>
#include <vector>

namespace orogen::formats::srgb {

enum class Tonemap {
    clamp,  ///< values above 1 clip
    reinhard,  ///< c / (1 + c) on the luminance, hue kept
    aces,  ///< Narkowicz's fit of the ACES filmic curve, per channel
};

/// "clamp" | "reinhard" | "aces"; throws orogen::BadInput naming the choices otherwise.
Tonemap parse_tonemap(std::string_view name);

/// RGBA8 sRGB bytes of `image`, rows top to bottom. A float image is scaled
/// by 2^exposure, tone-mapped and encoded; its alpha is clamped to [0, 1].
/// An 8-bit image is returned as it is.
std::vector<std::uint8_t> to_srgb8(const Image& image, Tonemap tonemap, double exposure_stops);

}  // namespace orogen::formats::srgb
