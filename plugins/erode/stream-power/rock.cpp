// rock.cpp — tilted beds of varying strength (rock.hpp).
#include "rock.hpp"

#include <orogen/parallel.hpp>
#include <orogen/random.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <cstdlib>

namespace orogen::stream_power {

int Beds::bed_class(double zeta, double x, double y) const {
    if (!layered()) return kStrengths / 2;
    // The bed's base rises towards the dip's opposite: q is the height above a bed surface through the origin.
    const double q = zeta + dip_slope * (x * dip_east + y * dip_south);
    const auto bed = static_cast<std::int64_t>(std::floor(q / thickness));
    return int(random::below(kStrengths, seed, std::uint64_t(bed)));
}

double Beds::strength(double zeta, double x, double y) const {
    return (bed_class(zeta, x, y) + 0.5) / double(kStrengths);
}

double Beds::landslide_slope(double s) const {
    constexpr double lo = 5.0 * std::numbers::pi / 180.0, hi = 80.0 * std::numbers::pi / 180.0;
    return std::tan(std::clamp(angle + angle_spread * (2.0 * s - 1.0), lo, hi));
}

double Beds::erodibility_factor(double s) const { return std::pow(erodibility_contrast, 0.5 - s); }

void rock_at(const Beds& beds, const double* heights, const double* uplifted, std::size_t count, int width, int x0,
             int y0, double cell, std::vector<double>& slopes, std::vector<double>& factors) {
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
            const double x = double(x0 + int(i % width)) * cell, y = double(y0 + int(i / width)) * cell;
            const int k = beds.bed_class(heights[i] - uplifted[i], x, y);
            if (vary_slope) slopes[std::size_t(i)] = slope_of[k];
            if (vary_k) factors[std::size_t(i)] = factor_of[k];
        }
    });
}

}  // namespace orogen::stream_power
