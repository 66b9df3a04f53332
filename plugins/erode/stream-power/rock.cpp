// rock.cpp — tilted beds of varying strength (rock.hpp).
#include "rock.hpp"

#include <orogen/parallel.hpp>
#include <orogen/random.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <cstdlib>
#include <limits>

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

/// ... and the beds' thicknesses and the faults from the strengths and from each other.
constexpr std::uint64_t kThicknessSalt = 0x746869636bull;  // "thick"
constexpr std::uint64_t kFaultSalt = 0x6661756c7473ull;  // "faults"
constexpr std::uint64_t kBlockSalt = 0x626c6f636bull;  // "block"

/// The strength class of the bed at height q (m) above the bed surface through the origin.
int class_of(const Beds& beds, double q) {
    return int(random::below(Beds::kStrengths, beds.seed, std::uint64_t(beds.bed_at(q))));
}

/// One fault: its trace's middle (m), the unit vector along it, its half-length (m) and its throw (m, the
/// far side of the trace (left of the direction) is lifted by half of it, the near side dropped by half).
struct Fault {
    double x = 0.0, y = 0.0, along_x = 1.0, along_y = 0.0, half_length = 0.0, throw_m = 0.0;
};

/// The fault of lattice square (a, b) (squares `fault_spacing` across, a east, b south): its middle
/// anywhere in the square, any strike, 1–3 spacings long, a throw of 1/4 to all of fault_throw.
Fault fault_in(const Beds& beds, std::int64_t a, std::int64_t b) {
    const std::uint64_t s = random::hash(beds.seed, kFaultSalt);
    const auto u = [&](std::uint64_t k) { return random::uniform(s, std::uint64_t(a), std::uint64_t(b), k); };
    const double spacing = beds.fault_spacing, strike = std::numbers::pi * u(2);
    Fault f;
    f.x = (double(a) + u(0)) * spacing;
    f.y = (double(b) + u(1)) * spacing;
    f.along_x = std::cos(strike);
    f.along_y = std::sin(strike);
    f.half_length = spacing * (0.5 + u(3));
    f.throw_m = beds.fault_throw * (0.25 + 0.75 * u(4));
    return f;
}

/// How far a fault lifts the beds at (x, y): ± half its throw on either side of the trace, greatest at its
/// middle and dying away (smoothly, as (1 − r²)²) to nothing at its half-length from the middle.
double fault_lift(const Fault& f, double x, double y) {
    const double dx = x - f.x, dy = y - f.y;
    const double along = dx * f.along_x + dy * f.along_y, across = dy * f.along_x - dx * f.along_y;
    const double r2 = (along * along + across * across) / (f.half_length * f.half_length);
    if (r2 >= 1.0) return 0.0;
    return (across >= 0.0 ? 0.5 : -0.5) * f.throw_m * (1.0 - r2) * (1.0 - r2);
}

/// The faults' lift at (x, y): the sum over the 5 × 5 lattice squares around it (a fault reaches at most
/// 1.5 spacings from its middle, which lies in its square), in one fixed order. `fault_of(a, b)` gives
/// square (a, b)'s fault, so a caller can look them up in a table rather than draw them again.
template <typename FaultOf>
double faults_lift(const Beds& beds, double x, double y, FaultOf&& fault_of) {
    const auto a0 = static_cast<std::int64_t>(std::floor(x / beds.fault_spacing));
    const auto b0 = static_cast<std::int64_t>(std::floor(y / beds.fault_spacing));
    double lift = 0.0;
    for (std::int64_t b = b0 - 2; b <= b0 + 2; ++b)
        for (std::int64_t a = a0 - 2; a <= a0 + 2; ++a) lift += fault_lift(fault_of(a, b), x, y);
    return lift;
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

double Beds::fault(double x, double y) const {
    if (!faulted()) return 0.0;
    return faults_lift(*this, x, y, [&](std::int64_t a, std::int64_t b) { return fault_in(*this, a, b); });
}

double Beds::offset(double x, double y) const {
    // The bed's base rises towards the dip's opposite and where the folds or the faults lift it: the rock
    // at a given height there lies in a lower bed.
    return dip_slope * (x * dip_east + y * dip_south) - fold(x, y) - fault(x, y);
}

double Beds::bed_base(std::int64_t k) const {
    if (!(thickness_spread > 0.0)) return thickness * double(k);
    const std::uint64_t s = random::hash(seed, kThicknessSalt);
    return thickness * (double(k) + thickness_spread * (random::uniform(s, std::uint64_t(k)) - 0.5));
}

std::int64_t Beds::bed_at(double q) const {
    // A height that is not finite (the run reports it, naming the node and step) or beyond any bed index
    // lies in bed 0 rather than in an undefined cast.
    const double index = std::floor(q / thickness);
    if (!(std::abs(index) < 0x1p62)) return 0;
    auto bed = static_cast<std::int64_t>(index);
    if (thickness_spread > 0.0) {
        // Bed k's base is within half a thickness of k·thickness, so q lies in bed k − 1, k or k + 1, and
        // two bases tell which.
        if (q < bed_base(bed)) --bed;
        else if (q >= bed_base(bed + 1)) ++bed;
    }
    return bed;
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
    // The faults of every lattice square within reach of the block, drawn once (Beds::fault draws the 25
    // around a point each time it is asked); faults_lift adds them up in the same order either way.
    std::vector<Fault> table;
    std::int64_t a_lo = 0, b_lo = 0, a_count = 0;
    if (beds.faulted()) {
        const int height = int(count / std::size_t(width));
        const auto square = [&](int c) { return static_cast<std::int64_t>(std::floor(c * cell / beds.fault_spacing)); };
        a_lo = square(x0) - 2, b_lo = square(y0) - 2;
        a_count = square(x0 + width - 1) + 3 - a_lo;
        const std::int64_t b_count = square(y0 + height - 1) + 3 - b_lo;
        table.resize(std::size_t(a_count * b_count));
        for (std::int64_t b = 0; b < b_count; ++b)
            for (std::int64_t a = 0; a < a_count; ++a)
                table[std::size_t(b * a_count + a)] = fault_in(beds, a_lo + a, b_lo + b);
    }
    const auto fault_of = [&](std::int64_t a, std::int64_t b) -> const Fault& {
        return table[std::size_t((b - b_lo) * a_count + (a - a_lo))];
    };
    parallel_for(0, std::int64_t(count), 1 << 14, [&](std::int64_t b, std::int64_t e) {
        for (std::int64_t i = b; i < e; ++i) {
            const double x = double(x0 + int(i % width)) * cell, y = double(y0 + int(i / width)) * cell;
            double offset = beds.dip_slope * (x * beds.dip_east + y * beds.dip_south) - beds.fold(x, y);
            if (beds.faulted()) offset -= faults_lift(beds, x, y, fault_of);
            offsets[std::size_t(i)] = offset;
        }
    });
}

void rock_at(const Beds& beds, const double* heights, const double* uplifted, const double* offsets, std::size_t count,
             int width, int x0, int y0, double cell, std::vector<double>& slopes, std::vector<double>& factors) {
    const bool layered = beds.layered();
    const bool blocky = beds.angle > 0.0 && beds.block_spread > 0.0;
    const bool vary_slope = (layered && beds.angle > 0.0 && beds.angle_spread > 0.0) || blocky;
    const bool vary_k = layered && beds.erodibility_contrast != 1.0;
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
    // The beds the cells lie in this step, from the lowest to the highest, with one more each side: their
    // bases and classes drawn once into a table rather than hashed per cell (bed_at and class_of's own
    // expressions, so the same bits). A cell outside the table (a height not finite, or a range of more
    // than kMaxBeds beds) falls back on class_of.
    constexpr std::int64_t kMaxBeds = std::int64_t(1) << 20;
    const double thickness = beds.thickness;
    std::int64_t first = 0;
    std::vector<double> base;
    std::vector<int> klass;
    if (layered) {
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (std::size_t i = 0; i < count; ++i) {
            const double q = (heights[i] - uplifted[i]) + offsets[i];
            lo = std::min(lo, q), hi = std::max(hi, q);
        }
        if (lo <= hi && (hi - lo) / thickness < double(kMaxBeds)) {
            first = static_cast<std::int64_t>(std::floor(lo / thickness)) - 1;
            const std::int64_t beds_in = static_cast<std::int64_t>(std::floor(hi / thickness)) + 2 - first + 1;
            base.resize(std::size_t(beds_in));
            klass.resize(std::size_t(beds_in));
            for (std::int64_t j = 0; j < beds_in; ++j) {
                base[std::size_t(j)] = beds.bed_base(first + j);
                klass[std::size_t(j)] = int(random::below(Beds::kStrengths, beds.seed, std::uint64_t(first + j)));
            }
        }
    }
    const bool uneven = beds.thickness_spread > 0.0;
    const std::int64_t last = first + std::int64_t(base.size()) - 1;
    // The joint blocks: one per cell and cell-deep slice of rock height, keyed by the cell's place in the
    // whole grid (the same on any tiling). No block stands steeper than the landslide angles' 80°.
    const std::uint64_t block_seed = random::hash(beds.seed, kBlockSalt);
    const double steepest = std::tan(80.0 * std::numbers::pi / 180.0);
    parallel_for(0, std::int64_t(count), 1 << 14, [&](std::int64_t b, std::int64_t e) {
        for (std::int64_t i = b; i < e; ++i) {
            const double zeta = heights[i] - uplifted[i];
            int k = kStrengths / 2;
            if (layered) {
                const double q = zeta + offsets[i];
                if (const double bed = std::floor(q / thickness); bed > double(first) && bed < double(last)) {
                    std::size_t j = std::size_t(static_cast<std::int64_t>(bed) - first);
                    if (uneven) {
                        if (q < base[j]) --j;
                        else if (q >= base[j + 1]) ++j;
                    }
                    k = klass[j];
                } else {
                    k = class_of(beds, q);
                }
            }
            if (vary_slope) {
                double slope = slope_of[k];
                if (blocky) {
                    const double slice = std::floor(zeta / cell);
                    const std::int64_t key = std::abs(slice) < 0x1p62 ? static_cast<std::int64_t>(slice) : 0;
                    const double u = random::uniform(block_seed, std::uint64_t(x0 + int(i % width)),
                                                     std::uint64_t(y0 + int(i / width)), std::uint64_t(key));
                    slope = std::min(slope * (1.0 + beds.block_spread * u), steepest);
                }
                slopes[std::size_t(i)] = slope;
            }
            if (vary_k) factors[std::size_t(i)] = factor_of[k];
        }
    });
}

}  // namespace orogen::stream_power
