// The kernel's support code: random numbers, hashing, atomic files, PNG codec.
#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/node.hpp>
#include <orogen/parallel.hpp>
#include <orogen/random.hpp>
#include <orogen/values.hpp>

#include "io/digest.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>
#include <utility>

#include "orogen_test.hpp"

#include <cmath>
#include <set>

using namespace orogen;
using orogen::test::TempDir;

TEST(Random, IsAPureFunctionOfSeedAndCounters) {
    EXPECT_EQ(random::hash(1, 2, 3), random::hash(1, 2, 3));
    EXPECT_NE(random::hash(1, 2, 3), random::hash(1, 3, 2));  // counter order matters
    EXPECT_NE(random::hash(1, 2, 3), random::hash(2, 2, 3));
    EXPECT_NE(random::hash(0, 0), random::hash(0, 1));
}

TEST(Random, UniformIsInRangeAndRoughlyUniform) {
    int buckets[10] = {0};
    for (int i = 0; i < 100000; ++i) {
        const double u = random::uniform(42, i);
        ASSERT_GE(u, 0.0);
        ASSERT_LT(u, 1.0);
        ++buckets[int(u * 10)];
    }
    for (int b : buckets) EXPECT_NEAR(b, 10000, 400);  // ~4 sigma
    for (int i = 0; i < 1000; ++i) EXPECT_LT(random::below(7, 3, i), 7u);
}

TEST(Sha256, MatchesTheStandardTestVectors) {
    const std::string abc = "abc";
    EXPECT_EQ(sha256_hex({reinterpret_cast<const std::uint8_t*>(abc.data()), abc.size()}),
              "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
    EXPECT_EQ(sha256_hex({}), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
    const std::string two_blocks = "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq";
    EXPECT_EQ(sha256_hex({reinterpret_cast<const std::uint8_t*>(two_blocks.data()), two_blocks.size()}),
              "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
}

TEST(ParallelSum, IsTheSameForEveryThreadCount) {
    auto body = [](std::int64_t a, std::int64_t b) {
        double s = 0;
        for (std::int64_t i = a; i < b; ++i) s += 1.0 / double(i + 1);
        return s;
    };
    const double one = parallel_sum(0, 1000000, 4096, body);
    EXPECT_EQ(one, parallel_sum(0, 1000000, 4096, body));
    EXPECT_NEAR(one, std::log(1000000.0) + 0.5772156649, 1e-6);
}

TEST(AtomicFile, CommitReplacesTheTargetAtOnce) {
    TempDir dir;
    const auto target = dir / "a.bin";
    dir.write("a.bin", "old");
    {
        AtomicFile f(target);
        f.stream() << "new contents";
        EXPECT_EQ(orogen::test::slurp(target), "old");  // not visible before commit
        f.commit();
    }
    EXPECT_EQ(orogen::test::slurp(target), "new contents");
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1);  // no temporary left
}

TEST(AtomicFile, AnAbandonedWriteLeavesTheOldFileAndNoTemporary) {
    TempDir dir;
    dir.write("good.png", "good");
    try {
        AtomicFile f(dir / "good.png");
        f.stream() << "half";
        throw std::runtime_error("the node failed half way");
    } catch (const std::runtime_error&) {}
    EXPECT_EQ(orogen::test::slurp(dir / "good.png"), "good");
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1);
}

TEST(AtomicFile, AMissingFolderIsAClearError) {
    TempDir dir;
    try {
        AtomicFile f(dir / "no-such-folder" / "x.png");
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()),
                  "cannot write " + (dir / "no-such-folder" / "x.png").string() + ": folder " +
                      (dir / "no-such-folder").string() + " does not exist");
    }
}

namespace {
std::string hash_of_bytes_on_disk(const std::filesystem::path& p) {
    const std::vector<std::uint8_t> bytes = read_file(p);
    return sha256_hex(bytes);
}
}  // namespace

// The digest taken while writing is the file's: pieces of every size (into the 64 KiB block, straight
// past it, single characters, tellp() between them) give the hash of the bytes on disk, and
// sha256_file() answers it from memory, without reading the file.
TEST(AtomicFile, TheDigestTakenWhileWritingIsTheFilesAndSparesTheReadBack) {
    TempDir dir;
    const auto target = dir / "mixed.bin";
    std::string big(300000, '\0');
    for (std::size_t i = 0; i < big.size(); ++i) big[i] = char((i * 2654435761u) >> 13);
    {
        AtomicFile f(target);
        f.stream() << "header " << 42 << '\n';
        EXPECT_EQ(f.stream().tellp(), std::streampos(10));
        f.stream().write(big.data(), 1000);  // into the block
        f.stream().write(big.data(), std::streamsize(big.size()));  // straight through
        for (int i = 0; i < 70000; ++i) f.stream().put(char(i));  // overflows the block one byte at a time
        f.write({reinterpret_cast<const std::uint8_t*>(big.data()), 5});
        f.commit();
    }
    const std::string on_disk = hash_of_bytes_on_disk(target);
    EXPECT_EQ(detail::remembered_sha256(target), on_disk);
    EXPECT_EQ(sha256_file(target), on_disk);
    EXPECT_EQ(std::filesystem::file_size(target), 10u + 1000u + big.size() + 70000u + 5u);
}

// Whatever might make the digest wrong makes sha256_file() read the file instead: a seek that
// overwrites bytes, the temporary written by name, and the file changed after the commit.
TEST(AtomicFile, ASeekAWriteByNameOrALaterChangeMeansTheFileIsReadAgain) {
    TempDir dir;
    {
        AtomicFile f(dir / "seek.bin");
        f.stream() << "aaaaaaaa";
        f.stream().seekp(2);
        f.stream() << "BB";
        f.stream().seekp(0, std::ios::end);
        f.commit();
    }
    EXPECT_EQ(orogen::test::slurp(dir / "seek.bin"), "aaBBaaaa");
    EXPECT_EQ(detail::remembered_sha256(dir / "seek.bin"), "");
    EXPECT_EQ(sha256_file(dir / "seek.bin"), hash_of_bytes_on_disk(dir / "seek.bin"));
    {
        AtomicFile f(dir / "by-name.bin");
        f.stream().close();  // as the VTK and GDAL exporters do
        std::ofstream(f.temporary(), std::ios::binary) << "written by a library";
        f.commit();
    }
    EXPECT_EQ(detail::remembered_sha256(dir / "by-name.bin"), "");
    EXPECT_EQ(sha256_file(dir / "by-name.bin"), hash_of_bytes_on_disk(dir / "by-name.bin"));
    {
        AtomicFile f(dir / "later.bin");
        f.stream() << "first version";
        f.commit();
    }
    ASSERT_NE(detail::remembered_sha256(dir / "later.bin"), "");
    // Rewritten in place with as many bytes: the inode and size stay, the times do not (past the file
    // system's clock tick, a few ms on Linux: digest.hpp).
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    std::ofstream(dir / "later.bin", std::ios::binary | std::ios::in | std::ios::out) << "FIRST VERSION";
    EXPECT_EQ(sha256_file(dir / "later.bin"), hash_of_bytes_on_disk(dir / "later.bin"));
    EXPECT_EQ(detail::remembered_sha256(dir / "later.bin"), "");
}

// A moved AtomicFile keeps hashing what it writes; an abandoned one remembers nothing.
TEST(AtomicFile, AMovedFileKeepsItsDigestAndAnAbandonedOneLeavesNone) {
    TempDir dir;
    {
        AtomicFile a(dir / "moved.bin");
        a.stream() << "before the move, ";
        AtomicFile b(std::move(a));
        b.stream() << "after the move";
        b.commit();
    }
    EXPECT_EQ(orogen::test::slurp(dir / "moved.bin"), "before the move, after the move");
    EXPECT_EQ(detail::remembered_sha256(dir / "moved.bin"), hash_of_bytes_on_disk(dir / "moved.bin"));
    {
        AtomicFile f(dir / "abandoned.bin");
        f.stream() << std::string(100000, 'x');
    }
    EXPECT_FALSE(std::filesystem::exists(dir / "abandoned.bin"));
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1);  // no temporary left
}

namespace {
void write_png(const std::filesystem::path& p, int w, int h, int bits, const std::vector<std::uint16_t>& s) {
    AtomicFile f(p);
    write_gray_png(f.stream(), w, h, bits, s);
    f.commit();
}
}  // namespace

TEST(Png, SixteenAndEightBitRoundTripsAreExact) {
    TempDir dir;
    std::vector<std::uint16_t> samples(37 * 23);
    for (std::size_t i = 0; i < samples.size(); ++i) samples[i] = std::uint16_t((i * 2654435761u) & 0xFFFF);
    write_png(dir / "16.png", 37, 23, 16, samples);
    GrayImage back = read_gray_png(dir / "16.png");
    EXPECT_EQ(back.width, 37);
    EXPECT_EQ(back.height, 23);
    EXPECT_EQ(back.bits, 16);
    EXPECT_EQ(back.samples, samples);

    for (auto& s : samples) s &= 0xFF;
    write_png(dir / "8.png", 37, 23, 8, samples);
    back = read_gray_png(dir / "8.png");
    EXPECT_EQ(back.bits, 8);
    EXPECT_EQ(back.samples, samples);
}

TEST(Png, EveryCompressionLevelDecodesToTheSameSamplesAndHigherLevelsAreSmaller) {
    // A smooth 16-bit terrain-like ramp with noise in the low bits: what the filters and deflate are for.
    TempDir dir;
    const int w = 257, h = 129;
    std::vector<std::uint16_t> samples(std::size_t(w) * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            samples[std::size_t(y) * w + std::size_t(x)] =
                std::uint16_t(20000 + 90 * x + 40 * y + ((std::uint32_t(x * 7919 + y * 104729) * 2654435761u) >> 29));
    std::uintmax_t size[13] = {};
    for (int level : {0, 1, 6, 12}) {
        const auto path = dir / ("l" + std::to_string(level) + ".png");
        {
            AtomicFile f(path);
            write_gray_png(f.stream(), w, h, 16, samples, level);
            f.commit();
        }
        EXPECT_EQ(read_gray_png(path).samples, samples) << "level " << level;
        size[level] = std::filesystem::file_size(path);
    }
    EXPECT_GT(size[0], std::uintmax_t(w) * h * 2) << "level 0 stores the filtered rows";
    EXPECT_LT(size[1], size[0] / 2);
    EXPECT_LE(size[12], size[6]);
    EXPECT_LE(size[6], size[1]);
    std::ostringstream sink;
    EXPECT_THROW(write_gray_png(sink, w, h, 16, samples, 13), BadInput);
}

TEST(Png, BadFilesAreRefusedWithTheirName) {
    TempDir dir;
    dir.write("text.png", "this is not an image at all");
    try {
        read_gray_png(dir / "text.png");
        FAIL();
    } catch (const BadInput& e) {
        EXPECT_EQ(std::string(e.what()),
                  "cannot read " + (dir / "text.png").string() +
                      ": not a PNG file (it does not start with the PNG signature)");
    }

    std::vector<std::uint8_t> rgba(16 * 16 * 4, 200);
    {
        AtomicFile f(dir / "rgba.png");
        write_rgba_png(f.stream(), 16, 16, rgba);
        f.commit();
    }
    try {
        read_gray_png(dir / "rgba.png");
        FAIL();
    } catch (const BadInput& e) {
        EXPECT_NE(std::string(e.what()).find("it is an RGBA colour image, but a heightmap must be a grayscale PNG"),
                  std::string::npos)
            << e.what();
    }

    std::vector<std::uint16_t> samples(64 * 64);
    for (std::size_t i = 0; i < samples.size(); ++i) samples[i] = std::uint16_t(i * 7919);
    write_png(dir / "whole.png", 64, 64, 16, samples);
    const auto bytes = read_file(dir / "whole.png");
    std::ofstream(dir / "cut.png", std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size() / 2));
    // The header is intact, but the chunks show the file was cut: refused before decoding, header reads too.
    for (const bool header_only : {true, false}) {
        try {
            header_only ? read_gray_png_header(dir / "cut.png") : read_gray_png(dir / "cut.png");
            FAIL();
        } catch (const BadInput& e) {
            EXPECT_NE(std::string(e.what()).find(": truncated PNG (the file ends at byte " +
                                                 std::to_string(bytes.size() / 2)),
                      std::string::npos)
                << e.what();
        }
    }
}

TEST(Heightmap, AdoptsFilledVectorsAndRefusesWrongSizes) {
    std::vector<float> heights{1, 2, 3, 4, 5, 6};
    const float* data = heights.data();
    Heightmap hm(3, 2, 10.0, std::move(heights));
    EXPECT_EQ(hm.heights().data(), data);  // adopted, not copied
    EXPECT_EQ(hm.view().at(2, 1), 6.0f);
    std::vector<float> water{0, 0, 0, 0, 0, 0.5f};
    const float* wdata = water.data();
    hm.set_layer("water", std::move(water));
    EXPECT_EQ(hm.layer("water").data, wdata);
    hm.set_layer("water", std::vector<float>(6, 2.0f));  // replaces
    EXPECT_EQ(std::as_const(hm).layer("water").data[5], 2.0f);
    EXPECT_EQ(hm.layer_names(), std::vector<std::string>{"water"});
    EXPECT_THROW(hm.set_layer("flow", std::vector<float>(5)), Error);
    EXPECT_FALSE(hm.has_layer("flow"));
    EXPECT_THROW(Heightmap(3, 3, 1.0, std::vector<float>(6)), Error);
    // The flat constructor still works as before.
    const Heightmap flat(2, 2, 1.0, 7.0f);
    EXPECT_EQ(flat.heights(), std::vector<float>(4, 7.0f));
}

TEST(Heightmap, MissingLayerNamesTheOnesThatExist) {
    Heightmap hm(4, 3, 10.0);
    hm.layer("water", 0.5f);
    EXPECT_TRUE(hm.has_layer("water"));
    EXPECT_EQ(hm.layer("water").at(3, 2), 0.5f);
    try {
        std::as_const(hm).layer("sediment");
        FAIL();
    } catch (const BadInput& e) { EXPECT_STREQ(e.what(), "the heightmap has no layer 'sediment' (it has water)"); }
}

TEST(SplitNames, ItemsLoseTheirSpacesAndEmptyOnesAreDropped) {
    using V = std::vector<std::string>;
    EXPECT_EQ(orogen::split_names(""), V{});
    EXPECT_EQ(orogen::split_names(" , \t,"), V{});
    EXPECT_EQ(orogen::split_names("water"), V{"water"});
    EXPECT_EQ(orogen::split_names("water, eroded"), V({"water", "eroded"}));
    EXPECT_EQ(orogen::split_names("\twater ,,eroded ,  flow_x\t"), V({"water", "eroded", "flow_x"}));
    EXPECT_EQ(orogen::split_names("a b, c"), V({"a b", "c"}));  // inner spaces stay: the item's name says what is wrong
}
