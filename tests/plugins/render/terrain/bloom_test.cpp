// The bloom passes: bright pass, separable Gaussian, combine, through OSMesa.
#include "bloom.hpp"
#include "render_support.hpp"

#include <orogen/error.hpp>
#include <orogen/random.hpp>

#include <gtest/gtest.h>

using namespace orogen;
using namespace orogen::render;
using namespace orogen::test;

namespace {

const auto* const no_display = ::testing::AddGlobalTestEnvironment(new NoDisplay);

Image noise_image(int w, int h, float scale, std::uint64_t seed) {
    Image im = float_image(w, h);
    for (std::size_t i = 0; i < im.rgba32f.size(); ++i)
        im.rgba32f[i] = i % 4 == 3 ? 1.0f : scale * float(random::hash(seed, i) % 10000) / 10000.0f;
    return im;
}

double channel_mean(const Image& im, int c) {
    double s = 0;
    for (std::size_t i = std::size_t(c); i < im.rgba32f.size(); i += 4) s += im.rgba32f[i];
    return s / double(im.rgba32f.size() / 4);
}

}  // namespace

TEST(BrightPass, AnImageWithNothingAboveTheThresholdIsBlack) {
    // Luminance ≤ 0.5: Reinhard (white 1.5) maps it to ≤ 0.37 < threshold 0.4.
    const Image dim = noise_image(33, 21, 0.5f, 7);
    const Image out = bright_pass(dim, BrightPass{});
    ASSERT_EQ(out.width, 33);
    for (std::size_t i = 0; i < out.rgba32f.size(); i += 4)
        for (int c = 0; c < 3; ++c) ASSERT_EQ(out.rgba32f[i + std::size_t(c)], 0.0f) << "pixel " << i / 4;
    // A bright pixel (luminance 3) survives, with its hue.
    Image one = dim;
    one.rgba32f[4 * 100 + 0] = 3.0f;
    one.rgba32f[4 * 100 + 1] = 3.0f;
    one.rgba32f[4 * 100 + 2] = 1.5f;
    const Image kept = bright_pass(one, BrightPass{});
    EXPECT_GT(kept.rgba32f[4 * 100], 0.5f);
    EXPECT_NEAR(kept.rgba32f[4 * 100 + 2] / kept.rgba32f[4 * 100], 0.5, 1e-5);
    // scale=2 halves the size (rounding up) and averages 2 × 2 pixels.
    EXPECT_EQ(bright_pass(one, BrightPass{.scale = 2}).width, 17);
}

TEST(Blur, KeepsTheMeanOfEveryChannel) {
    const Image im = noise_image(47, 29, 2.0f, 3);
    for (Axis axis : {Axis::x, Axis::y}) {
        const Image out = blur(im, axis, 3.5);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(channel_mean(out, c), channel_mean(im, c), 1e-5) << "channel " << c;
        // ... and does blur: the variance drops.
        double v_in = 0, v_out = 0;
        const double m = channel_mean(im, 0);
        for (std::size_t i = 0; i < im.rgba32f.size(); i += 4) {
            v_in += (im.rgba32f[i] - m) * (im.rgba32f[i] - m);
            v_out += (out.rgba32f[i] - m) * (out.rgba32f[i] - m);
        }
        EXPECT_LT(v_out, 0.5 * v_in);
    }
}

TEST(Blur, XThenYEqualsTheTwoDimensionalGaussian) {
    const int w = 31, h = 23;
    const double sigma = 2.2;
    const Image im = noise_image(w, h, 1.0f, 11);
    const Image xy = blur(blur(im, Axis::x, sigma), Axis::y, sigma);
    // The 2-D kernel w(i)·w(j) applied directly (doubles), with the same mirrored edges.
    const std::vector<float> k = gaussian_weights(sigma);
    const int r = int(k.size()) - 1;
    auto mirror = [](int i, int n) {
        const int p = 2 * n;
        i %= p;
        if (i < 0) i += p;
        return i < n ? i : p - 1 - i;
    };
    double worst = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) {
                double s = 0;
                for (int j = -r; j <= r; ++j)
                    for (int i = -r; i <= r; ++i)
                        s += double(k[std::size_t(std::abs(i))]) * k[std::size_t(std::abs(j))] *
                            im.rgba32f[4 * std::size_t(mirror(y + j, h) * w + mirror(x + i, w)) + std::size_t(c)];
                worst = std::max(worst, std::abs(s - xy.rgba32f[4 * std::size_t(y * w + x) + std::size_t(c)]));
            }
    EXPECT_LT(worst, 2e-6);
}

TEST(Blur, WeightsAreANormalisedGaussian) {
    const auto w = gaussian_weights(4.0);
    ASSERT_EQ(w.size(), 13u);  // 3 sigma
    double total = w[0];
    for (std::size_t i = 1; i < w.size(); ++i) total += 2 * w[i];
    EXPECT_NEAR(total, 1.0, 1e-6);
    EXPECT_NEAR(w[4] / w[0], std::exp(-0.5), 1e-6);
    EXPECT_THROW(gaussian_weights(-1), BadInput);
}

TEST(Combine, StrengthZeroIsTheIdentityAndOneAddsTheBloom) {
    const Image a = noise_image(19, 13, 3.0f, 5), b = noise_image(19, 13, 1.0f, 6);
    const Image same = combine(a, b, 0.0);
    EXPECT_TRUE(same.rgba32f == a.rgba32f);
    const Image sum = combine(a, b, 1.0);
    for (std::size_t i = 0; i < a.rgba32f.size(); ++i)
        if (i % 4 != 3) ASSERT_NEAR(sum.rgba32f[i], a.rgba32f[i] + b.rgba32f[i], 1e-6);
}

TEST(Bloom, TheChainEqualsThePassesOneByOne) {
    Image im = noise_image(64, 40, 0.3f, 9);
    for (int y = 18; y < 22; ++y)
        for (int x = 30; x < 34; ++x)
            for (int c = 0; c < 3; ++c) im.rgba32f[4 * std::size_t(y * 64 + x) + std::size_t(c)] = 20.0f;
    Bloom b;
    b.sigma = 0.06;  // 3.84 pixels of the full image, 1.92 of the half-size bright pass
    const Image chained = bloom(im, b);
    const double sigma = b.sigma * 64 / b.bright.scale;
    const Image by_hand =
        combine(im, blur(blur(bright_pass(im, b.bright), Axis::x, sigma), Axis::y, sigma), b.strength);
    ASSERT_EQ(chained.rgba32f.size(), by_hand.rgba32f.size());
    for (std::size_t i = 0; i < chained.rgba32f.size(); ++i) ASSERT_NEAR(chained.rgba32f[i], by_hand.rgba32f[i], 1e-5);
    // The glow reaches beyond the bright square.
    EXPECT_GT(chained.rgba32f[4 * std::size_t(20 * 64 + 36)], im.rgba32f[4 * std::size_t(20 * 64 + 36)] + 0.05f);
}
