// rock.cpp — tilted beds of varying strength (rock.hpp).
#include "rock.hpp"

#include <orogen/parallel.hpp>
#include <orogen/random.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <cstdlib>

namespace orogen::stream_power {

namespace {

/// Value noise in [-1, 1]: the seed's random values at the integer lattice points, blended by the quintic
/// fade 6t⁵ − 15t⁴ + 10t³ (smooth to the second derivative, so the folded beds have no creases).
double value_noise(double u, double v, std::uint64_t seed, std::uint64_t octave) {
    const double fu = std::floor(u), fv = std::floor(v);
    const auto i = static_cast<std::int64_t>(fu), j = static_cast<std::int64_t>(fv);
    const auto fade = [](double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); };
    const double a = fade(u - fu), b = fade(v - fv);
    const auto at = [&](std::int64_t di, std::int64_t dj) {
        return random::uniform_in(-1.0, 1.0, seed, octave, std::uint64_t(i + di), std::uint64_t(j + dj));
    };
    const double lo = at(0, 0) + a * (at(1, 0) - at(0, 0)), hi = at(0, 1) + a * (at(1, 1) - at(0, 1));
    return lo + b * (hi - lo);
}

/// Keeps the folds' random values apart from the beds' strengths, which use the seed itself.
constexpr std::uint64_t kFoldSalt = 0x666f6c6473ull;  // "folds"

/// The strength class of the bed at height q (m) above the bed surface through the origin.
int class_of(const Beds& beds, double q) {
    const auto bed = static_cast<std::int64_t>(std::floor(q / beds.thickness));
    return int(random::below(Beds::kStrengths, beds.seed, std::uint64_t(bed)));
}

}  // namespace

double Beds::fold(double x, double y) const {
    if (!folded()) return 0.0;
    // Across the fold axes is along the dip; the axes run along the strike, three times as long. Two
    // octaves: folds of the wavelength, and smaller ones on their limbs at half the height.
    const double across = x * dip_east + y * dip_south, along = -x * dip_south + y * dip_east;
    const double u = across / (0.5 * fold_wavelength), v = along / (1.5 * fold_wavelength);
    const std::uint64_t s = random::hash(seed, kFoldSalt);
    const double f = value_noise(u, v, s, 0) + 0.5 * value_noise(2.0 * u, 2.0 * v, s, 1);
    return fold_amplitude * f / 1.5;
}

double Beds::offset(double x, double y) const {
    // The bed's base rises towards the dip's opposite and where the folds lift it (an arch): the rock at a
    // given height there lies in a lower bed.
    return dip_slope * (x * dip_east + y * dip_south) - fold(x, y);
}

int Beds::bed_class(double zeta, double x, double y) const {
    if (!layered()) return kStrengths / 2;
    // q is the height above the bed surface through the origin.
    return class_of(*this, zeta + offset(x, y));
}

double Beds::strength(double zeta, double x, double y) const {
    return (bed_class(zeta, x, y) + 0.5) / double(kStrengths);
}

double Beds::landslide_slope(double s) const {
    constexpr double lo = 5.0 * std::numbers::pi / 180.0, hi = 80.0 * std::numbers::pi / 180.0;
    return std::tan(std::clamp(angle + angle_spread * (2.0 * s - 1.0), lo, hi));
}

double Beds::erodibility_factor(double s) const { return std::pow(erodibility_contrast, 0.5 - s); }

void bed_offsets(const Beds& beds, std::size_t count, int width, int x0, int y0, double cell,
                 std::vector<double>& offsets) {
    offsets.resize(beds.layered() ? count : 0);
    if (!beds.layered()) return;
    parallel_for(0, std::int64_t(count), 1 << 14, [&](std::int64_t b, std::int64_t e) {
        for (std::int64_t i = b; i < e; ++i)
            offsets[std::size_t(i)] =
                beds.offset(double(x0 + int(i % width)) * cell, double(y0 + int(i / width)) * cell);
    });
}

void rock_at(const Beds& beds, const double* heights, const double* uplifted, const double* offsets, std::size_t count,
             std::vector<double>& slopes, std::vector<double>& factors) {
    const bool vary_slope = beds.layered() && beds.angle > 0.0 && beds.angle_spread > 0.0;
    const bool vary_k = beds.layered() && beds.erodibility_contrast != 1.0;
    slopes.resize(vary_slope ? count : 0);
    factors.resize(vary_k ? count : 0);
    if (!vary_slope && !vary_k) return;
    // A bed's strength is one of kStrengths classes: the slopes and factors come from a table (a tan and
    // a pow per class, not per cell and step).
    constexpr int kStrengths = Beds::kStrengths;
    double slope_of[kStrengths], factor_of[kStrengths];
    for (int k = 0; k < kStrengths; ++k) {
        const double s = (k + 0.5) / double(kStrengths);
        slope_of[k] = beds.landslide_slope(s);
        factor_of[k] = beds.erodibility_factor(s);
    }
    parallel_for(0, std::int64_t(count), 1 << 14, [&](std::int64_t b, std::int64_t e) {
        for (std::int64_t i = b; i < e; ++i) {
            const int k = class_of(beds, (heights[i] - uplifted[i]) + offsets[i]);
            if (vary_slope) slopes[std::size_t(i)] = slope_of[k];
            if (vary_k) factors[std::size_t(i)] = factor_of[k];
        }
    });
}

}  // namespace orogen::stream_power
