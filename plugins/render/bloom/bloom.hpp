// bloom.hpp — the thesis's bloom (§3.7.2) as separate passes over linear float
// images, drawn through OSMesa: bright pass (Reinhard-mapped threshold),
// separable Gaussian blur (one axis per pass), combine (original + strength ×
// blurred bright pass), and the chain of all of them.
//
// Plain C++ over orogen::Image (RGBA; 8-bit sRGB inputs are decoded to
// linear); the GL calls stay in bloom.cpp. Outputs are always Format::rgba32f.
#pragma once

#include <orogen/values.hpp>

#include <vector>

namespace orogen::render {

/// The bright pass's constants (the thesis's defaults).
struct BrightPass {
    double average_luminance = 0.5;  ///< the scene's assumed mean luminance
    double middle_grey = 0.5;  ///< what that mean is scaled to
    double white = 1.5;  ///< the luminance Reinhard's curve maps to 1 (after scaling)
    double threshold = 0.4;  ///< mapped luminance below this is dropped
    int scale = 1;  ///< output is 1/scale the size (box-averaged): blur less, faster
};

/// Each pixel's colour times max(Ld − threshold, 0) / Ld, where Ld is its
/// luminance L scaled by middle_grey / average_luminance and mapped by
/// Reinhard: Ld = L (1 + L / white²) / (1 + L). Alpha 1.
Image bright_pass(const Image& image, const BrightPass& settings);

enum class Axis { x, y };

/// The normalised Gaussian of standard deviation `sigma` pixels sampled at
/// offsets 0..radius (radius = ceil(3 sigma), at most 256): weights[0] +
/// 2 Σ weights[k>0] = 1.
std::vector<float> gaussian_weights(double sigma);

/// One axis of a Gaussian blur of `sigma` pixels, the image mirrored at its
/// edges (which keeps its mean exactly). Blurring along x then y equals the
/// 2-D Gaussian. sigma = 0 returns the image unchanged (as float).
Image blur(const Image& image, Axis axis, double sigma);

/// original + strength × bloom (bloom resampled bilinearly to the original's
/// size if smaller). Alpha from the original.
Image combine(const Image& original, const Image& bloom, double strength);

/// The whole bloom: bright pass (scale), blur x, blur y, combine.
struct Bloom {
    BrightPass bright{
        .scale = 4};  ///< at quarter size: the glow is soft anyway (sigma ≈ 18 px at 1080p), and 16× cheaper to blur
    /// Gaussian sigma as a fraction of the image width: the thesis's 15 taps
    /// cover ±0.028 of the frame, taken here as ±3 sigma.
    double sigma = 0.028 / 3.0;
    double strength = 0.667;
};
Image bloom(const Image& image, const Bloom& settings);

/// The image as linear float RGBA (8-bit sRGB decoded), a copy.
Image to_linear_float(const Image& image);

}  // namespace orogen::render
