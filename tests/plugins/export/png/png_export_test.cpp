// export:png's layer= and hillshade=: the core, and 16-bit round trips through the binary.
#include <orogen/formats/heightmap_png.hpp>

#include "export_test_support.hpp"
#include "orogen_test.hpp"

#include <orogen/io.hpp>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstring>

using namespace orogen;
using namespace orogen::test;
namespace fs = std::filesystem;

TEST(Hillshade, FlatTerrainReadsTheSineOfTheElevation) {
    std::vector<float> flat(9 * 9, 120.0f);
    const auto s8 = formats::png::hillshade({flat.data(), 9, 9, 10.0}, 8, 315, 45);
    const auto s16 = formats::png::hillshade({flat.data(), 9, 9, 10.0}, 16, 315, 30);
    for (auto v : s8) EXPECT_EQ(v, 180);  // round(sin 45° · 255)
    const long expected16 = std::lround(std::sin(30.0 * 3.14159265358979323846 / 180.0) * 65535.0);
    EXPECT_EQ(expected16, 32767);  // sin 30° is 0.49999999999999994 in doubles
    for (auto v : s16) EXPECT_EQ(v, expected16);
}

TEST(Hillshade, SlopesFacingTheLightAreBrighterAndAFaceTowardsItIsWhite) {
    // Light from the west (azimuth 270°) at 45°: a plane rising to the east by 1 m/m faces it squarely.
    const int n = 7;
    std::vector<float> east(n * n), west(n * n);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            east[std::size_t(y * n + x)] = float(x * 2.0);  // 2 m cells: rises 1 m per m to the east
            west[std::size_t(y * n + x)] = float(-x * 2.0);
        }
    const auto lit = formats::png::hillshade({east.data(), n, n, 2.0}, 8, 270, 45);
    const auto dark = formats::png::hillshade({west.data(), n, n, 2.0}, 8, 270, 45);
    // Facing the light: normal (−1, 0, 1)/√2 · light (−cos45, 0, sin45) = 1.
    EXPECT_EQ(lit[3 * n + 3], 255);
    // Facing away at 45° with the light at 45°: grazing, 0.
    EXPECT_EQ(dark[3 * n + 3], 0);
    // North-south slopes are unaffected by a west light: (0, ±1, 1)/√2 · (−cos45, 0, sin45) = 1/2.
    std::vector<float> south(n * n);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) south[std::size_t(y * n + x)] = float(y * 2.0);
    EXPECT_NEAR(formats::png::hillshade({south.data(), n, n, 2.0}, 8, 270, 45)[3 * n + 3], 127.5, 0.5);  // 0.5 · 255
}

TEST(PngExportCli, SixteenBitHeightsLayersAndHillshadeRoundTrip) {
    TempDir dir;
    const auto spec = dir.write("png.orogen",
                                "orogen 1\nseed 3\ngrid 97 cell=15\n"
                                "base = generate:fault(iterations=80, displacement=4)\n"
                                "worn = erode:thermal(base, iterations=10)\n"
                                "export:png(worn, path=\"h.png\", bits=16)\n"
                                "export:png(worn, path=\"height.png\", bits=16, layer=\"height\")\n"
                                "export:png(worn, path=\"eroded.png\", bits=16, layer=\"eroded\")\n"
                                "export:png(worn, path=\"shade.png\", hillshade=true, azimuth=135, elevation=35)\n"
                                "export:raw(worn, path=\"h.r32\")\n");
    const RunResult r = run_orogen("run " + q(spec) + " --out " + q(dir / "out"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    // The 16-bit PNG gives back the heights within half a quantisation step.
    const GrayImage png = read_gray_png(dir / "out" / "h.png");
    ASSERT_EQ(png.bits, 16);
    ASSERT_EQ(png.width, 97);
    const std::string raw = file_text(dir / "out" / "h.r32");
    std::vector<float> h(97 * 97);
    ASSERT_EQ(raw.size(), h.size() * 4);
    std::memcpy(h.data(), raw.data(), raw.size());
    const auto [lo, hi] = std::minmax_element(h.begin(), h.end());
    const double step = (double(*hi) - *lo) / 65535.0;
    for (std::size_t i = 0; i < h.size(); ++i) ASSERT_NEAR(*lo + step * png.samples[i], h[i], 0.5 * step + 1e-6) << i;
    EXPECT_EQ(read_gray_png(dir / "out" / "height.png").samples, png.samples);  // layer="height" = the heights
    // The eroded layer is its own picture, spread over the full 16-bit range.
    const GrayImage eroded = read_gray_png(dir / "out" / "eroded.png");
    EXPECT_NE(eroded.samples, png.samples);
    EXPECT_EQ(*std::min_element(eroded.samples.begin(), eroded.samples.end()), 0);
    EXPECT_EQ(*std::max_element(eroded.samples.begin(), eroded.samples.end()), 65535);
    // The hillshade is the core's, written as 8-bit.
    const GrayImage shade = read_gray_png(dir / "out" / "shade.png");
    EXPECT_EQ(shade.bits, 8);
    EXPECT_EQ(shade.samples, formats::png::hillshade({h.data(), 97, 97, 15.0}, 8, 135, 35));
}

TEST(PngExportCli, ALogScaleSpreadsALayersOrdersOfMagnitudeOverTheGreys) {
    // scale=log: grey = (log10 v - log10 v_min) / (log10 v_max - log10 v_min) over the positive values. On a
    // drainage layer (one cell's area to the whole map's: three orders of magnitude here) the linear map
    // leaves nearly every sample black; the log map gives a cell draining 10x more area one third of the
    // range more.
    TempDir dir;
    const auto spec = dir.write("log.orogen",
                                "orogen 1\nseed 3\ngrid 65 cell=30\n"
                                "base = generate:fault(iterations=60, displacement=4)\n"
                                "river = erode:stream-power(base, years=1e5, dt=5e4)\n"
                                "export:png(river, path=\"lin.png\", bits=16, layer=\"drainage\")\n"
                                "export:png(river, path=\"log.png\", bits=16, layer=\"drainage\", scale=\"log\")\n"
                                "export:raw(river, path=\"h.r32\")\n");
    const RunResult r = run_orogen("run " + q(spec) + " --out " + q(dir / "out"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const GrayImage lin = read_gray_png(dir / "out" / "lin.png"), log = read_gray_png(dir / "out" / "log.png");
    ASSERT_EQ(log.samples.size(), std::size_t(65 * 65));
    // The same order (a monotone map of the same values), the ends at black and white.
    std::size_t lin_bright = 0, log_bright = 0;
    for (std::size_t a = 0; a < lin.samples.size(); ++a) {
        lin_bright += lin.samples[a] > 32767;
        log_bright += log.samples[a] > 32767;
        for (std::size_t b = a + 1; b < lin.samples.size(); b += 97)
            if (lin.samples[a] < lin.samples[b]) ASSERT_LE(log.samples[a], log.samples[b]) << a << " " << b;
    }
    EXPECT_EQ(*std::min_element(log.samples.begin(), log.samples.end()), 0);
    EXPECT_EQ(*std::max_element(log.samples.begin(), log.samples.end()), 65535);
    // Linear: only the trunk rivers are brighter than mid-grey. Log: every cell draining more than about
    // the square root of the largest area is, a whole tributary network.
    EXPECT_LT(lin_bright, lin.samples.size() / 100);
    EXPECT_GT(log_bright, 5 * std::max<std::size_t>(lin_bright, 1));
    EXPECT_GT(log_bright, lin.samples.size() / 100);
}

TEST(PngExportCli, LayerAndHillshadeMistakesFailAtCheckTime) {
    TempDir dir;
    const auto spec = dir.write("bad.orogen",
                                "orogen 1\ngrid 33\nbase = generate:fault()\n"
                                "export:png(base, path=\"a.png\", layer=\"sediment\")\n"
                                "export:png(base, path=\"b.png\", layer=\"eroded\", hillshade=true)\n"
                                "export:png(base, path=\"c.png\", azimuth=90)\n");
    const RunResult r = run_orogen("check " + q(spec));
    EXPECT_EQ(r.exit_code, 2);
    for (const char* want :
         {"bad.orogen:4:38: error: export:png: no layer 'sediment' on the input (the input has no layers); use "
          "\"height\" (the default) or the name of an existing layer",
          "bad.orogen:5:38: error: export:png: hillshade shades the terrain's heights; give either layer= or "
          "hillshade=true, not both",
          "bad.orogen:6:40: error: export:png: azimuth and elevation place the light of hillshade=true"})
        EXPECT_NE(r.err.find(want), std::string::npos) << "missing: " << want << "\n" << r.err;
}

// Issue 32, item 7: every contradiction inside one call is reported at once, not the first of them.
TEST(PngExportCli, EveryContradictionInOneCallIsReportedAtOnce) {
    TempDir dir;
    const auto spec = dir.write("bad.orogen",
                                "orogen 1\ngrid 33\nbase = generate:fault()\n"
                                "export:png(base, path=\"a.png\", tonemap=aces, exposure=1, relief=true, bits=16, "
                                "azimuth=10)\n");
    const RunResult r = run_orogen("check " + q(spec));
    EXPECT_EQ(r.exit_code, 2);
    for (const char* want : {"bad.orogen:4:40: error: export:png: tonemap= applies to an image input",
                             "bad.orogen:4:55: error: export:png: exposure= applies to an image input",
                             "bad.orogen:4:65: error: export:png: relief=true writes an 8-bit colour map"})
        EXPECT_NE(r.err.find(want), std::string::npos) << "missing: " << want << "\n" << r.err;
    EXPECT_NE(r.err.find("3 errors in"), std::string::npos) << r.err;
}

// relief=true: the splat colours by height, darker on faces turned from the light.
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>

// The one RGBA encoder (orogen/io.hpp): every level gives back the very pixels, and level 1 (strips deflated
// in parallel, for the textures glTF and tiles embed) the same bytes on one thread and on two.
TEST(RgbaPng, EveryLevelDecodesToThePixelsAndLevelOneToTheSameBytesOnAnyThreadCount) {
    const int w = 301, h = 203;  // more rows than level 1's 16 strips, odd sizes
    std::vector<std::uint8_t> rgba(std::size_t(w) * h * 4);
    for (std::size_t i = 0; i < rgba.size(); ++i)
        rgba[i] = std::uint8_t((i * 2654435761u) >> 13) & ((i / 4) % 7 ? 0xff : 0x0f);
    std::vector<std::uint8_t> level1[2];
    for (int threads : {1, 2}) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
        level1[threads - 1] = orogen::encode_rgba_png(rgba, w, h, 1);
    }
    EXPECT_EQ(level1[0], level1[1]);
    for (const int level : {1, 6, 12}) {
        const auto png = orogen::encode_rgba_png(rgba, w, h, level);
        int dw = 0, dh = 0, channels = 0;
        stbi_uc* px = stbi_load_from_memory(png.data(), int(png.size()), &dw, &dh, &channels, 4);
        ASSERT_NE(px, nullptr) << "level " << level << ": " << stbi_failure_reason();
        EXPECT_EQ(dw, w);
        EXPECT_EQ(dh, h);
        EXPECT_EQ(0, std::memcmp(px, rgba.data(), rgba.size())) << "level " << level;
        stbi_image_free(px);
    }
}

TEST(PngExportCli, ReliefIsTheSplatColourShadedByTheLight) {
    TempDir dir;
    const auto spec = dir.write("relief.orogen",
                                "orogen 1\ngrid 65 cell=10\nhill = generate:shape(kind=pyramid, height=300)\n"
                                "export:png(hill, path=\"relief.png\", relief=true, azimuth=315, elevation=45)\n");
    const RunResult r = run_orogen("run " + q(spec) + " --out " + q(dir.path()) + " --quiet");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    int w = 0, h = 0, channels = 0;
    stbi_uc* px = stbi_load((dir / "relief.png").c_str(), &w, &h, &channels, 4);
    ASSERT_NE(px, nullptr);
    EXPECT_EQ(w, 65);
    EXPECT_EQ(h, 65);
    EXPECT_EQ(channels, 4);
    auto at = [&](int x, int y) { return px + 4 * (std::size_t(y) * 65 + std::size_t(x)); };
    // The low corners are sand (yellow-brown: red > green > blue), the summit is snow (bright, nearly grey).
    const stbi_uc* corner = at(2, 2);
    EXPECT_GT(corner[0], corner[1]);
    EXPECT_GT(corner[1], corner[2]);
    const stbi_uc* summit = at(32, 32);
    EXPECT_GT(int(summit[2]), 150);
    EXPECT_LT(std::abs(int(summit[0]) - int(summit[2])), 30);
    // The north-west face (towards the light at 315°) is brighter than the south-east face.
    const stbi_uc* lit = at(20, 20);
    const stbi_uc* shaded = at(44, 44);
    EXPECT_GT(int(lit[0]) + lit[1] + lit[2], int(shaded[0]) + shaded[1] + shaded[2] + 60);
    stbi_image_free(px);
    // A relief map is 8-bit colour: bits= with it is a mistake.
    const auto bad = dir.write("bad.orogen",
                               "orogen 1\ngrid 9\nt = generate:fault()\n"
                               "export:png(t, path=\"r.png\", relief=true, bits=16)\n");
    const RunResult b = run_orogen("check " + q(bad));
    EXPECT_EQ(b.exit_code, 2);
    EXPECT_NE(b.err.find("bad.orogen:4:36: error: export:png: relief=true writes an 8-bit colour map of the heights; "
                         "drop hillshade=, layer= and bits="),
              std::string::npos)
        << b.err;
}

// Issue 53, "outputs that are hard to read": colours=rivers draws the drainage layer's rivers in blue over the
// pale shaded terrain, wider where they drain more; colours=auto puts a layer with both signs on a diverging
// map around zero (erosion blue, deposition red) and any other on a sequential one.
TEST(PngExportCli, RiversAndADivergingLayerReadAtAGlance) {
    TempDir dir;
    const auto spec = dir.write("colours.orogen",
                                "orogen 1\nseed 3\ngrid 129 cell=30\n"
                                "base = generate:fault(iterations=80, displacement=6)\n"
                                "river = erode:stream-power(base, years=2e5, dt=5e4)\n"
                                "worn = erode:thermal(base, iterations=40, talus=20)\n"
                                "export:png(river, path=\"rivers.png\", colours=\"rivers\")\n"
                                "export:png(worn, path=\"eroded.png\", layer=\"eroded\", colours=\"auto\")\n"
                                "export:png(river, path=\"area.png\", layer=\"drainage\", bits=16)\n"
                                "export:png(worn, path=\"eroded16.png\", layer=\"eroded\", bits=16)\n");
    const RunResult r = run_orogen("run " + q(spec) + " --out " + q(dir / "out") + " --quiet");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    // The layers' values, in order (16-bit grey: the lowest black, the highest white).
    const GrayImage area = read_gray_png(dir / "out" / "area.png"), e = read_gray_png(dir / "out" / "eroded16.png");
    auto load = [&](const char* name) {
        int w = 0, h = 0, c = 0;
        stbi_uc* px = stbi_load((dir / "out" / name).c_str(), &w, &h, &c, 4);
        EXPECT_EQ(w, 129);
        std::vector<stbi_uc> v(px, px + std::size_t(w) * std::size_t(h) * 4);
        stbi_image_free(px);
        return v;
    };
    const auto rivers = load("rivers.png"), eroded = load("eroded.png");
    // The largest river is blue (blue well above red); a cell draining only itself, far from any river, is
    // grey (its channels within a few units).
    const std::size_t n = area.samples.size();
    ASSERT_EQ(n, std::size_t(129 * 129));
    const std::size_t trunk =
        std::size_t(std::max_element(area.samples.begin(), area.samples.end()) - area.samples.begin());
    EXPECT_GT(int(rivers[4 * trunk + 2]), int(rivers[4 * trunk]) + 60);
    std::size_t greys = 0, blues = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const int red = rivers[4 * i], blue = rivers[4 * i + 2];
        greys += std::abs(blue - red) < 25;
        blues += blue > red + 40;
    }
    EXPECT_GT(greys, n / 2);  // most of the map is ground, not paint
    EXPECT_GT(blues, n / 100);  // and the river network shows
    // Diverging: where thermal took the most material the pixel is blue, where it laid the most down red, and
    // the ground it left alone (eroded 0, most of the map) white-grey: the map is centred on zero.
    const std::size_t cut = std::size_t(std::min_element(e.samples.begin(), e.samples.end()) - e.samples.begin());
    const std::size_t laid = std::size_t(std::max_element(e.samples.begin(), e.samples.end()) - e.samples.begin());
    EXPECT_GT(int(eroded[4 * cut + 2]), int(eroded[4 * cut]) + 40);
    EXPECT_GT(int(eroded[4 * laid]), int(eroded[4 * laid + 2]) + 40);
    std::size_t neutral = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const int red = eroded[4 * i], green = eroded[4 * i + 1], blue = eroded[4 * i + 2];
        neutral += std::abs(red - blue) < 20 && std::abs(red - green) < 20 && red > 130;
    }
    EXPECT_GT(neutral, n / 5);
    // Mistakes at check time: rivers without a drainage layer, and bits= with a colour map.
    const auto bad = dir.write("bad.orogen",
                               "orogen 1\ngrid 9\nt = generate:fault()\n"
                               "export:png(t, path=\"r.png\", colours=\"rivers\")\n"
                               "export:png(t, path=\"a.png\", colours=\"auto\", bits=16)\n");
    const RunResult b = run_orogen("check " + q(bad));
    EXPECT_EQ(b.exit_code, 2);
    EXPECT_NE(b.err.find("bad.orogen:4:37: error: export:png: no layer 'drainage' on the input"), std::string::npos)
        << b.err;
    EXPECT_NE(b.err.find("colours=auto writes an 8-bit colour PNG; drop bits="), std::string::npos) << b.err;
}
