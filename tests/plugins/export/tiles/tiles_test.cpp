// export:tiles: the layout covers the grid with shared edges; the files the real binary writes read back
// (orogen's PNG reader, the RAW bytes, GDAL through the VRT) equal the terrain the same run wrote as one .r16.
#include "lod.hpp"
#include "tiles.hpp"

#include "orogen_test.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>

#include <gdal_priv.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sys/wait.h>
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
                    for (int x = t.x0; x < t.x0 + t.width; ++x)
                        ++covered[std::size_t(y) * std::size_t(w) + std::size_t(x)];
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
    const GrayImage a = read_gray_png(dir / "out/engine/alps_x1_y2.png"),
                    b = read_gray_png(dir / "out/engine/alps_x2_y2.png"),
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

// Issue 32, item 10: what a run says agrees with itself and stays short. A grid smaller than one tile is
// written as one tile of its own size, said once; sixteen tiles are one line of the file list; --quiet says
// nothing when the run succeeds.
TEST(TilesCli, TheRunSaysWhatItWroteOnceAndQuietSaysNothing) {
    TempDir dir;
    auto spec = dir.write("small.orogen", spec_head + "export:tiles(w, path=\"engine/alps.json\", tile_size=257)\n");
    RunResult r = run_orogen("run " + q(spec) + " --out " + q(dir / "small"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("export:tiles: warning: the grid (129 × 129 samples) is smaller than one tile of 257"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("export:tiles: wrote 1 tile of 129 × 129 samples, engine/alps.json"), std::string::npos)
        << r.err;
    EXPECT_EQ(r.err.find("the last tiles are"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("tiles of 257"), std::string::npos) << r.err;

    spec = dir.write("t.orogen", spec_head + "export:tiles(w, path=\"engine/alps.json\", tile_size=33)\n");
    r = run_orogen("run " + q(spec) + " --out " + q(dir / "out"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("export:tiles: wrote 16 tiles of 33 samples (4 × 4), engine/alps.json"), std::string::npos)
        << r.err;
    // 21 files: whole.r16 and its sidecar, 16 tiles, the index, the VRT, the manifest.
    EXPECT_NE(r.out.find("wrote 21 files to "), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("/out/engine/alps_x0_y0.png ... alps_x3_y3.png (16 files)\n"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("alps_x1_y0.png"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("/out/engine/alps.json\n"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("/out/manifest.json\n"), std::string::npos) << r.out;
    EXPECT_LT(std::count(r.out.begin(), r.out.end(), '\n'), 20) << r.out;  // the files in 7 lines, the timings

    r = run_orogen("run " + q(spec) + " --out " + q(dir / "quiet") + " --quiet");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.out, "");
    EXPECT_EQ(r.err, "");
    EXPECT_TRUE(fs::exists(dir / "quiet/engine/alps_x3_y3.png"));
}

TEST(TilesCli, GdalReadsTheMosaicThroughTheVrtInMetres) {
    TempDir dir;
    const auto spec = dir.write("t.orogen",
                                spec_head +
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

// Issue 32, item 7: a call's mistakes are reported together (a missing high no longer hides that format=r32
// has no 16-bit scale, nor a mesh parameter given to a raster format).
TEST(TilesCli, EveryMistakeInOneCallIsReportedAtOnce) {
    TempDir dir;
    const auto spec =
        dir.write("bad.orogen", spec_head + "export:tiles(w, path=\"t.json\", format=r32, low=5, scale=2)\n");
    const RunResult r = run_orogen("check " + q(spec));
    EXPECT_EQ(r.exit_code, 2) << r.err;
    for (const char* want :
         {"error: export:tiles: scale applies to format=glb", "error: export:tiles: give both low and high",
          "error: export:tiles: low and high set the 16-bit scale; format=r32"})
        EXPECT_NE(r.err.find(want), std::string::npos) << "missing: " << want << "\n" << r.err;
    EXPECT_NE(r.err.find("3 errors in"), std::string::npos) << r.err;
}

// ------------------------------------------------------------ format=glb (lod.hpp)

namespace {

/// A rough synthetic terrain, w × h samples.
std::vector<float> bumpy(int w, int h) {
    std::vector<float> g(std::size_t(w) * std::size_t(h));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            g[std::size_t(y) * std::size_t(w) + std::size_t(x)] =
                float(40.0 * std::sin(0.37 * x) * std::cos(0.23 * y) + 7.0 * std::sin(1.9 * x + 0.7 * y));
    return g;
}

lod::Samples sample(const std::vector<float>& g, int w, AxisSamples cols, AxisSamples rows) {
    lod::Samples s;
    for (int i = 0; i < cols.size(); ++i) s.xs.push_back(cols.at(i));
    for (int j = 0; j < rows.size(); ++j) s.ys.push_back(rows.at(j));
    for (int y : s.ys)
        for (int x : s.xs) s.h.push_back(g[std::size_t(y) * std::size_t(w) + std::size_t(x)]);
    return s;
}

lod::Mesh mesh_of(const lod::Chunk& c, const std::vector<float>& g, int w, int h, double skirt) {
    const auto lat = lod::chunk_lattice(c, w, h);
    return lod::chunk_mesh(c, sample(g, w, lat[0], lat[1]), w, h, 2.0, 1.0, skirt);
}

}  // namespace

TEST(TilesLod, PyramidHalvesEachLevelUpToOneChunk) {
    const auto chunks = lod::pyramid(97, 61, 17, "t");
    ASSERT_EQ(chunks.size(), 24u + 6u + 2u + 1u);
    EXPECT_EQ(chunks.back().level, 3);
    EXPECT_EQ(chunks.back().x1, 96);
    EXPECT_EQ(chunks.back().y1, 60);
    // Level 0 is the engine tiles of layout().
    const auto tiles = layout(97, 61, 17, "t", Format::png16);
    for (std::size_t i = 0; i < tiles.size(); ++i) {
        EXPECT_EQ(chunks[i].x0, tiles[i].x0);
        EXPECT_EQ(chunks[i].x1, tiles[i].x0 + tiles[i].width - 1);
    }
}

TEST(TilesLod, NeighboursOfOneLevelShareTheirEdgeVerticesAndNormalsBitForBit) {
    const int w = 97, h = 61;
    const auto g = bumpy(w, h);
    const auto chunks = lod::pyramid(w, h, 17, "t");
    for (int level = 0; level < 2; ++level) {
        const lod::Chunk *a = nullptr, *b = nullptr;
        for (const auto& c : chunks)
            if (c.level == level && c.row == 0 && c.column == 0) a = &c;
            else if (c.level == level && c.row == 0 && c.column == 1) b = &c;
        ASSERT_TRUE(a && b);
        const lod::Mesh ma = mesh_of(*a, g, w, h, 0.0), mb = mesh_of(*b, g, w, h, 0.0);
        const std::size_t na = std::size_t(std::lround(ma.max[0] / 2.0)) / (std::size_t(1) << level) + 1;
        const std::size_t nb = std::size_t(std::lround(mb.max[0] / 2.0)) / (std::size_t(1) << level) + 1;
        const std::size_t rows = ma.vertex_count() / na;
        ASSERT_EQ(rows, mb.vertex_count() / nb);
        for (std::size_t r = 0; r < rows; ++r) {
            const std::size_t ea = r * na + na - 1, wb = r * nb;  // a's east edge, b's west edge
            for (int k = 0; k < 3; ++k)
                EXPECT_EQ(ma.normals[3 * ea + std::size_t(k)], mb.normals[3 * wb + std::size_t(k)]);
            EXPECT_EQ(ma.positions[3 * ea + 1], mb.positions[3 * wb + 1]);
            EXPECT_EQ(double(ma.positions[3 * ea]) + a->x0 * 2.0, double(mb.positions[3 * wb]) + b->x0 * 2.0);
        }
    }
}

TEST(TilesLod, DeviationBoundsTheCoarseSurfaceAndSkirtsCoverTheCracks) {
    const int w = 97, h = 61;
    const auto g = bumpy(w, h);
    const auto chunks = lod::pyramid(w, h, 17, "t");
    const int levels = chunks.back().level + 1;
    for (const auto& c : chunks) {
        const auto lat = lod::chunk_lattice(c, w, h);
        const lod::Samples s = sample(g, w, lat[0], lat[1]);
        const double dev = lod::deviation(c, s, w, h, 1.0);
        if (c.level == 0) EXPECT_EQ(dev, 0.0);
        else EXPECT_GT(dev, 0.0) << "a rough terrain loses detail at level " << c.level;
        // The skirt is at least the gap between the full-resolution edge and any level's edge along it.
        const auto e = lod::edge_lattices(c, w, h, levels);
        const double skirt =
            lod::skirt_depth(c, sample(g, w, e[0][0], e[0][1]), sample(g, w, e[1][0], e[1][1]), w, h, levels, 2.0, 1.0);
        for (int j = 1; j < levels; ++j) {
            const int st = 1 << j;
            for (int x = c.x0; x <= c.x1; ++x) {
                const int xa = std::min(x / st * st, w - 1), xb = std::min(xa + st, w - 1);
                if (xa == x) continue;
                const double va = g[std::size_t(c.y0) * w + xa], vb = g[std::size_t(c.y0) * w + xb];
                const double line = va + (vb - va) * (x - xa) / double(xb - xa);
                EXPECT_LE(2.0 * std::abs(g[std::size_t(c.y0) * w + x] - line), skirt + 1e-9);
            }
        }
        // The skirt: a copy of every edge vertex, that depth below it.
        const lod::Mesh m = lod::chunk_mesh(c, s, w, h, 2.0, 1.0, skirt), bare = mesh_of(c, g, w, h, 0.0);
        ASSERT_GT(m.vertex_count(), bare.vertex_count());
        for (std::size_t k = bare.vertex_count(); k < m.vertex_count(); ++k) {
            bool found = false;
            for (std::size_t v = 0; v < bare.vertex_count() && !found; ++v)
                found = bare.positions[3 * v] == m.positions[3 * k] &&
                    bare.positions[3 * v + 2] == m.positions[3 * k + 2] &&
                    std::abs(double(bare.positions[3 * v + 1]) - skirt - double(m.positions[3 * k + 1])) < 1e-3;
            EXPECT_TRUE(found) << "skirt vertex " << k << " of chunk " << c.file;
        }
    }
}

TEST(TilesCli, GlbChunksPassTheKhronosValidatorAndTheTilesetNestsTheLevels) {
    TempDir dir;
    const auto spec = dir.write("t.orogen",
                                spec_head +
                                    "export:tiles(w, path=\"g/tileset.json\", tile_size=33, "
                                    "format=glb, texture=64)\n");
    const RunResult r = run_orogen("run " + q(spec) + " --out " + q(dir / "one") + " --threads 1");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    ASSERT_EQ(run_orogen("run " + q(spec) + " --out " + q(dir / "two") + " --threads 2").exit_code, 0);
    // 129² in chunks of 33: 4 × 4, 2 × 2, 1.
    int files = 0;
    for (const auto& e : fs::directory_iterator(dir / "one/g")) {
        ++files;
        EXPECT_EQ(slurp(e.path()), slurp(dir / "two/g" / e.path().filename())) << e.path().filename();
    }
    EXPECT_EQ(files, 16 + 4 + 1 + 1);
    const std::string tileset = slurp(dir / "one/g/tileset.json");
    EXPECT_NE(tileset.find("\"version\": \"1.1\""), std::string::npos);
    EXPECT_NE(tileset.find("tileset_l2_x0_y0.glb"), std::string::npos);
    EXPECT_NE(tileset.find("tileset_l0_x3_y3.glb"), std::string::npos);
    // Errors shrink towards the leaves: the root's is the first after "root", and every level-0 chunk's is 0.
    const auto root = tileset.find("\"geometricError\": ", tileset.find("\"root\""));
    EXPECT_GT(std::stod(tileset.substr(root + 18)), 0.0);
    std::size_t zeros = 0;
    for (auto at = tileset.find("\"geometricError\": 0,"); at != std::string::npos;
         at = tileset.find("\"geometricError\": 0,", at + 1))
        ++zeros;
    EXPECT_EQ(zeros, 16u);
    const fs::path tool = fs::path(OROGEN_SOURCE_DIR) / "tools" / "gltf-validate";
    if (std::system("node --version >/dev/null 2>&1") != 0 ||
        !fs::exists(fs::path(OROGEN_SOURCE_DIR) / "tools/node_modules/gltf-validator"))
        GTEST_SKIP() << "SKIPPED glTF validation: node or the gltf-validator npm package is missing (npm install "
                        "--prefix tools)";
    for (const char* f :
         {"tileset_l0_x0_y0.glb", "tileset_l0_x3_y2.glb", "tileset_l1_x1_y0.glb", "tileset_l2_x0_y0.glb"}) {
        const fs::path report = dir / (std::string(f) + ".report");
        const int status =
            std::system(("node " + q(tool) + " " + q(dir / "one/g" / f) + " >" + q(report) + " 2>&1").c_str());
        const std::string text = slurp(report);
        EXPECT_EQ(WIFEXITED(status) ? WEXITSTATUS(status) : -1, 0) << f << "\n" << text;
        EXPECT_NE(text.find("errors 0 warnings 0 infos 0"), std::string::npos) << f << "\n" << text;
    }
}

TEST(TilesCli, RasterParametersWithGlbAreCheckErrors) {
    TempDir dir;
    for (const std::string& line : {std::string("export:tiles(w, path=\"t.json\", format=glb, low=0, high=9)"),
                                    std::string("export:tiles(w, path=\"t.json\", format=glb, vrt=true)"),
                                    std::string("export:tiles(w, path=\"t.json\", skirts=false)"),
                                    std::string("export:tiles(w, path=\"t.json\", format=glb, scale=0)")}) {
        const auto spec = dir.write("bad.orogen", spec_head + line + "\n");
        const RunResult r = run_orogen("check " + q(spec));
        EXPECT_EQ(r.exit_code, 2) << line << "\n" << r.err;
        EXPECT_NE(r.err.find("bad.orogen:7:"), std::string::npos) << line << "\n" << r.err;
    }
}
