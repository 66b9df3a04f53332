// export:exr and import:exr — files read back by OpenEXR's own tools (exrheader, exrmaketiled) and by a
// small independent parser of the uncompressed layout below; round trips that keep every bit (negative,
// denormal, huge, -0); determinism; and the hostile files: cut, forged sizes, overlapping chunks, wrong
// channel types, lossy compression, NaN, not an EXR — each refused with its message, before allocating.
#include <orogen/exr/exr.hpp>
#include "orogen_test.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>

#include <ImfChannelList.h>
#include <ImfDoubleAttribute.h>
#include <ImfStringAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <half.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define OROGEN_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define OROGEN_SANITIZED 1
#endif
#endif
#ifndef OROGEN_SANITIZED
#define OROGEN_SANITIZED 0
#endif

using namespace orogen;
using namespace orogen::test;
namespace fs = std::filesystem;

namespace {

/// Heights and two layers that hold every kind of float a round trip could lose: negative, -0, the
/// smallest denormal and others, the largest finite, tiny and huge of both signs.
Heightmap special_terrain(int w, int h) {
    Heightmap t(w, h, 12.5);
    GridView water = t.layer("water"), eroded = t.layer("eroded");
    const float specials[] = {-0.0f,
                              std::numeric_limits<float>::denorm_min(),
                              -std::numeric_limits<float>::denorm_min(),
                              1e-40f,
                              -3e-39f,
                              std::numeric_limits<float>::min(),
                              std::numeric_limits<float>::max(),
                              -std::numeric_limits<float>::max(),
                              -8848.86f,
                              1e30f,
                              -1e-30f,
                              0.1f};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = std::size_t(y) * w + x;
            t.heights()[i] = float(-500.0 + 3.0 * x - 2.0 * y + 10.0 * std::sin(0.3 * x * y));
            water.data[i] = specials[i % std::size(specials)];
            eroded.data[i] = std::bit_cast<float>(std::uint32_t(0x00000001u + 7919u * std::uint32_t(i)) & 0x807fffffu);
        }
    t.heights()[0] = std::numeric_limits<float>::denorm_min();
    t.heights()[1] = -0.0f;
    t.heights()[2] = std::numeric_limits<float>::max();
    return t;
}

bool same_bits(const float* a, const float* b, std::size_t n) { return std::memcmp(a, b, n * sizeof(float)) == 0; }

void write_terrain(const Heightmap& t, const fs::path& p, exr::Compression c = exr::Compression::zip, int threads = 1) {
    std::vector<exr::Plane> planes{{"Y", t.heights().data()}};
    for (const auto& name : t.layer_names()) planes.push_back({name, t.layer(name).data});
    exr::WriteOptions o;
    o.compression = c;
    o.cell = t.cell();
    o.threads = threads;
    exr::write(p, t.width(), t.height(), planes, o);
}

std::vector<std::uint8_t> bytes_of(const fs::path& p) { return read_file(p); }
void put(const fs::path& p, const std::vector<std::uint8_t>& b) {
    std::ofstream(p, std::ios::binary).write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size()));
}

// --------------------------------------------- an independent reader of the file layout (OpenEXR spec)

std::int32_t i32(const std::vector<std::uint8_t>& b, std::size_t at) {
    return std::int32_t(std::uint32_t(b.at(at)) | std::uint32_t(b.at(at + 1)) << 8 | std::uint32_t(b.at(at + 2)) << 16 |
                        std::uint32_t(b.at(at + 3)) << 24);
}
std::uint64_t u64(const std::vector<std::uint8_t>& b, std::size_t at) {
    return std::uint64_t(std::uint32_t(i32(b, at))) | std::uint64_t(std::uint32_t(i32(b, at + 4))) << 32;
}
std::string cstr(const std::vector<std::uint8_t>& b, std::size_t& at) {
    std::string s;
    while (b.at(at) != 0) s += char(b[at++]);
    ++at;
    return s;
}

struct Attribute {
    std::string type;
    std::size_t at = 0;  ///< where its value starts
    std::int32_t size = 0;
};
struct Parsed {
    std::map<std::string, Attribute> attributes;
    std::vector<std::pair<std::string, std::int32_t>> channels;  ///< name, pixel type (0 uint, 1 half, 2 float)
    std::size_t header_end = 0;  ///< the offset table starts here
};

Parsed parse_header(const std::vector<std::uint8_t>& b) {
    Parsed p;
    EXPECT_EQ(i32(b, 0), 20000630);  // the magic number
    EXPECT_EQ(i32(b, 4) & 0xff, 2);  // version 2
    EXPECT_EQ(i32(b, 4) & 0x1e00, 0) << "single-part scanline, not deep";
    std::size_t at = 8;
    while (b.at(at) != 0) {
        const std::string name = cstr(b, at);
        Attribute a;
        a.type = cstr(b, at);
        a.size = i32(b, at);
        a.at = at + 4;
        at = a.at + std::size_t(a.size);
        p.attributes[name] = a;
    }
    p.header_end = at + 1;
    const Attribute& ch = p.attributes.at("channels");
    std::size_t c = ch.at;
    while (b.at(c) != 0) {
        const std::string name = cstr(b, c);
        p.channels.emplace_back(name, i32(b, c));
        EXPECT_EQ(i32(b, c + 8), 1);  // x sampling
        EXPECT_EQ(i32(b, c + 12), 1);  // y sampling
        c += 16;
    }
    return p;
}

/// The samples of an uncompressed scanline file: one row a chunk, y then byte count then each channel's
/// row in the channel list's order.
std::map<std::string, std::vector<float>> read_uncompressed(const std::vector<std::uint8_t>& b, int& w, int& h) {
    const Parsed p = parse_header(b);
    EXPECT_EQ(b.at(p.attributes.at("compression").at), 0);  // NO_COMPRESSION
    const std::size_t win = p.attributes.at("dataWindow").at;
    w = i32(b, win + 8) - i32(b, win) + 1;
    h = i32(b, win + 12) - i32(b, win + 4) + 1;
    std::map<std::string, std::vector<float>> out;
    for (const auto& [name, type] : p.channels) {
        EXPECT_EQ(type, 2) << name << " is not FLOAT";
        out[name].resize(std::size_t(w) * h);
    }
    for (int y = 0; y < h; ++y) {
        std::size_t at = std::size_t(u64(b, p.header_end + 8 * std::size_t(y)));
        EXPECT_EQ(i32(b, at), y);
        EXPECT_EQ(i32(b, at + 4), w * 4 * int(p.channels.size()));
        at += 8;
        for (const auto& [name, type] : p.channels) {
            std::memcpy(out[name].data() + std::size_t(y) * w, b.data() + at, std::size_t(w) * 4);
            at += std::size_t(w) * 4;
        }
    }
    return out;
}

/// Overwrite a box2i attribute (dataWindow, displayWindow) in place.
void patch_box(std::vector<std::uint8_t>& b, const std::string& name, int x0, int y0, int x1, int y1) {
    const std::size_t at = parse_header(b).attributes.at(name).at;
    const int v[4] = {x0, y0, x1, y1};
    std::memcpy(b.data() + at, v, sizeof v);
}

/// A file written by OpenEXR's C++ API directly (not export:exr): `type` channels Y and G, `compression`.
void write_with_imf(const fs::path& p, Imf::PixelType type, Imf::Compression compression, int w, int h,
                    const std::vector<float>& values) {
    Imf::Header header(w, h);
    header.compression() = compression;
    header.channels().insert("Y", Imf::Channel(type));
    header.channels().insert("G", Imf::Channel(type));
    std::vector<half> halves(values.begin(), values.end());
    std::vector<std::uint32_t> uints(values.size());
    for (std::size_t i = 0; i < values.size(); ++i) uints[i] = std::uint32_t(std::abs(values[i]));
    char* base = type == Imf::HALF ? reinterpret_cast<char*>(halves.data())
        : type == Imf::UINT        ? reinterpret_cast<char*>(uints.data())
                                   : reinterpret_cast<char*>(const_cast<float*>(values.data()));
    const std::size_t bytes = type == Imf::HALF ? 2 : 4;
    Imf::FrameBuffer fb;
    fb.insert("Y", Imf::Slice(type, base, bytes, bytes * w));
    fb.insert("G", Imf::Slice(type, base, bytes, bytes * w));
    Imf::OutputFile out(p.c_str(), header);
    out.setFrameBuffer(fb);
    out.writePixels(h);
}

/// A FLOAT channel Y over the data window (x0, y0)-(x0 + w - 1, y0 + h - 1), with a cellSize and heightUnits.
void write_windowed(const fs::path& p, int x0, int y0, int w, int h, const std::vector<float>& values,
                    const std::string& units) {
    const Imath::Box2i window(Imath::V2i(x0, y0), Imath::V2i(x0 + w - 1, y0 + h - 1));
    Imf::Header header(window, window);
    header.channels().insert("Y", Imf::Channel(Imf::FLOAT));
    header.insert("cellSize", Imf::DoubleAttribute(2.5));
    header.insert("heightUnits", Imf::StringAttribute(units));
    Imf::FrameBuffer fb;
    // OpenEXR addresses a slice by absolute pixel coordinates: the base is moved back to (0, 0).
    char* base = reinterpret_cast<char*>(const_cast<float*>(values.data())) -
        (std::ptrdiff_t(y0) * w + x0) * std::ptrdiff_t(sizeof(float));
    fb.insert("Y", Imf::Slice(Imf::FLOAT, base, sizeof(float), sizeof(float) * std::size_t(w)));
    Imf::OutputFile out(p.c_str(), header);
    out.setFrameBuffer(fb);
    out.writePixels(h);
}

std::vector<std::string> entries(const fs::path& dir) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

std::string refusal(const fs::path& p, const exr::ReadOptions& o = {}) {
    try {
        exr::read(p, o);
    } catch (const BadInput& e) { return e.what(); }
    return "(read without an error)";
}

}  // namespace

TEST(Exr, ExrheaderReadsTheChannelsAndTheHeaderAttributes) {
    TempDir dir;
    const Heightmap t = special_terrain(37, 23);
    write_terrain(t, dir / "t.exr");
    dir.write("h.sh", "exrheader t.exr > header.txt\n");
    ASSERT_EQ(std::system(("cd '" + dir.path().string() + "' && sh h.sh").c_str()), 0);
    const std::string header = slurp(dir / "header.txt");
    for (const char* line :
         {"cellSize (type double): 12.5", "heightUnits (type string): \"m\"",
          "    Y, 32-bit floating-point, sampling 1 1", "    eroded, 32-bit floating-point, sampling 1 1",
          "    water, 32-bit floating-point, sampling 1 1", "dataWindow (type box2i): (0 0) - (36 22)",
          "compression (type compression): zip", "lineOrder (type lineOrder): increasing y"})
        EXPECT_NE(header.find(line), std::string::npos) << line << "\nin:\n" << header;
}

TEST(Exr, AnIndependentParserReadsTheSamplesBitForBit) {
    TempDir dir;
    const Heightmap t = special_terrain(29, 17);
    write_terrain(t, dir / "t.exr", exr::Compression::none);
    int w = 0, h = 0;
    const auto channels = read_uncompressed(bytes_of(dir / "t.exr"), w, h);
    ASSERT_EQ(w, 29);
    ASSERT_EQ(h, 17);
    ASSERT_EQ(channels.size(), 3u);
    EXPECT_TRUE(same_bits(channels.at("Y").data(), t.heights().data(), t.size()));  // row 0 is the north edge
    EXPECT_TRUE(same_bits(channels.at("water").data(), t.layer("water").data, t.size()));
    EXPECT_TRUE(same_bits(channels.at("eroded").data(), t.layer("eroded").data, t.size()));
    const Parsed p = parse_header(bytes_of(dir / "t.exr"));
    const auto b = bytes_of(dir / "t.exr");
    ASSERT_EQ(p.attributes.at("cellSize").type, "double");
    double cell = 0;
    std::memcpy(&cell, b.data() + p.attributes.at("cellSize").at, 8);
    EXPECT_EQ(cell, 12.5);
}

TEST(Exr, EveryCompressionRoundTripsEveryBitOfHeightsAndLayers) {
    TempDir dir;
    const Heightmap t = special_terrain(67, 45);  // zip's 16-row and piz's 32-row blocks end part-filled
    for (auto c : {exr::Compression::none, exr::Compression::rle, exr::Compression::zips, exr::Compression::zip,
                   exr::Compression::piz}) {
        SCOPED_TRACE(int(c));
        write_terrain(t, dir / "t.exr", c);
        exr::ReadOptions o;
        o.all_layers = true;
        const auto back = exr::read(dir / "t.exr", o);
        ASSERT_EQ(back->width(), 67);
        ASSERT_EQ(back->height(), 45);
        EXPECT_EQ(back->cell(), 12.5);
        EXPECT_EQ(back->layer_names(), t.layer_names());
        EXPECT_TRUE(same_bits(back->heights().data(), t.heights().data(), t.size()));
        EXPECT_TRUE(same_bits(back->layer("water").data, t.layer("water").data, t.size()));
        EXPECT_TRUE(same_bits(back->layer("eroded").data, t.layer("eroded").data, t.size()));
    }
}

TEST(Exr, TheBytesAreTheSameEveryTime) {
    TempDir dir;
    const Heightmap t = special_terrain(101, 77);
    write_terrain(t, dir / "a.exr");
    write_terrain(t, dir / "b.exr");
    EXPECT_EQ(slurp(dir / "a.exr"), slurp(dir / "b.exr"));
    write_terrain(t, dir / "a.exr", exr::Compression::piz);
    write_terrain(t, dir / "b.exr", exr::Compression::piz);
    EXPECT_EQ(slurp(dir / "a.exr"), slurp(dir / "b.exr"));
    // On OpenEXR's thread pool: the same bytes as on one thread, for 2 and 4 threads.
    for (auto c : {exr::Compression::zip, exr::Compression::piz, exr::Compression::zips}) {
        write_terrain(t, dir / "one.exr", c, 1);
        for (int threads : {2, 4}) {
            write_terrain(t, dir / "many.exr", c, threads);
            EXPECT_EQ(slurp(dir / "one.exr"), slurp(dir / "many.exr")) << int(c) << " on " << threads << " threads";
        }
    }
}

TEST(ExrImport, BigImagesDecodeInParallelBitForBitAndNameTheFirstDamagedChunk) {
    TempDir dir;
    const Heightmap t = special_terrain(1100, 1000);  // 1.1 M samples, 63 zip chunks: decoded on the pool
    for (auto c : {exr::Compression::zip, exr::Compression::piz}) {
        write_terrain(t, dir / "t.exr", c);
        exr::ReadOptions o;
        o.all_layers = true;
        const auto back = exr::read(dir / "t.exr", o);
        EXPECT_TRUE(same_bits(back->heights().data(), t.heights().data(), t.size()));
        EXPECT_TRUE(same_bits(back->layer("water").data, t.layer("water").data, t.size()));
        EXPECT_TRUE(same_bits(back->layer("eroded").data, t.layer("eroded").data, t.size()));
    }
    // Two zip chunks made undecodable (their deflate streams zeroed): the lower one is named, every time.
    write_terrain(t, dir / "t.exr", exr::Compression::zip);
    auto bytes = bytes_of(dir / "t.exr");
    const std::size_t table = parse_header(bytes).header_end;
    for (std::size_t chunk : {40u, 10u}) {
        const std::size_t at = std::size_t(u64(bytes, table + 8 * chunk));
        const std::size_t size = std::size_t(i32(bytes, at + 4));
        std::fill(bytes.begin() + std::ptrdiff_t(at + 8), bytes.begin() + std::ptrdiff_t(at + 8 + size), 0);
    }
    put(dir / "damaged.exr", bytes);
    exr::ReadOptions o;
    o.all_layers = true;
    EXPECT_NO_THROW(exr::probe(dir / "damaged.exr", o));  // the layout is whole; the contents are not
    for (int i = 0; i < 5; ++i)
        EXPECT_NE(refusal(dir / "damaged.exr", o).find("it is damaged: the chunk at row 160, column 0 does not decode"),
                  std::string::npos)
            << refusal(dir / "damaged.exr", o);
}

TEST(ExrImport, TiledMipmappedAndHalfFilesFromOpenExrsToolsReadExactly) {
    TempDir dir;
    const Heightmap t = special_terrain(70, 50);
    write_terrain(t, dir / "t.exr");
    // OpenEXR's own exrmaketiled re-tiles it (odd tiles at the edges), one level and mipmapped.
    dir.write("tile.sh", "exrmaketiled -t 16 16 -z piz t.exr tiled.exr && exrmaketiled -m -t 32 24 t.exr mip.exr\n");
    ASSERT_EQ(std::system(("cd '" + dir.path().string() + "' && sh tile.sh").c_str()), 0);
    for (const char* name : {"tiled.exr", "mip.exr"}) {
        exr::ReadOptions o;
        o.layers = {"water", "eroded"};
        o.cell = 3.0;
        const auto back = exr::read(dir / name, o);
        EXPECT_TRUE(exr::probe(dir / name, o).tiled);
        ASSERT_EQ(back->width(), 70);
        EXPECT_EQ(back->cell(), 3.0);
        EXPECT_TRUE(same_bits(back->heights().data(), t.heights().data(), t.size())) << name;
        EXPECT_TRUE(same_bits(back->layer("water").data, t.layer("water").data, t.size())) << name;
    }
    // Half channels widen exactly (every half is a float).
    std::vector<float> v(40 * 30);
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = float(half(float(i) * 0.37f - 200.0f));
    v[5] = std::bit_cast<float>(std::uint32_t(0x33800000));  // 2^-24, the smallest half denormal
    v[6] = -65504.0f;  // the largest half
    write_with_imf(dir / "half.exr", Imf::HALF, Imf::ZIP_COMPRESSION, 40, 30, v);
    exr::ReadOptions o;
    o.cell = 1.0;
    const auto back = exr::read(dir / "half.exr", o);
    EXPECT_TRUE(same_bits(back->heights().data(), v.data(), v.size()));
}

TEST(ExrImport, ADataWindowAwayFromTheOriginIsReadAsIs) {
    TempDir dir;
    std::vector<float> v(23 * 17);
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = float(i) * 0.25f - 40.0f;
    write_windowed(dir / "w.exr", -10, 7, 23, 17, v, "m");
    const auto back = exr::read(dir / "w.exr", {});
    ASSERT_EQ(back->width(), 23);
    ASSERT_EQ(back->height(), 17);
    EXPECT_EQ(back->cell(), 2.5);
    EXPECT_TRUE(same_bits(back->heights().data(), v.data(), v.size()));  // the window's first row is row 0
}

TEST(ExrImport, WrongChannelsAndLossyOrNonFiniteDataAreRefusedByName) {
    TempDir dir;
    std::vector<float> v(16 * 8, 1.0f);
    write_with_imf(dir / "uint.exr", Imf::UINT, Imf::ZIP_COMPRESSION, 16, 8, v);
    write_with_imf(dir / "b44.exr", Imf::HALF, Imf::B44_COMPRESSION, 16, 8, v);
    write_with_imf(dir / "float.exr", Imf::FLOAT, Imf::PIZ_COMPRESSION, 16, 8, v);
    exr::ReadOptions o;
    o.cell = 1.0;
    EXPECT_NE(refusal(dir / "uint.exr", o)
                  .find("channel 'Y' holds 32-bit unsigned integers; import:exr reads 32-bit "
                        "or 16-bit float channels"),
              std::string::npos)
        << refusal(dir / "uint.exr", o);
    EXPECT_NE(refusal(dir / "b44.exr", o).find("it is compressed with b44, which import:exr does not read"),
              std::string::npos)
        << refusal(dir / "b44.exr", o);
    try {
        exr::ReadOptions missing = o;
        missing.channel = "height";
        exr::probe(dir / "float.exr", missing);
        FAIL() << "a missing channel was not refused";
    } catch (const exr::ChannelError& e) {
        EXPECT_EQ(e.param, "channel");
        EXPECT_NE(std::string(e.what()).find("it has no channel 'height' (its channels are: G, Y); give channel=NAME"),
                  std::string::npos)
            << e.what();
    }
    // No cell size anywhere.
    EXPECT_NE(refusal(dir / "float.exr").find("has no cellSize attribute to take a cell size from; give cell=METRES"),
              std::string::npos);
    // NaN in a layer, named with its place.
    Heightmap t = special_terrain(9, 7);
    t.layer("water").data[2 * 9 + 4] = std::numeric_limits<float>::quiet_NaN();
    write_terrain(t, dir / "nan.exr");
    exr::ReadOptions all;
    all.all_layers = true;
    EXPECT_NE(refusal(dir / "nan.exr", all)
                  .find("sample (4, 2) of channel 'water' is NaN; heights and layers must be "
                        "finite numbers"),
              std::string::npos)
        << refusal(dir / "nan.exr", all);
    // Not an EXR at all.
    dir.write("text.exr", "this is text, not an image");
    EXPECT_NE(refusal(dir / "text.exr").find("it is not an OpenEXR file (it does not begin with the EXR magic number"),
              std::string::npos);
    EXPECT_NE(refusal(dir / "absent.exr").find("absent.exr"), std::string::npos);
}

TEST(ExrImport, EveryCutOfAFileIsRefusedAsBadInput) {
    TempDir dir;
    for (auto c : {exr::Compression::zip, exr::Compression::none, exr::Compression::piz}) {
        write_terrain(special_terrain(33, 40), dir / "t.exr", c);
        const auto whole = bytes_of(dir / "t.exr");
        exr::ReadOptions o;
        o.all_layers = true;
        std::size_t refused = 0;
        for (std::size_t n = 0; n < whole.size(); n += std::max<std::size_t>(1, whole.size() / 97)) {
            try {
                exr::read_bytes(std::span(whole.data(), n), "cut.exr", o);
                ADD_FAILURE() << "a file cut to " << n << " of " << whole.size() << " bytes was read";
            } catch (const BadInput& e) {
                ++refused;
                EXPECT_EQ(std::string(e.what()).rfind("cannot read cut.exr: ", 0), 0u) << e.what();
            }
        }
        EXPECT_GE(refused, 97u);
        EXPECT_NO_THROW(exr::read_bytes(whole, "whole.exr", o));
    }
}

TEST(ExrImport, ForgedSizesAndOverlappingChunksAreRefusedBeforeAllocating) {
    TempDir dir;
    write_terrain(special_terrain(65, 65), dir / "t.exr");
    const auto good = bytes_of(dir / "t.exr");
    exr::ReadOptions o;
    o.all_layers = true;

    // Beyond the memory budget.
    auto huge = good;
    patch_box(huge, "dataWindow", 0, 0, 999999, 999999);
    put(dir / "huge.exr", huge);
    EXPECT_NE(refusal(dir / "huge.exr", o)
                  .find("its data window is 1000000x1000000 samples, which needs 3.6 TiB for "
                        "one heightmap"),
              std::string::npos)
        << refusal(dir / "huge.exr", o);

    // Within the budget, but far more rows than the file holds: the offset table alone would not fit.
    auto big = good;
    patch_box(big, "dataWindow", 0, 0, 0, 999999);
    put(dir / "big.exr", big);
    EXPECT_NE(refusal(dir / "big.exr", o).find("it is truncated: its 62500 chunks' offset table alone needs 488.3 KiB"),
              std::string::npos)
        << refusal(dir / "big.exr", o);

    // Wide rows: the table and the chunks fit (zip could hold 30000-sample rows in them, so the 23 MB are
    // allocated), but the first chunk does not decompress to them.
    auto wide = good;
    patch_box(wide, "dataWindow", 0, 0, 29999, 64);
    put(dir / "wide.exr", wide);
    EXPECT_NO_THROW(exr::probe(dir / "wide.exr", o));
    EXPECT_NE(refusal(dir / "wide.exr", o).find("it is damaged: the chunk at row 0, column 0 does not decode"),
              std::string::npos)
        << refusal(dir / "wide.exr", o);

    // Two offsets pointing at the same chunk (OpenEXR finds the second chunk's leader names the wrong row).
    auto twice = good;
    const std::size_t table = parse_header(good).header_end;
    std::memcpy(twice.data() + table + 8, twice.data() + table, 8);
    put(dir / "twice.exr", twice);
    const std::string why = refusal(dir / "twice.exr", o);
    EXPECT_TRUE(why.find("share the same bytes") != std::string::npos ||
                why.find("truncated or damaged") != std::string::npos)
        << why;
}

// Through the binary, in an address space of 1 GiB: a forged 30000 × 2000 × 6-channel file (1.3 GiB if
// allocated) fails at check time with exit 2 and the file's fault, not an allocation failure.
TEST(ExrCli, AForgedHugeFileFailsInAOneGibAddressSpace) {
#if OROGEN_SANITIZED
    GTEST_SKIP() << "SKIPPED: an address-space limit cannot hold a sanitizer's shadow memory";
#endif
    TempDir dir;
    write_terrain(special_terrain(65, 65), dir / "t.exr");
    auto tall = bytes_of(dir / "t.exr");
    patch_box(tall, "dataWindow", 0, 0, 29999, 1999);
    put(dir / "tall.exr", tall);
    dir.write("s.orogen",
              "orogen 1\ngrid 9\nd = import:exr(path=\"tall.exr\", layers=all)\nexport:raw(d, path=\"d.r32\")\n");
    for (const char* command : {"check s.orogen", "run s.orogen --out out"}) {
        const RunResult r = run_orogen(command, "prlimit --as=1073741824", dir.path());
        EXPECT_EQ(r.exit_code, 2) << command << "\n" << r.err;
        EXPECT_NE(r.err.find("s.orogen:3:21: error: import:exr: cannot read tall.exr: it"), std::string::npos) << r.err;
    }
    EXPECT_FALSE(fs::exists(dir / "out/d.r32"));
}

TEST(ExrCli, ExportThenImportThroughTheBinaryKeepsEveryBit) {
    TempDir dir;
    dir.write("out.orogen",
              "orogen 1\nseed 5\ngrid 65 cell=20\nb = generate:fault(iterations=40, displacement=8)\n"
              "w = erode:hydraulic(b, iterations=5)\n"
              "export:exr(w, path=\"t.exr\", layers=all)\n"
              "export:exr(w, path=\"s.exr\", layers=\"water, eroded\", split=true, channel=height, "
              "compression=piz)\n"
              "export:raw(w, path=\"w.r32\")\n");
    RunResult r = run_orogen("run out.orogen --out out --quiet", "", dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(entries(dir / "out"),
              (std::vector<std::string>{"manifest.json", "s.eroded.exr", "s.exr", "s.water.exr", "t.exr", "w.r32",
                                        "w.r32.json"}));
    // Again, on one thread: the same bytes.
    r = run_orogen("run out.orogen --out again --quiet --threads 1", "", dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    for (const char* f : {"t.exr", "s.exr", "s.water.exr"})
        EXPECT_EQ(slurp(dir / "out" / f), slurp(dir / "again" / f)) << f;
    dir.write("in.orogen",
              "orogen 1\ngrid 9\nd = import:exr(path=\"out/t.exr\", layers=all)\n"
              "export:raw(d, path=\"d.r32\")\nexport:exr(d, path=\"t.exr\", layers=all)\n"
              "s = import:exr(path=\"out/s.water.exr\", channel=height)\nexport:raw(s, path=\"s.r32\")\n");
    r = run_orogen("run in.orogen --out back --quiet", "", dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(slurp(dir / "back/d.r32"), slurp(dir / "out/w.r32"));
    EXPECT_EQ(slurp(dir / "back/t.exr"), slurp(dir / "out/t.exr"));  // heights and every layer, bit for bit
    EXPECT_NE(slurp(dir / "back/d.r32.json").find("\"cell_size\": 20,"), std::string::npos);
    EXPECT_NE(slurp(dir / "back/s.r32.json").find("\"cell_size\": 20,"), std::string::npos);
    dir.write("h.sh", "exrheader out/s.water.exr > header.txt\n");
    ASSERT_EQ(std::system(("cd '" + dir.path().string() + "' && sh h.sh").c_str()), 0);
    EXPECT_NE(slurp(dir / "header.txt").find("orogenLayer (type string): \"water\""), std::string::npos);
}

TEST(ExrCli, BadParametersAndFilesFailAtCheckTimeNamingTheParameter) {
    TempDir dir;
    write_terrain(special_terrain(9, 9), dir / "t.exr");
    dir.write("text.exr", "not an image");
    write_windowed(dir / "feet.exr", 0, 0, 4, 4, std::vector<float>(16, 1.0f), "ft");
    dir.write("s.orogen",
              "orogen 1\ngrid 33\nb = generate:fault()\n"
              "export:exr(b, path=\"a.exr\", layers=\"snow\")\n"
              "export:exr(b, path=\"b.exr\", channel=\"\")\n"
              "export:exr(b, path=\"c.tif\")\n"
              "d = import:exr(path=\"text.exr\")\n"
              "e = import:exr(path=\"t.exr\", channel=Z)\n"
              "f = import:exr(path=\"t.exr\", layers=\"water, snow\")\n"
              "g = import:exr(path=\"feet.exr\")\n");
    const RunResult r = run_orogen("check s.orogen", "", dir.path());
    EXPECT_EQ(r.exit_code, 2);
    for (const char* m :
         {"s.orogen:4:36: error: export:exr: no layer 'snow' on the input",
          "s.orogen:5:37: error: export:exr: a channel name cannot be empty",
          "s.orogen:6:20: error: export:exr writes .exr files; 'c.tif' has another extension",
          "s.orogen:7:21: error: import:exr: cannot read text.exr: it is not an "
          "OpenEXR file",
          "s.orogen:8:38: error: import:exr: cannot read t.exr: it has no channel 'Z' (its channels are: Y, eroded, "
          "water); give channel=NAME",
          "s.orogen:9:37: error: import:exr: cannot read t.exr: it has no channel 'snow'",
          "s.orogen:10:21: error: import:exr: the file says its heights are in 'ft' (its heightUnits attribute); "
          "import:exr reads metres: convert the file first"})
        EXPECT_NE(r.err.find(m), std::string::npos) << m << "\nin:\n" << r.err;
}
