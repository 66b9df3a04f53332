// Shared by the render tests: no display, images compared by PSNR, colours classified.
#pragma once

#include <orogen/values.hpp>

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>

namespace orogen::test {

/// Every render test runs without a display: OSMesa needs none.
struct NoDisplay : ::testing::Environment {
    void SetUp() override {
        ::unsetenv("DISPLAY");
        ::unsetenv("WAYLAND_DISPLAY");
    }
};

/// Peak signal-to-noise ratio of two 8-bit buffers, dB (infinity when equal).
inline double psnr(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
    EXPECT_EQ(a.size(), b.size());
    double se = 0;
    for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) se += (double(a[i]) - b[i]) * (double(a[i]) - b[i]);
    if (se == 0) return std::numeric_limits<double>::infinity();
    return 10.0 * std::log10(255.0 * 255.0 / (se / double(a.size())));
}

/// Index of the nearest of `colours` (linear RGB) to pixel i of a float image.
inline int nearest(const Image& image, std::size_t pixel, const std::array<std::array<float, 3>, 4>& colours) {
    int best = -1;
    double best_d = 1e300;
    for (int k = 0; k < 4; ++k) {
        double d = 0;
        for (int c = 0; c < 3; ++c) {
            const double e = image.rgba32f[4 * pixel + std::size_t(c)] - colours[std::size_t(k)][std::size_t(c)];
            d += e * e;
        }
        if (d < best_d) best_d = d, best = k;
    }
    return best;
}

inline Image float_image(int w, int h) {
    Image im;
    im.width = w;
    im.height = h;
    im.format = Image::Format::rgba32f;
    im.rgba32f.assign(std::size_t(w) * std::size_t(h) * 4, 0.0f);
    return im;
}

}  // namespace orogen::test
