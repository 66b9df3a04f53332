// orogen/random.hpp — counter-based random numbers.
//
// orogen's outputs must be bit-identical for a spec and seed whatever the
// thread count, so nothing draws from a generator that is shared or advanced
// in an order that depends on scheduling. A random number is a pure function
// of (seed, counters...): e.g. random::uniform(seed, x, y, step). Any loop can
// then be split across threads freely. The mixing function is SplitMix64's
// finaliser applied per counter, which passes BigCrush when used this way.
// `std::*_distribution` is never used: its output differs between libraries.
#pragma once

#include <cstdint>
#include <string_view>

namespace orogen::random {

/// SplitMix64 finaliser: a bijective 64-bit mixer.
constexpr std::uint64_t mix(std::uint64_t z) {
    z += 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/// Hash of a seed and any number of integer counters.
constexpr std::uint64_t hash(std::uint64_t seed) { return mix(seed); }
template <typename... Rest>
constexpr std::uint64_t hash(std::uint64_t seed, std::uint64_t first, Rest... rest) {
    return hash(mix(seed ^ mix(first + 0x632BE59BD9B4E019ull)), std::uint64_t(rest)...);
}

/// FNV-1a of a string: to derive a seed from a name.
constexpr std::uint64_t hash_string(std::string_view s) {
    std::uint64_t h = 0xCBF29CE484222325ull;
    for (char c : s) {
        h ^= std::uint8_t(c);
        h *= 0x100000001B3ull;
    }
    return h;
}

/// Uniform double in [0, 1) from 53 random bits of hash(seed, counters...).
template <typename... Counters>
constexpr double uniform(std::uint64_t seed, Counters... counters) {
    return double(hash(seed, std::uint64_t(counters)...) >> 11) * 0x1.0p-53;
}

/// Uniform double in [lo, hi).
template <typename... Counters>
constexpr double uniform_in(double lo, double hi, std::uint64_t seed, Counters... counters) {
    return lo + (hi - lo) * uniform(seed, counters...);
}

/// Uniform float in [-1, 1) from 24 random bits (cheap, for per-cell noise).
constexpr float symmetric_float(std::uint64_t bits) {
    return float(std::int32_t(bits >> 40) - (1 << 23)) * (1.0f / float(1 << 23));
}

/// Uniform integer in [0, n) (n > 0), by 128-bit multiply (no modulo bias worth noting).
template <typename... Counters>
constexpr std::uint64_t below(std::uint64_t n, std::uint64_t seed, Counters... counters) {
    return std::uint64_t((static_cast<unsigned __int128>(hash(seed, std::uint64_t(counters)...)) * n) >> 64);
}

}  // namespace orogen::random
