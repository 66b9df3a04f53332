// export:raw — .r16 / .r32 round trips, the sidecar, and failing writes.
#include <orogen/formats/raw.hpp>

#include "export_test_support.hpp"
#include "orogen_test.hpp"

#include <orogen/error.hpp>

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <functional>

using namespace orogen;
namespace fs = std::filesystem;

namespace {

template <typename T>
std::vector<T> read_le(const fs::path& p) {
    const std::string bytes = test::file_text(p);
    std::vector<T> v(bytes.size() / sizeof(T));
    std::memcpy(v.data(), bytes.data(), v.size() * sizeof(T));  // this machine is little-endian (checked below)
    return v;
}

}  // namespace

TEST(Raw, R16RoundTripsWithinHalfAQuantisationStep) {
    static_assert(std::endian::native == std::endian::little);
    test::TempDir dir;
    const int w = 129, h = 97;
    auto heights = test::hills(w, h, 2500.0);
    const ConstGridView g(heights.data(), w, h, 30.0);
    const auto written = formats::raw::write_raw(g, dir / "t.r16");
    ASSERT_EQ(fs::file_size(dir / "t.r16"), std::size_t(w * h * 2));
    const auto q = read_le<std::uint16_t>(dir / "t.r16");
    const auto [lo, hi] = std::minmax_element(heights.begin(), heights.end());
    EXPECT_EQ(written.range.low, double(*lo));
    EXPECT_EQ(written.range.high, double(*hi));
    const double step = (double(*hi) - double(*lo)) / 65535.0;
    for (std::size_t i = 0; i < heights.size(); ++i)
        ASSERT_NEAR(formats::raw::dequantize16(q[i], written.range), heights[i], 0.5 * step + 1e-9) << "sample " << i;
    // The extremes use the full 16-bit range (the thesis's exporter wrapped its top to black).
    EXPECT_EQ(*std::min_element(q.begin(), q.end()), 0);
    EXPECT_EQ(*std::max_element(q.begin(), q.end()), 65535);
    // Little-endian on disk: the first byte is the low byte.
    const std::string bytes = test::file_text(dir / "t.r16");
    EXPECT_EQ(std::uint8_t(bytes[0]), std::uint8_t(q[0] & 0xff));
}

TEST(Raw, R32HoldsTheExactMetres) {
    test::TempDir dir;
    auto heights = test::hills(65, 33);
    formats::raw::write_raw(ConstGridView(heights.data(), 65, 33, 2.0), dir / "t.r32");
    EXPECT_EQ(read_le<float>(dir / "t.r32"), heights);
}

TEST(Raw, SidecarDescribesTheFile) {
    test::TempDir dir;
    auto heights = test::hills(17, 9);
    formats::raw::write_raw(ConstGridView(heights.data(), 17, 9, 12.5), dir / "t.r16", formats::raw::Range{-100, 3000});
    EXPECT_EQ(test::folder_entries(dir.path()), (std::vector<std::string>{"t.r16", "t.r16.json"}));
    EXPECT_EQ(test::file_text(dir / "t.r16.json"),
              "{\n"
              "  \"format\": \"r16\",\n"
              "  \"sample_type\": \"uint16\",\n"
              "  \"byte_order\": \"little-endian\",\n"
              "  \"width\": 17,\n"
              "  \"height\": 9,\n"
              "  \"cell_size\": 12.5,\n"
              "  \"height_min\": -100,\n"
              "  \"height_max\": 3000,\n"
              "  \"units\": \"m\",\n"
              "  \"layout\": \"rows north to south, samples west to east, no header\",\n"
              "  \"height_of_sample\": \"height_min + (height_max - height_min) * value / 65535\"\n"
              "}\n");
}

TEST(Raw, GivenRangeMapsItsEndsAndClampsOutside) {
    std::vector<float> h = {-200, -100, 0, 1450, 3000, 3500};
    std::size_t clamped = 0;
    const auto q = formats::raw::quantize16(ConstGridView(h.data(), 6, 1, 1.0), {-100, 3000}, &clamped);
    EXPECT_EQ(q, (std::vector<std::uint16_t>{0, 0, 2114, 32768, 65535, 65535}));
    EXPECT_EQ(clamped, 2u);
    std::vector<float> flat(4, 7.0f);
    EXPECT_EQ(formats::raw::quantize16(ConstGridView(flat.data(), 2, 2, 1.0),
                                       formats::raw::min_max(ConstGridView(flat.data(), 2, 2, 1.0))),
              (std::vector<std::uint16_t>(4, 0)));
}

TEST(Raw, BadExtensionAndRangeAreBadInput) {
    test::TempDir dir;
    auto heights = test::hills(9, 9);
    const ConstGridView g(heights.data(), 9, 9, 1.0);
    try {
        formats::raw::write_raw(g, dir / "t.raw");
        FAIL();
    } catch (const BadInput& e) {
        EXPECT_STREQ(e.what(), "export:raw writes .r16 or .r32 files; 't.raw' has another extension");
    }
    try {
        formats::raw::write_raw(g, dir / "t.r16", formats::raw::Range{10, 10});
        FAIL();
    } catch (const BadInput& e) { EXPECT_STREQ(e.what(), "the height range must have high > low, got low=10 high=10"); }
    EXPECT_TRUE(test::folder_entries(dir.path()).empty());
}

TEST(Raw, UnwritableFolderFailsWithoutLeavingAFile) {
    auto heights = test::hills(9, 9);
    EXPECT_THROW(formats::raw::write_raw(ConstGridView(heights.data(), 9, 9, 1.0), test::unwritable_folder() / "t.r16"),
                 Error);
    EXPECT_FALSE(fs::exists(test::unwritable_folder() / "t.r16"));
}

TEST(Raw, FullDiskKeepsTheGoodFilesAndLeavesNoTemporary) {
    test::TempDir dir;
    test::TinyDisk disk(dir / "tiny");
    OROGEN_SKIP_WITHOUT_TINY_DISK(disk);
    std::ofstream(disk.path() / "t.r32") << "good";
    std::ofstream(disk.path() / "t.r32.json") << "good json";
    auto heights = test::hills(257, 257);  // 264 KB: does not fit in 64 KiB
    EXPECT_THROW(formats::raw::write_raw(ConstGridView(heights.data(), 257, 257, 1.0), disk.path() / "t.r32"), Error);
    EXPECT_EQ(test::folder_entries(disk.path()), (std::vector<std::string>{"t.r32", "t.r32.json"}));
    EXPECT_EQ(test::file_text(disk.path() / "t.r32"), "good");
    EXPECT_EQ(test::file_text(disk.path() / "t.r32.json"), "good json");
}

// ------------------------------------------------------------------ reading back (import:raw)

namespace {
std::string bad_input_text(const std::function<void()>& f) {
    try {
        f();
    } catch (const BadInput& e) { return e.what(); }
    return "no error";
}
}  // namespace

TEST(RawRead, BothFormatsReadBackWhatWasWritten) {
    test::TempDir dir;
    const int w = 65, h = 40;
    auto heights = test::hills(w, h, 800.0);
    const ConstGridView g(heights.data(), w, h, 5.0);
    formats::raw::write_raw(g, dir / "t.r32");
    formats::raw::write_raw(g, dir / "t.r16");
    formats::raw::Sidecar s;
    EXPECT_EQ(formats::raw::read_raw(dir / "t.r32", s), heights);  // exact
    EXPECT_EQ(s.width, w);
    EXPECT_EQ(s.height, h);
    EXPECT_EQ(s.cell, 5.0);
    const auto q = formats::raw::read_raw(dir / "t.r16", s);
    const double step = (s.range.high - s.range.low) / 65535.0;
    ASSERT_EQ(q.size(), heights.size());
    for (std::size_t i = 0; i < q.size(); ++i) ASSERT_NEAR(q[i], heights[i], 0.5 * step + 1e-3) << i;
}

TEST(RawRead, AHugeDeclaredSizeACutFileAndABrokenSidecarAreRefusedBeforeReading) {
    test::TempDir dir;
    std::vector<float> heights(65 * 40, 1.0f);
    heights[7] = 9.0f;
    formats::raw::write_raw(ConstGridView(heights.data(), 65, 40, 5.0), dir / "t.r16");
    std::string sidecar = test::file_text(dir / "t.r16.json");
    auto with = [&](const std::string& from, const std::string& to) {
        std::string s = sidecar;
        s.replace(s.find(from), from.size(), to);
        std::ofstream(dir / "t.r16.json", std::ios::binary) << s;
    };
    const std::string file = (dir / "t.r16").string();
    {
        std::string s = sidecar;
        s.replace(s.find("\"width\": 65"), 11, "\"width\": 100000");
        s.replace(s.find("\"height\": 40"), 12, "\"height\": 100000");
        std::ofstream(dir / "t.r16.json", std::ios::binary) << s;
    }
    std::string m = bad_input_text([&] { formats::raw::read_raw_header(dir / "t.r16"); });
    EXPECT_EQ(m.substr(0, m.find(" more than")),
              "cannot read " + file +
                  ": its sidecar declares 100000x100000 samples, which needs 37.3 GiB for one "
                  "heightmap (4 bytes a vertex),");
    std::ofstream(dir / "t.r16.json", std::ios::binary) << sidecar;
    const std::string data = test::file_text(dir / "t.r16");
    std::ofstream(dir / "t.r16", std::ios::binary) << data.substr(0, 1000);
    EXPECT_EQ(bad_input_text([&] { formats::raw::read_raw_header(dir / "t.r16"); }),
              "cannot read " + file +
                  ": it holds 1000 bytes, but its sidecar's 65x40 16-bit samples need exactly "
                  "5200; it is truncated");
    std::ofstream(dir / "t.r16", std::ios::binary) << data;
    with("\"width\": 65", "\"width\": -1");
    EXPECT_EQ(bad_input_text([&] { formats::raw::read_raw_header(dir / "t.r16"); }),
              "cannot read " + file + ".json: \"width\" must be a whole number from 1 to 1000000, got -1");
    std::ofstream(dir / "t.r16.json", std::ios::binary) << sidecar.substr(0, 40);
    EXPECT_EQ(bad_input_text([&] { formats::raw::read_raw_header(dir / "t.r16"); }),
              "cannot read " + file + ".json: it is not valid JSON; export:raw writes it beside the RAW file");
    fs::remove(dir / "t.r16.json");
    EXPECT_EQ(bad_input_text([&] { formats::raw::read_raw_header(dir / "t.r16"); }),
              "cannot read " + file + ": its sidecar " + file +
                  ".json does not exist; a RAW file says nothing of its "
                  "size, so the sidecar export:raw writes must sit beside it");
    EXPECT_EQ(bad_input_text([&] {
                  formats::raw::parse_sidecar(
                      "{\"format\": \"r16\", \"width\": 3, \"height\": 3, "
                      "\"cell_size\": 1, \"height_min\": 5, \"height_max\": 1}",
                      "s.json");
              }),
              "cannot read s.json: \"height_max\" (1) is below \"height_min\" (5)");
}
