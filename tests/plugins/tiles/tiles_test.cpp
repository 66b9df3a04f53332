// export:tiles: the layout covers the grid with shared edges; the files the real binary writes read back
// (orogen's PNG reader, the RAW bytes, GDAL through the VRT) equal the terrain the same run wrote as one .r16.
#include "tiles.hpp"

#include "orogen_test.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>

#include <gdal_priv.h>
#include <gtest/gtest.h>

#include <cstring>

using namespace orogen;
using namespace orogen::test;
using namespace orogen::tiles_export;

namespace {

std::vector<std::uint16_t> read_u16(const fs::path& p) {
    const std::string bytes = slurp(p);
    std::vector<std::uint16_t> v(bytes.size() / 2);
    for (std::size_t i = 0; i < v.size(); ++i)
        v[i] = std::uint16_t(std::uint8_t(bytes[2 * i]) | (std::uint8_t(bytes[2 * i + 1]) << 8));
    return v;
}

// 129² samples, 33-sample tiles: 4 × 4 tiles of 33 (128 = 4 · 32).
const std::string spec_head =
    "orogen 1\nseed 11\ngrid 129 cell=20\n"
    "t = generate:diamond-square(roughness=0.6, amplitude=800)\n"
    "w = erode:thermal(t, iterations=4)\n"
    "export:raw(w, path=\"whole.r16\")\n";

}  // namespace

TEST(TilesLayout, TilesCoverTheGridAndNeighboursShareOneRowOrColumn) {
    for (int w : {2, 3, 33, 64, 65, 100, 129}) {
        for (int size : {2, 5, 33, 64, 505}) {
            const auto tiles = layout(w, 47, size, "t", Format::png16);
            std::vector<int> covered(std::size_t(w) * 47, 0);
            for (const Tile& t : tiles) {
                ASSERT_GE(t.width, 2);
                ASSERT_LE(t.width, size);
                ASSERT_LE(t.x0 + t.width, w);
                for (int y = t.y0; y < t.y0 + t.height; ++y)
                    for (int x = t.x0; x < t.x0 + t.width; ++x) ++covered[std::size_t(y) * std::size_t(w) + std::size_t(x)];
                // a neighbour to the east starts on this tile's last column
                for (const Tile& u : tiles)
                    if (u.row == t.row && u.column == t.column + 1) EXPECT_EQ(u.x0, t.x0 + t.width - 1);
            }
            for (int y = 0; y < 47; ++y)
                for (int x = 0; x < w; ++x) {
                    const int c = covered[std::size_t(y) * std::size_t(w) + std::size_t(x)];
                    EXPECT_GE(c, 1) << "sample " << x << "," << y << " in no tile (w " << w << ", size " << size << ")";
                    EXPECT_LE(c, 4);
                }
        }
    }
    const auto unreal = layout(2017, 2017, 505, "t", Format::r16);
    EXPECT_EQ(unreal.size(), 16u);  // 2016 = 4 · 504
    for (const Tile& t : unreal) EXPECT_EQ(t.width, 505);
    EXPECT_EQ(unreal[5].file, "t_x1_y1.r16");
    EXPECT_THROW(layout(100, 100, 1, "t", Format::r16), BadInput);
}

TEST(TilesCli, PngTilesShareTheirEdgesAndMosaicToTheWholeTerrain) {
    TempDir dir;
    const auto spec = dir.write("t.orogen", spec_head + "export:tiles(w, path=\"engine/alps.json\", tile_size=33)\n");
    const RunResult r = run_orogen("run " + q(spec) + " --out " + q(dir / "out"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    // The same terrain as one .r16 with the same (its own) range: every tile is a window onto it.
    const std::vector<std::uint16_t> whole = read_u16(dir / "out" / "whole.r16");
    ASSERT_EQ(whole.size(), 129u * 129u);
    for (int row = 0; row < 4; ++row)
        for (int column = 0; column < 4; ++column) {
            const std::string name = "alps_x" + std::to_string(column) + "_y" + std::to_string(row) + ".png";
            const GrayImage tile = read_gray_png(dir / "out" / "engine" / name);
            ASSERT_EQ(tile.width, 33);
            ASSERT_EQ(tile.height, 33);
            ASSERT_EQ(tile.bits, 16);
            for (int y = 0; y < 33; ++y)
                for (int x = 0; x < 33; ++x)
                    ASSERT_EQ(tile.samples[std::size_t(y * 33 + x)],
                              whole[std::size_t((row * 32 + y) * 129 + column * 32 + x)])
                        << name << " sample " << x << "," << y;
        }
    // Neighbours: the east edge of one is the west edge of the next, the south edge the next row's north edge.
    const GrayImage a = read_gray_png(dir / "out/engine/alps_x1_y2.png"), b = read_gray_png(dir / "out/engine/alps_x2_y2.png"),
                    c = read_gray_png(dir / "out/engine/alps_x1_y3.png");
    for (int i = 0; i < 33; ++i) {
        EXPECT_EQ(a.samples[std::size_t(i * 33 + 32)], b.samples[std::size_t(i * 33)]);
        EXPECT_EQ(a.samples[std::size_t(32 * 33 + i)], c.samples[std::size_t(i)]);
    }
    // The index and the manifest name every tile.
    const std::string index = slurp(dir / "out/engine/alps.json"), manifest = slurp(dir / "out/manifest.json");
    EXPECT_NE(index.find("\"columns\": 4"), std::string::npos) << index;
    EXPECT_NE(index.find("\"tile_size\": 33"), std::string::npos);
    EXPECT_NE(index.find("\"file\": \"alps_x3_y3.png\", \"column\": 3, \"row\": 3, \"x0\": 96, \"y0\": 96"),
              std::string::npos);
    for (const char* f : {"engine/alps_x0_y0.png", "engine/alps_x3_y3.png", "engine/alps.json", "engine/alps.vrt"})
        EXPECT_NE(manifest.find(f), std::string::npos) << f;
}

TEST(TilesCli, GdalReadsTheMosaicThroughTheVrtInMetres) {
    TempDir dir;
    const auto spec = dir.write("t.orogen", spec_head +
                                                "export:tiles(w, path=\"png/t.json\", tile_size=40)\n"  // uneven last tiles
                                                "export:tiles(w, path=\"r16/t.json\", format=r16, tile_size=65)\n"
                                                "export:tiles(w, path=\"r32/t.json\", format=r32, tile_size=17)\n"
                                                "export:raw(w, path=\"whole.r32\")\n");
    const RunResult r = run_orogen("run " + q(spec) + " --out " + q(dir / "out"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("for equal tiles use a grid of k"), std::string::npos) << r.err;  // 128 is not 3 · 39
    const std::string metres_bytes = slurp(dir / "out/whole.r32");
    std::vector<float> metres(129 * 129);
    ASSERT_EQ(metres_bytes.size(), metres.size() * 4);
    std::memcpy(metres.data(), metres_bytes.data(), metres_bytes.size());
    float low = metres[0], high = metres[0];
    for (float v : metres) low = std::min(low, v), high = std::max(high, v);
    const double step = (double(high) - double(low)) / 65535.0;
    GDALAllRegister();
    for (const char* folder : {"png", "r16", "r32"}) {
        std::unique_ptr<GDALDataset> ds(
            GDALDataset::Open((dir / "out" / folder / "t.vrt").c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY));
        ASSERT_TRUE(ds) << folder << ": GDAL could not open the VRT: " << CPLGetLastErrorMsg();
        ASSERT_EQ(ds->GetRasterXSize(), 129);
        ASSERT_EQ(ds->GetRasterYSize(), 129);
        double gt[6];
        ASSERT_EQ(ds->GetGeoTransform(gt), CE_None);
        EXPECT_DOUBLE_EQ(gt[1], 20.0);
        EXPECT_DOUBLE_EQ(gt[5], -20.0);
        GDALRasterBand* band = ds->GetRasterBand(1);
        int has = 0;
        const double offset = band->GetOffset(&has), scale = has ? band->GetScale() : 1.0;
        std::vector<double> v(129 * 129);
        ASSERT_EQ(band->RasterIO(GF_Read, 0, 0, 129, 129, v.data(), 129, 129, GDT_Float64, 0, 0, nullptr), CE_None);
        double worst = 0;
        for (std::size_t i = 0; i < v.size(); ++i)
            worst = std::max(worst, std::abs((has ? offset + scale * v[i] : v[i]) - double(metres[i])));
        // 16-bit tiles: within half a quantisation step; float tiles: exact
        EXPECT_LE(worst, std::string(folder) == "r32" ? 0.0 : 0.5 * step + 1e-9) << folder;
    }
}

TEST(TilesCli, SameBytesOnOneAndTwoThreads) {
    TempDir dir;
    const auto spec = dir.write("t.orogen", spec_head + "export:tiles(w, path=\"t.json\", tile_size=17)\n");
    ASSERT_EQ(run_orogen("run " + q(spec) + " --out " + q(dir / "one") + " --threads 1").exit_code, 0);
    ASSERT_EQ(run_orogen("run " + q(spec) + " --out " + q(dir / "two") + " --threads 2").exit_code, 0);
    for (int i = 0; i < 8; ++i) {
        const std::string name = "t_x" + std::to_string(i) + "_y" + std::to_string(7 - i) + ".png";
        EXPECT_EQ(slurp(dir / "one" / name), slurp(dir / "two" / name)) << name;
    }
    EXPECT_EQ(slurp(dir / "one/t.json"), slurp(dir / "two/t.json"));
}

TEST(TilesCli, BadParametersAreCheckErrorsThatSayWhere) {
    TempDir dir;
    for (const std::string& line : {std::string("export:tiles(w, path=\"t.json\", tile_size=1)"),
                                    std::string("export:tiles(w, path=\"t.json\", low=5)"),
                                    std::string("export:tiles(w, path=\"t.json\", low=5, high=2)"),
                                    std::string("export:tiles(w, path=\"t.json\", format=r32, low=0, high=9)"),
                                    std::string("export:tiles(w, path=\"t.png\")"),
                                    std::string("export:tiles(w, path=\"t.json\", format=tiff)")}) {
        const auto spec = dir.write("bad.orogen", spec_head + line + "\n");
        const RunResult r = run_orogen("check " + q(spec));
        EXPECT_EQ(r.exit_code, 2) << line << "\n" << r.err;
        EXPECT_NE(r.err.find("bad.orogen:7:"), std::string::npos) << line << "\n" << r.err;
    }
}
