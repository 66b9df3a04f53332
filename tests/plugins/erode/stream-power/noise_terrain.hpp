// noise_terrain.hpp — the rough starting terrain the stream-power tests share.
#pragma once

#include <orogen/random.hpp>

#include <cstdint>
#include <vector>

namespace orogen::landscape::test {

/// w × h heights (m), row-major: white noise of `amplitude` metres from the counter-based generator,
/// the same on any thread count.
inline std::vector<double> noise(int w, int h, std::uint64_t seed, double amplitude) {
    std::vector<double> v(std::size_t(w) * std::size_t(h));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            v[std::size_t(y) * std::size_t(w) + std::size_t(x)] = amplitude * random::uniform(seed, x, y);
    return v;
}

}  // namespace orogen::landscape::test
