// `orogen analyze --discriminate` through the real binary: white noise told from two real DEMs shipped in
// data/dems/ (the table, discriminate.json, .txt and the picture), and bad input: a missing file, a window larger
// than a source, cell sizes too far apart, too few sources of a kind; each one message naming what is wrong and
// the fix, exit 2, nothing written.
#include "orogen_test.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <regex>
#include <vector>

namespace {

using namespace orogen::test;

const fs::path dems = fs::path(OROGEN_SOURCE_DIR) / "data" / "dems";
const fs::path baspa = dems / "himalaya_baspa_30m.tif", kahurangi = dems / "nz_kahurangi_30m.tif",
               rif = dems / "morocco_rif_27m.tif";

/// NAME.f32 + NAME.json in `dir`: side² samples of white noise (±100 m) `cell` metres apart.
fs::path noise_f32(const TempDir& dir, const std::string& name, int side, double cell, std::uint64_t seed) {
    std::vector<float> z;
    std::uint64_t state = seed;
    for (int i = 0; i < side * side; ++i) {
        state = state * 6364136223846793005ull + 1442695040888963407ull;  // PCG's LCG step; the top bits
        z.push_back(float(100.0 * (double(state >> 11) / double(1ull << 53) * 2.0 - 1.0)));
    }
    const fs::path path = dir / (name + ".f32");
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(z.data()), std::streamsize(z.size() * 4));
    dir.write(name + ".json",
              "{\"nx\": " + std::to_string(side) + ", \"ny\": " + std::to_string(side) +
                  ", \"dx_m\": " + std::to_string(cell) + "}");
    return path;
}

TEST(DiscriminateCli, TellsWhiteNoiseFromRealRangesAndWritesTheReport) {
    TempDir dir;
    const fs::path a = noise_f32(dir, "noise_a", 400, 30.0, 1), b = noise_f32(dir, "noise_b", 400, 30.0, 2);
    const auto r = run_orogen("analyze --discriminate " + q(a) + " " + q(b) + " --against " + q(baspa) + " " +
                              q(kahurangi) + " " + q(rif) + " --window-m 1920 --out " + q(dir / "out"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    // Told apart at once (a window or two of noise may pass: one noise source is all the other learns from).
    EXPECT_TRUE(std::regex_search(r.out, std::regex("balanced accuracy  (9[5-9]|100)\\.[0-9] %"))) << r.out;
    EXPECT_TRUE(std::regex_search(r.out, std::regex("noise_a +generated +36 +[0-9]\\.[0-9] %"))) << r.out;
    EXPECT_TRUE(std::regex_search(r.out, std::regex("himalaya_baspa_30m +real +225 +(9[0-9]|100)\\.[0-9] %"))) << r.out;
    // Each source's windows in its own cells: 1920 m is 64 samples of 30 m and 71 of the Rif's 27 m.
    EXPECT_NE(r.out.find("windows of 1920 m (64 x 64 samples, 71 x 71 samples)"), std::string::npos) << r.out;
    EXPECT_TRUE(std::regex_search(r.out, std::regex("morocco_rif_27m +real +49 +"))) << r.out;
    EXPECT_NE(r.out.find("the figures that tell apart most"), std::string::npos) << r.out;
    const std::string json = slurp(dir / "out/discriminate.json");
    std::smatch m;
    ASSERT_TRUE(std::regex_search(json, m, std::regex("\"balanced_accuracy\": ([0-9.]+),"))) << json.substr(0, 400);
    EXPECT_GE(std::stod(m[1]), 0.95);
    EXPECT_NE(json.find("\"key\": \"roughness_ratio\""), std::string::npos);
    EXPECT_NE(json.find("Perron, Kirchner & Dietrich 2008"), std::string::npos);
    EXPECT_EQ(slurp(dir / "out/discriminate.txt"), r.out.substr(0, slurp(dir / "out/discriminate.txt").size()));
    const std::string png = slurp(dir / "out/discriminate.png");
    ASSERT_GT(png.size(), 24u);
    EXPECT_EQ(png.substr(1, 3), "PNG");
    // Six thumbnails a row in slots of the largest window shown (64 samples of 30 m, or the Rif's 71 of 27 m),
    // 8 samples apart: 6·slot + 7·8 wide, 2·slot + 3·8 high (big-endian in IHDR).
    auto be32 = [&](std::size_t at) {
        return (std::uint32_t(std::uint8_t(png[at])) << 24) | (std::uint32_t(std::uint8_t(png[at + 1])) << 16) |
            (std::uint32_t(std::uint8_t(png[at + 2])) << 8) | std::uint32_t(std::uint8_t(png[at + 3]));
    };
    const std::uint32_t slot = (be32(20) - 3u * 8u) / 2u;
    EXPECT_TRUE(slot == 64u || slot == 71u) << slot;
    EXPECT_EQ(be32(16), 6u * slot + 7u * 8u);
    EXPECT_EQ(be32(20), 2u * slot + 3u * 8u);
}

/// Runs `args`, expects exit 2, `message` in stderr and no report written.
void expect_refused(const TempDir& dir, const std::string& args, const std::string& message) {
    const auto r = run_orogen("analyze --discriminate " + args + " --out " + q(dir / "out"));
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out/discriminate.json"));
    EXPECT_FALSE(fs::exists(dir / "out/discriminate.png"));
}

TEST(DiscriminateCli, RefusesBadInputWithTheFix) {
    TempDir dir;
    const fs::path a = noise_f32(dir, "a", 300, 30.0, 1), b = noise_f32(dir, "b", 300, 30.0, 2);
    const fs::path small = noise_f32(dir, "small", 100, 30.0, 3), coarse = noise_f32(dir, "coarse", 300, 90.0, 4);
    const std::string real = " --against " + q(baspa) + " " + q(kahurangi);
    expect_refused(dir, q(a) + " " + q(dir / "missing.tif") + real, "missing.tif: no such file");
    expect_refused(dir, q(a) + " " + q(small) + real,
                   "small (100x100 samples of 30 m) is smaller than one window of 3840 m (128 samples); give a "
                   "smaller window (--window-m 3000 or less) or leave it out");
    expect_refused(dir, q(a) + " " + q(coarse) + real, "coarse has 90 m cells and a 30 m: more than 12 % apart");
    expect_refused(dir, q(a) + " " + q(coarse) + real, "gdalwarp -tr 90 90");
    expect_refused(dir, q(a) + real, "needs at least two generated terrains and two real DEMs");
    expect_refused(dir, q(a) + " " + q(b) + " --against " + q(baspa), "needs at least two generated terrains");
    expect_refused(dir, q(a) + " " + q(b) + real + " --window-m 0", "--window-m needs the windows' side in metres");
}

TEST(DiscriminateCli, WindowWithoutDiscriminateIsAMistake) {
    TempDir dir;
    const auto r = run_orogen("analyze " + q(baspa) + " --window-m 1000 --no-render --out " + q(dir / "out"));
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--window-m is the window of --discriminate; add --discriminate"), std::string::npos) << r.err;
}

}  // namespace
