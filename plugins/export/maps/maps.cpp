#include "maps.hpp"

#include <orogen/mesh/terrain_mesh.hpp>

#include <orogen/parallel.hpp>

#include <algorithm>
#include <cmath>

namespace orogen::maps {

void round_to_total(const float weights[4], int total, std::uint8_t out[4]) {
    int sum = 0;
    float rest[4];
    for (int c = 0; c < 4; ++c) {
        const float v = std::clamp(weights[c], 0.0f, 1.0f) * float(total);
        out[c] = std::uint8_t(std::floor(v));
        rest[c] = v - std::floor(v);
        sum += out[c];
    }
    // Hand the missing units to the largest remainders (stable: lower channel first on ties).
    while (sum < total) {
        int best = 0;
        for (int c = 1; c < 4; ++c)
            if (rest[c] > rest[best]) best = c;
        ++out[best];
        rest[best] = -1.0f;
        ++sum;
    }
}

std::vector<std::uint8_t> splat_map(ConstGridView h) {
    std::vector<std::uint8_t> rgba(h.size() * 4);
    if (h.size() == 0) return rgba;
    const auto [lo_it, hi_it] = std::minmax_element(h.data, h.data + h.size());
    const float lo = *lo_it, hi = *hi_it;
    parallel_for(0, h.height, 8, [&](std::int64_t y0, std::int64_t y1) {
        for (int y = int(y0); y < int(y1); ++y)
            for (int x = 0; x < h.width; ++x) {
                const float ny = mesh::surface_normal(h, x, y, 1.0)[1];
                const mesh::SplatWeights s = mesh::splat_weights(h.at(x, y), lo, hi, ny);
                const float w[4] = {s.sand, s.grass, s.rock, s.snow};
                round_to_total(w, 255, &rgba[(std::size_t(y) * std::size_t(h.width) + std::size_t(x)) * 4]);
            }
    });
    return rgba;
}

std::vector<std::uint8_t> normal_map(ConstGridView h, double vertical_scale, Green green) {
    std::vector<std::uint8_t> rgba(h.size() * 4);
    const float north = green == Green::opengl ? 1.0f : -1.0f;
    auto encode = [](float v) { return std::uint8_t(std::lround(std::clamp(v, -1.0f, 1.0f) * 127.5f + 127.5f)); };
    parallel_for(0, h.height, 8, [&](std::int64_t y0, std::int64_t y1) {
        for (int y = int(y0); y < int(y1); ++y)
            for (int x = 0; x < h.width; ++x) {
                // World normal, Y up and Z south → tangent space X east, Y north (or south), Z up.
                const auto n = mesh::surface_normal(h, x, y, vertical_scale);
                std::uint8_t* p = &rgba[(std::size_t(y) * std::size_t(h.width) + std::size_t(x)) * 4];
                p[0] = encode(n[0]);
                p[1] = encode(-n[2] * north);
                p[2] = encode(n[1]);
                p[3] = 255;
            }
    });
    return rgba;
}

}  // namespace orogen::maps
