// Engine texture maps: the splat weights sum to 255 and follow the height and
// slope rules; normals point the right way for each green convention; the
// files written by the real binary decode to the same bytes.
#include "maps.hpp"
#include "orogen_test.hpp"

#include <gtest/gtest.h>

#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>

#include <cmath>

using namespace orogen;
using namespace orogen::test;

namespace {

/// A plane rising `east` m per m to the east and `south` m per m to the south.
std::vector<float> plane(int n, double cell, double east, double south, double base = 0.0) {
    std::vector<float> h(std::size_t(n) * n);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) h[std::size_t(y) * n + x] = float(base + east * x * cell + south * y * cell);
    return h;
}

}  // namespace

TEST(SplatMap, EveryTexelsWeightsSumToExactly255) {
    const int n = 97;
    std::vector<float> h(std::size_t(n) * n);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) h[std::size_t(y) * n + x] = float(400 * std::sin(0.11 * x) * std::cos(0.07 * y));
    const auto m = maps::splat_map({h.data(), n, n, 10.0});
    std::size_t blended = 0;
    for (std::size_t i = 0; i < h.size(); ++i) {
        const int sum = m[4 * i] + m[4 * i + 1] + m[4 * i + 2] + m[4 * i + 3];
        ASSERT_EQ(sum, 255) << "texel " << i;
        int nonzero = 0;
        for (int c = 0; c < 4; ++c) nonzero += m[4 * i + std::size_t(c)] > 0;
        blended += nonzero > 1;
    }
    EXPECT_GT(blended, h.size() / 20);  // the blend bands are there, not only pure materials
}

TEST(SplatMap, LowFlatGroundIsSandAndASteepSnowySlopeIsRock) {
    // A gentle ramp from 0 to 1000 m: the low end sand, the high end snow.
    const int n = 65;
    auto ramp = plane(n, 10.0, 1000.0 / (64 * 10.0) * 0.1, 0.0);  // 0.16 m per m: gentle
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) ramp[std::size_t(y) * n + x] *= 10.0f;  // ... to 1000 m, still under the slope rule
    const auto m = maps::splat_map({ramp.data(), n, n, 100.0});
    const std::uint8_t* low = &m[4 * (32 * n + 0)];
    const std::uint8_t* high = &m[4 * (32 * n + 64)];
    EXPECT_EQ(low[0], 255);  // sand
    EXPECT_EQ(high[3], 255);  // snow
    // The same heights on a 60° slope: the top is rock (snow does not rest there).
    const auto steep = plane(n, 10.0, std::tan(60.0 * M_PI / 180.0), 0.0);
    const auto s = maps::splat_map({steep.data(), n, n, 10.0});
    const std::uint8_t* top = &s[4 * (32 * n + 64)];
    EXPECT_EQ(top[2], 255) << int(top[0]) << " " << int(top[1]) << " " << int(top[2]) << " " << int(top[3]);
}

TEST(SplatMap, RoundingHandsTheLeftoverToTheLargestRemainders) {
    const float thirds[4] = {1.0f / 3, 1.0f / 3, 1.0f / 3, 0.0f};
    std::uint8_t out[4];
    maps::round_to_total(thirds, 255, out);
    EXPECT_EQ(out[0] + out[1] + out[2] + out[3], 255);
    const float mixed[4] = {0.504f, 0.0f, 0.496f, 0.0f};  // 128.52 and 126.48
    maps::round_to_total(mixed, 255, out);
    EXPECT_EQ(out[0], 129);
    EXPECT_EQ(out[2], 126);
}

TEST(NormalMap, FlatIsStraightUpAndSlopesTiltTheRightWay) {
    const int n = 33;
    auto flat = plane(n, 10.0, 0.0, 0.0, 50.0);
    auto m = maps::normal_map({flat.data(), n, n, 10.0}, 1.0, maps::Green::opengl);
    EXPECT_EQ(m[4 * (16 * n + 16)], 128);
    EXPECT_EQ(m[4 * (16 * n + 16) + 1], 128);
    EXPECT_EQ(m[4 * (16 * n + 16) + 2], 255);
    // Rising to the east: the normal leans west (red below 128); 45° → x = −0.7071.
    auto east = plane(n, 10.0, 1.0, 0.0);
    m = maps::normal_map({east.data(), n, n, 10.0}, 1.0, maps::Green::opengl);
    EXPECT_EQ(m[4 * (16 * n + 16)], std::lround(-std::sqrt(0.5) * 127.5 + 127.5));
    EXPECT_EQ(m[4 * (16 * n + 16) + 1], 128);
    // Rising to the south (down the image): the normal leans north, +green in OpenGL, −green in DirectX.
    auto south = plane(n, 10.0, 0.0, 0.5);
    const auto gl = maps::normal_map({south.data(), n, n, 10.0}, 1.0, maps::Green::opengl);
    const auto dx = maps::normal_map({south.data(), n, n, 10.0}, 1.0, maps::Green::directx);
    EXPECT_GT(gl[4 * (16 * n + 16) + 1], 128);
    EXPECT_LT(dx[4 * (16 * n + 16) + 1], 128);
    EXPECT_EQ(int(gl[4 * (16 * n + 16) + 1]) + int(dx[4 * (16 * n + 16) + 1]), 255);
    // Vertical exaggeration steepens the surface.
    const auto x2 = maps::normal_map({east.data(), n, n, 10.0}, 2.0, maps::Green::opengl);
    EXPECT_LT(x2[4 * (16 * n + 16)], m[4 * (16 * n + 16)] + 0);
}

TEST(MapsCli, TheBinaryWritesBothMapsAtTheTerrainsSize) {
    TempDir dir;
    dir.write("s.orogen",
              "orogen 1\ngrid 65 cell=10\nhill = generate:shape(kind=pyramid, height=300)\n"
              "export:splatmap(hill, path=\"maps/splat.png\")\n"
              "export:normalmap(hill, path=\"maps/normal.png\", green=directx, scale=2)\n");
    const RunResult r = run_orogen("run s.orogen --out out --quiet", "", dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    for (const char* f : {"out/maps/splat.png", "out/maps/normal.png"}) {
        int w = 0, h = 0, c = 0;
        stbi_uc* px = stbi_load((dir / f).c_str(), &w, &h, &c, 4);
        ASSERT_NE(px, nullptr) << f;
        EXPECT_EQ(w, 65);
        EXPECT_EQ(h, 65);
        if (std::string(f).find("splat") != std::string::npos) {
            for (int i = 0; i < w * h; ++i) ASSERT_EQ(px[4 * i] + px[4 * i + 1] + px[4 * i + 2] + px[4 * i + 3], 255);
            EXPECT_EQ(px[4 * (2 * 65 + 2)], 255);  // the low corner is sand
        } else {
            // The pyramid's west face rises to the east: red below 128 there; the east face: above.
            EXPECT_LT(px[4 * (32 * 65 + 16)], 128);
            EXPECT_GT(px[4 * (32 * 65 + 48)], 128);
        }
        stbi_image_free(px);
    }
}
