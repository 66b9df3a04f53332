// A screenshot read back for tests (8-bit RGB through libpng's simplified API): the viewer's and pvbatch's
// pictures are checked pixel by pixel. Tests that include this link PNG::PNG.
#pragma once

#include <gtest/gtest.h>
#include <png.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <cstdint>
#include <filesystem>
#include <vector>

namespace orogen::test {

struct Picture {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgb;
    std::array<int, 3> at(int x, int y) const {
        const std::uint8_t* p = &rgb[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * 3];
        return {p[0], p[1], p[2]};
    }
};

/// The picture, or an empty one and a test failure if the file cannot be read.
inline Picture read_picture(const std::filesystem::path& file) {
    png_image image{};
    image.version = PNG_IMAGE_VERSION;
    Picture p;
    if (!png_image_begin_read_from_file(&image, file.c_str())) {
        ADD_FAILURE() << "cannot read " << file;
        return p;
    }
    image.format = PNG_FORMAT_RGB;
    p.width = int(image.width);
    p.height = int(image.height);
    p.rgb.resize(PNG_IMAGE_SIZE(image));
    png_image_finish_read(&image, nullptr, p.rgb.data(), 0, nullptr);
    return p;
}

/// Pixels whose colours differ by more than `threshold` (sum over R, G, B) where both pictures have them.
inline std::size_t differing_pixels(const Picture& a, const Picture& b, int threshold = 30) {
    std::size_t n = 0;
    for (int y = 0; y < std::min(a.height, b.height); ++y)
        for (int x = 0; x < std::min(a.width, b.width); ++x) {
            const auto p = a.at(x, y), q = b.at(x, y);
            n += std::abs(p[0] - q[0]) + std::abs(p[1] - q[1]) + std::abs(p[2] - q[2]) > threshold;
        }
    return n;
}

}  // namespace orogen::test
