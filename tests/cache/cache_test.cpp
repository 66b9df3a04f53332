// The node cache end to end (docs/cache.md): the real CLI on real specs, each
// test with its own cache folder, looking at the files it leaves and at the
// timing table ("cached" / "cached, read" rows).
#include "cache/cache.hpp"
#include "run/loader.hpp"

#include <orogen/io.hpp>

#include <gtest/gtest.h>

#include "orogen_test.hpp"

#include <cstring>
#include <fstream>
#include <functional>
#include <algorithm>
#include <chrono>
#include <ctime>
#include <map>
#include <regex>
#include <set>

using namespace orogen;
using namespace orogen::test;
namespace fs = std::filesystem;

namespace {

// Generators, an eroder, and exporters of two kinds; small, so each run takes a fraction of a second.
const char* spec_text =
    "orogen 1\n"
    "seed 3\n"
    "grid 97 cell=30\n"
    "base  = generate:diamond-square(roughness=0.6, amplitude=800)\n"
    "cut   = generate:fault(base, iterations=40, displacement=4)\n"
    "scree = erode:thermal(cut, talus=38, iterations=10)\n"
    "export:png(scree, path=\"scree.png\", bits=16)\n"
    "export:raw(scree, path=\"raw/scree.r32\")\n"
    "export:png(base, path=\"base.png\")\n";

/// relative path → sha256 of every output the manifest lists (the manifest's own view of the run).
std::map<std::string, std::string> manifest_hashes(const fs::path& out) {
    std::map<std::string, std::string> m;
    const std::string text = slurp(out / "manifest.json");
    const std::regex entry("\"path\": *\"([^\"]+)\",\\s*\"bytes\": *[0-9]+,\\s*\"sha256\": *\"([0-9a-f]{64})\"");
    for (std::sregex_iterator it(text.begin(), text.end(), entry), end; it != end; ++it) m[(*it)[1]] = (*it)[2];
    return m;
}

/// Every file under `out` (the manifest excepted) → its sha256, as found on disk.
std::map<std::string, std::string> disk_hashes(const fs::path& out) {
    std::map<std::string, std::string> m;
    for (const auto& e : fs::recursive_directory_iterator(out))
        if (e.is_regular_file() && e.path().filename() != "manifest.json")
            m[fs::relative(e.path(), out).generic_string()] = sha256_file(e.path());
    return m;
}

/// The timing table's cache column for each node label: "" ran, "cached", "cached, read".
std::map<std::string, std::string> cache_column(const std::string& stdout_text) {
    std::map<std::string, std::string> rows;
    std::istringstream in(stdout_text);
    std::string line;
    bool table = false;
    while (std::getline(in, line)) {
        if (line.rfind("node ", 0) == 0) {
            table = true;
            continue;
        }
        if (!table || line.rfind("total", 0) == 0) {
            if (table) break;
            continue;
        }
        std::istringstream fields(line);
        std::string label, node, lineno, seconds, share;
        fields >> label >> node >> lineno >> seconds >> share;
        std::string rest;
        std::getline(fields, rest);
        rest.erase(0, rest.find_first_not_of(' '));
        rows[label + " " + node + ":" + lineno] = rest;
    }
    return rows;
}

std::vector<fs::path> entries(const fs::path& cache) {
    std::vector<fs::path> out;
    if (!fs::exists(cache)) return out;
    for (const auto& e : fs::directory_iterator(cache))
        if (e.path().extension() == ".orc") out.push_back(e.path());
    std::sort(out.begin(), out.end());
    return out;
}

std::uint64_t entry_bytes(const fs::path& cache) {
    std::uint64_t n = 0;
    for (const auto& e : entries(cache)) n += fs::file_size(e);
    return n;
}

/// The GNU build-id of an ELF file as binutils' readelf prints it ("" if it has none).
std::string read_build_id(const fs::path& file) {
    const std::string cmd = "readelf -n " + q(file) + " 2>/dev/null";
    std::FILE* p = ::popen(cmd.c_str(), "r");
    if (!p) return {};
    std::string text;
    char buf[4096];
    while (std::size_t n = std::fread(buf, 1, sizeof buf, p)) text.append(buf, n);
    ::pclose(p);
    std::smatch m;
    return std::regex_search(text, m, std::regex("Build ID: ([0-9a-f]+)")) ? m[1].str() : std::string();
}

struct Fixture {
    TempDir dir;
    fs::path spec = dir.write("t.orogen", spec_text);
    fs::path cache = dir / "cache";

    test::RunResult run(const std::string& out, const std::string& extra = "", const std::string& env = "") const {
        return run_orogen("run " + q(spec) + " --out " + q(dir / out) + " " + extra, env);
    }
    test::RunResult cached(const std::string& out, const std::string& extra = "") const {
        return run(out, "--cache " + q(cache) + " " + extra);
    }
};

int count_rows(const std::map<std::string, std::string>& rows, const std::string& status) {
    int n = 0;
    for (const auto& [_, s] : rows) n += s == status;
    return n;
}

std::string row(const std::map<std::string, std::string>& rows, const std::string& label_prefix) {
    for (const auto& [k, s] : rows)
        if (k.rfind(label_prefix + " ", 0) == 0) return s;
    ADD_FAILURE() << "no row " << label_prefix;
    return "?";
}

}  // namespace

// ------------------------------------------------------------ entries

TEST(CacheEntry, EveryStorableValueTypeRoundTripsBitForBit) {
    auto hm = std::make_shared<Heightmap>(7, 5, 12.5, 0.0f);
    for (std::size_t i = 0; i < hm->size(); ++i) hm->heights()[i] = float(i) * 0.37f - 3.0f;
    GridView water = hm->layer("water", 0.25f);
    water.data[3] = -1e-30f;
    hm->layer("flow", 2.0f);
    auto img8 = std::make_shared<Image>();
    img8->width = 3;
    img8->height = 2;
    img8->rgba8 = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23, 24};
    auto imgf = std::make_shared<Image>();
    imgf->width = 1;
    imgf->height = 1;
    imgf->format = Image::Format::rgba32f;
    imgf->rgba32f = {0.5f, 1e9f, -0.0f, 3.0f};
    auto ps = std::make_shared<ParticleSeries>();
    ps->frames.resize(2);
    ps->frames[1].time = 0.75;
    ps->frames[1].step = 9;
    ps->frames[1].attributes["position"] = {3, {1, 2, 3, 4, 5, 6}};
    ps->frames[1].attributes["density"] = {1, {1000, 998}};
    auto ph = std::make_shared<PlateHistory>();
    ph->width = 100;
    ph->height = 50;
    ph->snapshots.push_back({4, 2.5, {{7, {{0, 0}, {1, 0}, {0, 1}}, {0.5, -0.25}, 1.2}}});
    ph->collisions.push_back({4, 7, 8, {1, 2}, {3, 4}, BoundaryKind::transform, 0.125});

    cache::Contents c;
    c.values = {
        {"", Value(hm)}, {"img8", Value(img8)}, {"imgf", Value(imgf)}, {"particles", Value(ps)}, {"plates", Value(ph)}};
    c.files = {{"sub/a.png", {9, 8, 7}}, {"empty.txt", {}}};
    c.recorded = {{"tiles/t_l0_x0_y0.glb", 875u << 20, std::string(64, 'c')}};
    c.messages = {"scree: warning: steep"};
    cache::Hasher kh;
    const cache::Digest key = kh.text("k").finish();
    const std::vector<std::uint8_t> bytes = cache::encode(key, c);
    const cache::Contents d = cache::decode(bytes, key);

    ASSERT_EQ(d.values.size(), 5u);
    const Heightmap& h2 = *d.values[0].second.heightmap();
    EXPECT_EQ(h2.width(), 7);
    EXPECT_EQ(h2.height(), 5);
    EXPECT_EQ(h2.cell(), 12.5);
    EXPECT_EQ(h2.heights(), hm->heights());
    EXPECT_EQ(h2.layer_names(), (std::vector<std::string>{"flow", "water"}));
    EXPECT_EQ(std::memcmp(h2.layer("water").data, hm->layer("water").data, hm->size() * 4), 0);
    EXPECT_EQ(d.values[1].second.image()->rgba8, img8->rgba8);
    EXPECT_EQ(d.values[2].second.image()->format, Image::Format::rgba32f);
    EXPECT_EQ(std::memcmp(d.values[2].second.image()->rgba32f.data(), imgf->rgba32f.data(), 16), 0);  // -0.0 kept
    const auto& f1 = d.values[3].second.particles()->frames.at(1);
    EXPECT_EQ(f1.time, 0.75);
    EXPECT_EQ(f1.step, 9);
    EXPECT_EQ(f1.attributes.at("position").components, 3);
    EXPECT_EQ(f1.attributes.at("position").data, (std::vector<float>{1, 2, 3, 4, 5, 6}));
    EXPECT_EQ(f1.attributes.at("density").data, (std::vector<float>{1000, 998}));
    const auto& p2 = *d.values[4].second.plates();
    EXPECT_EQ(p2.width, 100);
    ASSERT_EQ(p2.snapshots.size(), 1u);
    EXPECT_EQ(p2.snapshots[0].plates[0].polygon, ph->snapshots[0].plates[0].polygon);
    EXPECT_EQ(p2.snapshots[0].plates[0].velocity, (Point2{0.5, -0.25}));
    EXPECT_EQ(p2.collisions[0].kind, BoundaryKind::transform);
    EXPECT_EQ(p2.collisions[0].b, (Point2{3, 4}));
    EXPECT_EQ(d.files, c.files);
    EXPECT_EQ(d.recorded, c.recorded);
    EXPECT_EQ(d.messages, c.messages);
    // Encoding is a function of the contents: the same bytes twice.
    EXPECT_EQ(cache::encode(key, d), bytes);
}

TEST(CacheEntry, AnyFlippedByteOrCutIsCaughtAndAnotherVersionOrKeyRefused) {
    auto hm = std::make_shared<Heightmap>(64, 64, 1.0, 5.0f);
    cache::Contents c;
    c.values = {{"", Value(hm)}};
    cache::Hasher kh;
    const cache::Digest key = kh.text("k").finish();
    const std::vector<std::uint8_t> good = cache::encode(key, c);
    for (std::size_t at : {std::size_t(130), good.size() / 2, good.size() - 1}) {
        auto bad = good;
        bad[at] ^= 0x10;
        EXPECT_THROW(cache::decode(bad, key), cache::CorruptEntry) << "flipped byte " << at;
    }
    for (std::size_t keep : {std::size_t(0), std::size_t(100), std::size_t(128), good.size() - 1}) {
        const std::vector<std::uint8_t> cut(good.begin(), good.begin() + std::ptrdiff_t(keep));
        EXPECT_THROW(cache::decode(cut, key), cache::CorruptEntry) << "cut to " << keep;
    }
    auto other = good;
    other[16] = '9';  // the orogen version in the header
    EXPECT_THROW(cache::decode(other, key), cache::OtherVersion);
    cache::Hasher kh2;
    EXPECT_THROW(cache::decode(good, kh2.text("other").finish()), cache::CorruptEntry);
}

TEST(CacheEntry, LargeValuesRoundTripThroughTheParallelCopies) {
    // Arrays of 256 KiB and more are copied after parsing, on every core beside the checksum, and from 4 MiB
    // into huge pages: a 1025² heightmap (4.2 MB a layer) with three layers, a large image and a large file.
    const int n = 1025;
    auto hm = std::make_shared<Heightmap>(n, n, 7.5, 0.0f);
    for (std::size_t i = 0; i < hm->size(); ++i) hm->heights()[i] = float(i % 8191) * 0.5f - 100.0f;
    for (const char* name : {"water", "sediment", "flow"}) {
        GridView l = hm->layer(name);
        for (std::size_t i = 0; i < l.size(); ++i) l.data[i] = float((i * 31 + std::strlen(name)) % 977);
    }
    auto img = std::make_shared<Image>();
    img->width = 400;
    img->height = 300;
    img->rgba8.resize(400 * 300 * 4);
    for (std::size_t i = 0; i < img->rgba8.size(); ++i) img->rgba8[i] = std::uint8_t(i * 13);
    std::vector<std::uint8_t> file(3u << 20);
    for (std::size_t i = 0; i < file.size(); ++i) file[i] = std::uint8_t(i ^ (i >> 9));
    cache::Contents c;
    c.values = {{"", Value(hm)}, {"img", Value(img)}};
    c.files = {{"big.bin", file}, {"small.txt", {1, 2}}};
    cache::Hasher kh;
    const cache::Digest key = kh.text("big").finish();
    const std::vector<std::uint8_t> bytes = cache::encode(key, c);
    const cache::Contents d = cache::decode(bytes, key);
    ASSERT_EQ(d.values.size(), 2u);
    const Heightmap& h2 = *d.values[0].second.heightmap();
    EXPECT_EQ(h2.width(), n);
    EXPECT_EQ(h2.cell(), 7.5);
    EXPECT_EQ(h2.heights(), hm->heights());
    ASSERT_EQ(h2.layer_names(), hm->layer_names());
    for (const auto& name : hm->layer_names())
        EXPECT_EQ(std::memcmp(h2.layer(name).data, hm->layer(name).data, hm->size() * 4), 0) << name;
    EXPECT_EQ(d.values[1].second.image()->rgba8, img->rgba8);
    EXPECT_EQ(d.files, c.files);
    EXPECT_EQ(cache::encode(key, d), bytes);
    // Encoded as the store writes it, streamed 8 MiB at a time with each block's checksum taken on its way
    // out: the same seal as over the whole payload (reseal() recomputes it from the whole buffer), and the
    // same bytes as a second, separately streamed encoding.
    ASSERT_GT(bytes.size(), std::size_t(19) << 20);
    auto resealed = bytes;
    cache::reseal(resealed, key);
    EXPECT_EQ(resealed, bytes);
    std::vector<std::uint8_t> streamed;
    std::size_t pieces = 0;
    const std::uint64_t size = cache::encode_into(
        key, c,
        {[&](std::span<const std::uint8_t> b) {
             ++pieces;
             streamed.insert(streamed.end(), b.begin(), b.end());
         },
         [&](std::span<const std::uint8_t> h) { std::memcpy(streamed.data(), h.data(), h.size()); }});
    EXPECT_EQ(size, bytes.size());
    EXPECT_EQ(streamed, bytes);
    EXPECT_GE(pieces, 4u) << "the payload went out in pieces, not whole";
    // One flipped bit in the last layer: refused, whichever core copied or checked that part.
    auto bad = bytes;
    bad[bytes.size() - (3u << 20) - 4096] ^= 0x04;
    EXPECT_THROW(cache::decode(bad, key), cache::CorruptEntry);
}

namespace {
/// An entry of one value whose payload passes the checksum but was written wrong on purpose: `edit` changes
/// the encoded bytes of `c` (found by searching them), then the entry is resealed.
std::string refusal(const cache::Contents& c, const std::function<void(std::vector<std::uint8_t>&)>& edit) {
    cache::Hasher kh;
    const cache::Digest key = kh.text("sealed").finish();
    auto bytes = cache::encode(key, c);
    edit(bytes);
    cache::reseal(bytes, key);
    try {
        cache::decode(bytes, key);
    } catch (const cache::CorruptEntry& e) { return e.what(); }
    return "accepted";
}

/// Replace the first occurrence of `from` after the 192-byte header in `bytes` by `to` (the same length). (Not
/// in the header: its format version, 3, is a little-endian int like the sizes these tests edit.)
void replace_bytes(std::vector<std::uint8_t>& bytes, const std::vector<std::uint8_t>& from,
                   const std::vector<std::uint8_t>& to) {
    const auto it = std::search(bytes.begin() + 192, bytes.end(), from.begin(), from.end());
    ASSERT_NE(it, bytes.end());
    std::copy(to.begin(), to.end(), it);
}

template <typename T>
std::vector<std::uint8_t> le(T v) {
    std::vector<std::uint8_t> b(sizeof v);
    std::memcpy(b.data(), &v, sizeof v);
    return b;
}
}  // namespace

TEST(CacheEntry, ASealedButInvalidPayloadIsRefusedNamingWhatIsWrong) {
    // What the checksum cannot catch (an entry written wrong, by another program or by hand) must still never
    // reach a node: sizes that disagree, a path out of --out, an unknown kind.
    auto img = std::make_shared<Image>();
    img->width = 0x1234;
    img->height = 1;
    img->rgba8.assign(0x1234 * 4, 9);
    cache::Contents ci;
    ci.values = {{"", Value(img)}};
    EXPECT_EQ(refusal(ci, [](auto&) {}), "accepted");
    EXPECT_EQ(refusal(ci, [](auto& b) { replace_bytes(b, le<std::int32_t>(0x1234), le<std::int32_t>(0x1235)); }),
              "an image's pixels do not match its size and format");

    cache::Contents cf;
    cf.files = {{"abc/x.png", {1, 2, 3}}};
    const auto path = [](const std::string& p) {
        return [p](std::vector<std::uint8_t>& b) {
            replace_bytes(b, std::vector<std::uint8_t>{'a', 'b', 'c', '/', 'x', '.', 'p', 'n', 'g'},
                          std::vector<std::uint8_t>(p.begin(), p.end()));
        };
    };
    EXPECT_EQ(refusal(cf, path("abc/x.png")), "accepted");
    EXPECT_EQ(refusal(cf, path("../../x.p")), "a kept file has a bad path ('../../x.p')");
    EXPECT_EQ(refusal(cf, path("/etc/x.pn")), "a kept file has a bad path ('/etc/x.pn')");
    cache::Contents cr;
    cr.recorded = {{"abc/x.png", 3, std::string(64, 'a')}};
    EXPECT_EQ(refusal(cr, [](auto&) {}), "accepted");
    EXPECT_EQ(refusal(cr, path("../../x.p")), "a kept file has a bad path ('../../x.p')");
    EXPECT_EQ(refusal(cr,
                      [](auto& b) {
                          replace_bytes(b, {'a', 'a', 'a', 'a'}, {'a', 'A', 'a', 'a'});
                      }),
              "a recorded file's SHA-256 is not 64 hex digits");

    auto hm = std::make_shared<Heightmap>(3, 2, 4.0, 1.0f);
    hm->layer("water");
    cache::Contents ch;
    ch.values = {{"", Value(hm)}};
    EXPECT_EQ(refusal(ch, [](auto& b) { replace_bytes(b, le<double>(4.0), le<double>(-4.0)); }),
              "a heightmap whose cell size is not a positive number");
    EXPECT_EQ(refusal(ch, [](auto& b) { replace_bytes(b, le<std::int32_t>(3), le<std::int32_t>(2)); }),
              "a heightmap's size does not match its heights");

    auto ps = std::make_shared<ParticleSeries>();
    ps->frames.resize(1);
    ps->frames[0].attributes["position"] = {3, {1, 2, 3, 4, 5, 6}};
    ps->frames[0].attributes["zdensity"] = {1, {7, 8, 9}};  // one particle too many
    cache::Contents cp;
    cp.values = {{"", Value(ps)}};
    EXPECT_EQ(refusal(cp, [](auto&) {}), "a particle attribute's size does not match the frame's particles");

    auto ph = std::make_shared<PlateHistory>();
    ph->collisions.push_back({4, 7, 8, {1, 2}, {3, 4}, BoundaryKind::transform, 0.125});
    cache::Contents cpl;
    cpl.values = {{"", Value(ph)}};
    EXPECT_EQ(refusal(cpl, [](auto& b) { replace_bytes(b, le<std::int32_t>(3), le<std::int32_t>(9)); }),
              "a collision of unknown kind 9");
}

TEST(CacheKey, ThePluginsAndTheKernelsBinaryIdentityAreInTheKey) {
    NodeDescriptor desc{.kind = "generate", .name = "x"};
    PlannedNode node;
    node.node = &desc;
    node.label = "x";
    Plan plan;
    const auto key = [&](std::string_view identity) {
        return cache::node_key(plan, node, {}, "p", "0.1.0", identity, 7);
    };
    EXPECT_EQ(key("build-id:aa11"), key("build-id:aa11"));
    EXPECT_NE(key("build-id:aa11"), key("build-id:aa12"));
    EXPECT_NE(key("build-id:aa11"), key("sha256:aa11"));
    // The kernel's own identity is its build-id as binutils reads it from the file.
    const std::string kernel = read_build_id(fs::path(OROGEN_BINARY_DIR) / "lib" / "liborogen.so");
    ASSERT_FALSE(kernel.empty());
    EXPECT_EQ(cache::kernel_identity(), "build-id:" + kernel);
}

TEST(CacheKey, ALoadedPluginsIdentityIsItsBuildIdAndTwoBuildsDiffer) {
    std::vector<std::string> identities;
    for (const char* variant : {"1", "2"}) {
        const fs::path file = fs::path(OROGEN_STALE_PLUGIN_DIR + std::string(variant)) / "stale.so";
        PluginSet set;
        set.load(file);
        ASSERT_EQ(set.plugins().size(), 1u) << file;
        const std::string id = read_build_id(file);
        ASSERT_FALSE(id.empty()) << file;
        EXPECT_EQ(set.plugins()[0].identity, "build-id:" + id);
        identities.push_back(set.plugins()[0].identity);
    }
    EXPECT_NE(identities[0], identities[1]);
    // Code with no loaded binary around it has no identity.
    int on_the_stack = 0;
    EXPECT_EQ(cache::binary_identity(&on_the_stack), "");
}

TEST(CacheRun, ARebuiltPluginWithTheSameVersionDoesNotFindTheOldBuildsResults) {
    TempDir dir;
    const fs::path spec =
        dir.write("s.orogen", "orogen 1\ngrid 9 cell=1\nh = generate:test-stale()\nexport:raw(h, path=\"h.r32\")\n");
    const auto run = [&](const char* variant, const std::string& out) {
        return run_orogen("run " + q(spec) + " --out " + q(dir / out) + " --cache " + q(dir / "cache"),
                          "OROGEN_PLUGIN_PATH=" + q(OROGEN_STALE_PLUGIN_DIR + std::string(variant)));
    };
    const auto first_height = [&](const std::string& out) {
        const auto bytes = read_file(dir / out / "h.r32");
        float v = -1;
        if (bytes.size() >= 4) std::memcpy(&v, bytes.data(), 4);
        return v;
    };
    const test::RunResult a = run("1", "a");
    ASSERT_EQ(a.exit_code, 0) << a.err;
    EXPECT_EQ(first_height("a"), 1.0f);
    const test::RunResult again = run("1", "again");  // the same build: everything reused
    ASSERT_EQ(again.exit_code, 0) << again.err;
    EXPECT_EQ(count_rows(cache_column(again.out), "cached"), 2) << again.out;
    const test::RunResult b = run("2", "b");  // rebuilt with other code, same name and version "0.1.0"
    ASSERT_EQ(b.exit_code, 0) << b.err;
    EXPECT_EQ(row(cache_column(b.out), "h"), "") << b.out;  // ran
    EXPECT_EQ(first_height("b"), 2.0f);
}

TEST(CacheEntry, TheFuzzCorpusHoldsRealEntriesThatDecodeOnceResealed) {
    // tests/fuzz/corpus/cache: entries of a real run (and a few made here), so the fuzzer starts from valid
    // payloads of every kind. Resealed (the version and checksums of this build), each must decode: a corpus
    // the decoder refuses would leave the fuzzer at the door.
    const fs::path corpus = fs::path(OROGEN_SOURCE_DIR) / "tests" / "fuzz" / "corpus" / "cache";
    std::set<int> kinds;
    int decoded = 0;
    for (const auto& e : fs::directory_iterator(corpus)) {
        const std::string name = e.path().filename().string();
        if (e.path().extension() != ".orc" || name.rfind("truncated", 0) == 0) continue;
        auto bytes = read_file(e.path());
        ASSERT_GE(bytes.size(), 192u) << name;
        cache::Digest key{};
        std::memcpy(key.data(), bytes.data() + 88, key.size());
        cache::reseal(bytes, key);
        const cache::Contents c = cache::decode(bytes, key);
        for (const auto& [_, v] : c.values) kinds.insert(int(v.type()));
        if (!c.files.empty()) kinds.insert(100);
        ++decoded;
    }
    EXPECT_GE(decoded, 8);
    EXPECT_EQ(kinds,
              (std::set<int>{int(ValueType::heightmap), int(ValueType::image), int(ValueType::particles),
                             int(ValueType::plates), 100}));
}

TEST(CacheEntry, SizesParseWithUnits) {
    EXPECT_EQ(cache::parse_size("2G"), std::uint64_t(2) << 30);
    EXPECT_EQ(cache::parse_size("500M"), std::uint64_t(500) << 20);
    EXPECT_EQ(cache::parse_size("64MiB"), std::uint64_t(64) << 20);
    EXPECT_EQ(cache::parse_size("1.5k"), 1536u);
    EXPECT_EQ(cache::parse_size("123456"), 123456u);
    EXPECT_FALSE(cache::parse_size("lots"));
    EXPECT_FALSE(cache::parse_size("-1G"));
    EXPECT_FALSE(cache::parse_size("2X"));
}

// ------------------------------------------------------------ runs

TEST(CacheRun, ColdAndWarmRunsWriteTheSameBytesAsARunWithoutTheCache) {
    Fixture f;
    const test::RunResult plain = f.run("plain", "--no-cache");
    ASSERT_EQ(plain.exit_code, 0) << plain.err;
    EXPECT_FALSE(fs::exists(f.cache));
    const test::RunResult cold = f.cached("cold");
    ASSERT_EQ(cold.exit_code, 0) << cold.err;
    EXPECT_EQ(count_rows(cache_column(cold.out), ""), 6) << cold.out;
    EXPECT_EQ(entries(f.cache).size(), 6u);  // three heightmaps, three exports' files
    const test::RunResult warm = f.cached("warm");
    ASSERT_EQ(warm.exit_code, 0) << warm.err;

    // Every node came from the cache; the exports' files were put back from their entries, and the
    // heightmaps, which no node that ran needed, were never read.
    const auto rows = cache_column(warm.out);
    EXPECT_EQ(rows.size(), 6u) << warm.out;
    EXPECT_EQ(count_rows(rows, "cached"), 6) << warm.out;
    EXPECT_NE(warm.out.find("cache: 6 of 6 nodes reused from"), std::string::npos) << warm.out;
    EXPECT_NE(warm.err.find("(erode:thermal) cached"), std::string::npos) << warm.err;

    const auto reference = manifest_hashes(f.dir / "plain");
    EXPECT_EQ(reference.size(), 4u);  // two PNGs, the .r32 and its sidecar
    EXPECT_EQ(manifest_hashes(f.dir / "cold"), reference);
    EXPECT_EQ(manifest_hashes(f.dir / "warm"), reference);
    EXPECT_EQ(disk_hashes(f.dir / "warm"), reference);  // the files themselves, not only what the manifest says
    EXPECT_EQ(slurp(f.dir / "warm" / "manifest.json"), slurp(f.dir / "plain" / "manifest.json"));

    // Into the folder of the cold run, whose files are already the right bytes: they are left in place
    // (not staged and renamed over themselves) and still listed, so the manifest is again the same bytes.
    // A file changed since is put back.
    std::ofstream(f.dir / "cold" / "scree.png", std::ios::binary) << "edited by hand";
    const test::RunResult again = f.cached("cold");
    ASSERT_EQ(again.exit_code, 0) << again.err;
    EXPECT_NE(again.out.find("wrote 5 files"), std::string::npos) << again.out;
    EXPECT_EQ(slurp(f.dir / "cold" / "manifest.json"), slurp(f.dir / "plain" / "manifest.json"));
    EXPECT_EQ(disk_hashes(f.dir / "cold"), reference);
}

TEST(CacheRun, LargeFilesAreRecordedByDigestAndTheirExportRunsAgainWhenTheyAreMissingOrDiffer) {
    // A node's files are copied into its entry only if together they take at most 1/64 of the cache's limit;
    // larger ones (a 4097² glTF pyramid: 1.1 GB) are recorded by size and SHA-256. With a 640 KiB limit (10 KiB
    // a node), scree.png (16 KB) and the .r32 with its sidecar (38 KB) are recorded, base.png (6 KB) is kept.
    Fixture f;
    const std::string limit = "--cache-size 640K";
    const test::RunResult plain = f.run("plain", "--no-cache");
    ASSERT_EQ(plain.exit_code, 0) << plain.err;
    const auto reference = disk_hashes(f.dir / "plain");
    const test::RunResult cold = f.cached("a", limit);
    ASSERT_EQ(cold.exit_code, 0) << cold.err;
    EXPECT_EQ(slurp(f.dir / "a" / "manifest.json"), slurp(f.dir / "plain" / "manifest.json"));
    int small = 0;
    for (const auto& e : entries(f.cache)) small += fs::file_size(e) < 2048;
    EXPECT_EQ(small, 2);  // export:png(scree) and export:raw: a path, a size and a digest a file

    // Into the same --out: the files are there with their bytes, so every node is cached and nothing moves.
    const test::RunResult warm = f.cached("a", limit);
    ASSERT_EQ(warm.exit_code, 0) << warm.err;
    EXPECT_EQ(count_rows(cache_column(warm.out), "cached"), 6) << warm.out;
    EXPECT_EQ(slurp(f.dir / "a" / "manifest.json"), slurp(f.dir / "plain" / "manifest.json"));
    EXPECT_EQ(disk_hashes(f.dir / "a"), reference);

    // A deleted file, then an edited one (same size): their export runs again and writes them, and only it.
    for (const auto& damage : {0, 1}) {
        const fs::path victim = f.dir / "a" / "raw" / "scree.r32";
        if (damage == 0) fs::remove(victim);
        else {
            std::fstream io(victim, std::ios::in | std::ios::out | std::ios::binary);
            io.seekp(100);
            io.write("x", 1);
        }
        const test::RunResult r = f.cached("a", limit);
        ASSERT_EQ(r.exit_code, 0) << r.err;
        const auto rows = cache_column(r.out);
        EXPECT_EQ(count_rows(rows, ""), 1) << r.out;  // export:raw
        EXPECT_EQ(row(rows, "scree"), "cached, read") << r.out;  // what it exports
        EXPECT_EQ(disk_hashes(f.dir / "a"), reference) << damage;
        EXPECT_EQ(slurp(f.dir / "a" / "manifest.json"), slurp(f.dir / "plain" / "manifest.json"));
    }

    // Into a new --out: the exports whose files were recorded run again; base.png's, kept whole, is put back.
    const test::RunResult fresh = f.cached("b", limit);
    ASSERT_EQ(fresh.exit_code, 0) << fresh.err;
    const auto rows = cache_column(fresh.out);
    EXPECT_EQ(count_rows(rows, ""), 2) << fresh.out;
    EXPECT_EQ(row(rows, "base"), "cached") << fresh.out;
    EXPECT_EQ(row(rows, "scree"), "cached, read") << fresh.out;
    EXPECT_EQ(disk_hashes(f.dir / "b"), reference);
    EXPECT_EQ(slurp(f.dir / "b" / "manifest.json"), slurp(f.dir / "plain" / "manifest.json"));
}

TEST(CacheRun, ADownstreamChangeRecomputesOnlyWhatItFeeds) {
    Fixture f;
    ASSERT_EQ(f.cached("a").exit_code, 0);
    const test::RunResult r = f.cached("b", "--set scree.talus=30");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto rows = cache_column(r.out);
    EXPECT_EQ(row(rows, "base"), "cached") << r.out;  // not even read: nothing that ran needed it
    EXPECT_EQ(row(rows, "cut"), "cached, read") << r.out;  // read: the thermal erosion starts from it
    EXPECT_EQ(row(rows, "scree"), "") << r.out;  // recomputed
    EXPECT_EQ(count_rows(rows, ""), 3) << r.out;  // with the two exports of scree
    EXPECT_EQ(count_rows(rows, "cached"), 2) << r.out;  // export:png(base) put back from the cache

    const test::RunResult plain = f.run("plain", "--no-cache --set scree.talus=30");
    ASSERT_EQ(plain.exit_code, 0) << plain.err;
    EXPECT_EQ(manifest_hashes(f.dir / "b"), manifest_hashes(f.dir / "plain"));
    EXPECT_NE(manifest_hashes(f.dir / "b"), manifest_hashes(f.dir / "a"));
}

TEST(CacheRun, ANewSeedOrUpstreamParameterRecomputesEverythingAfterIt) {
    Fixture f;
    ASSERT_EQ(f.cached("a").exit_code, 0);
    const test::RunResult seed = f.cached("seed", "--seed 4");
    ASSERT_EQ(seed.exit_code, 0) << seed.err;
    EXPECT_EQ(count_rows(cache_column(seed.out), ""), 6) << seed.out;
    EXPECT_NE(manifest_hashes(f.dir / "seed"), manifest_hashes(f.dir / "a"));

    const test::RunResult up = f.cached("up", "--set cut.iterations=41");
    ASSERT_EQ(up.exit_code, 0) << up.err;
    const auto rows = cache_column(up.out);
    EXPECT_EQ(row(rows, "base"), "cached, read") << up.out;  // the new cut starts from it
    EXPECT_EQ(row(rows, "cut"), "") << up.out;
    EXPECT_EQ(row(rows, "scree"), "") << up.out;
    EXPECT_EQ(count_rows(rows, ""), 4) << up.out;  // cut, scree and scree's two exports
    const test::RunResult plain = f.run("plain", "--no-cache --set cut.iterations=41");
    EXPECT_EQ(manifest_hashes(f.dir / "up"), manifest_hashes(f.dir / "plain"));
}

TEST(CacheRun, DamagedOrTruncatedEntriesAreRecomputedWithAWarningNeverUsed) {
    Fixture f;
    ASSERT_EQ(f.run("plain", "--no-cache").exit_code, 0);
    ASSERT_EQ(f.cached("a").exit_code, 0);
    const auto all = entries(f.cache);
    ASSERT_EQ(all.size(), 6u);
    // Half the entries get one byte flipped deep in the payload, the other half lose their tail.
    for (std::size_t i = 0; i < all.size(); ++i) {
        const auto size = fs::file_size(all[i]);
        if (i % 2 == 0) {
            std::fstream io(all[i], std::ios::in | std::ios::out | std::ios::binary);
            io.seekg(std::streamoff(size - 2));
            char b = 0;
            io.read(&b, 1);
            b = char(b ^ 0x01);
            io.seekp(std::streamoff(size - 2));
            io.write(&b, 1);
        } else {
            fs::resize_file(all[i], size - 7);
        }
    }
    // Change the last exporter's file name so the heightmap entries must be read, not only the exports'.
    f.dir.write("t.orogen", std::string(spec_text) + "export:png(scree, path=\"again.png\")\n");
    const test::RunResult r = f.cached("b");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::regex warning(
        "orogen: warning: the cache entry of '[^']+' \\([0-9a-f]{64}\\.orc\\) is damaged \\([^\\n]*\\); recomputing "
        "it\\n");
    const auto n = std::distance(std::sregex_iterator(r.err.begin(), r.err.end(), warning), std::sregex_iterator());
    EXPECT_EQ(n, 6) << r.err;
    EXPECT_NE(r.err.find("truncated"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("does not match its checksum"), std::string::npos) << r.err;
    auto expected = manifest_hashes(f.dir / "plain");
    auto got = manifest_hashes(f.dir / "b");
    ASSERT_EQ(got.count("again.png"), 1u);
    got.erase("again.png");
    EXPECT_EQ(got, expected);
    EXPECT_EQ(disk_hashes(f.dir / "b").at("scree.png"), expected.at("scree.png"));
    // The damaged entries were replaced by good ones: the next run reuses everything, silently.
    const test::RunResult again = f.cached("c");
    ASSERT_EQ(again.exit_code, 0) << again.err;
    EXPECT_EQ(again.err.find("warning"), std::string::npos) << again.err;
    EXPECT_EQ(count_rows(cache_column(again.out), ""), 0) << again.out;
}

TEST(CacheRun, AnEntryWrittenByAnotherVersionIsIgnored) {
    Fixture f;
    ASSERT_EQ(f.cached("a").exit_code, 0);
    for (const auto& e : entries(f.cache)) {
        std::fstream io(e, std::ios::in | std::ios::out | std::ios::binary);
        io.seekp(16);
        const char other[32] = "0.0.1-elsewhere";
        io.write(other, 32);
    }
    const test::RunResult r = f.cached("b");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("orogen: note: ignoring the cache entry of 'scree': written by orogen 0.0.1-elsewhere"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(count_rows(cache_column(r.out), ""), 6) << r.out;
    EXPECT_EQ(manifest_hashes(f.dir / "b"), manifest_hashes(f.dir / "a"));
}

TEST(CacheRun, AFolderThatCannotBeWrittenGivesAWarningAndTheRunGoesOn) {
    Fixture f;
    const fs::path file = f.dir.write("not-a-folder", "x");
    const test::RunResult r = f.run("a", "--cache " + q(file / "cache"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("orogen: warning: cache folder " + (file / "cache").string() + ": cannot create it"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("running without the cache"), std::string::npos) << r.err;
    EXPECT_EQ(manifest_hashes(f.dir / "a").size(), 4u);
    EXPECT_EQ(r.out.find("cache:"), std::string::npos) << r.out;
}

TEST(CacheRun, EvictionKeepsTheFolderUnderItsLimitAndKeepsTheRecentEntries) {
    Fixture f;
    ASSERT_EQ(f.cached("probe").exit_code, 0);
    const std::uint64_t one_run = entry_bytes(f.cache);
    ASSERT_GT(one_run, 0u);
    fs::remove_all(f.cache);
    // Room for about two runs' entries.
    const std::uint64_t limit = one_run * 2 + one_run / 2;
    for (int seed = 10; seed < 15; ++seed) {
        const test::RunResult r = f.cached("s" + std::to_string(seed),
                                           "--seed " + std::to_string(seed) + " --cache-size " + std::to_string(limit));
        ASSERT_EQ(r.exit_code, 0) << r.err;
        EXPECT_LE(entry_bytes(f.cache), limit) << "after seed " << seed;
    }
    // The last seed's results are all there; the first seed's are gone. (Into the last run's own --out: with a
    // limit this small, the exports' files take more than 1/64 of it, so their entries record them by digest
    // instead of copying them, and a new --out would make the exports run again.)
    const test::RunResult last = f.cached("s14", "--seed 14 --cache-size " + std::to_string(limit));
    EXPECT_EQ(count_rows(cache_column(last.out), ""), 0) << last.out;
    const test::RunResult first = f.cached("again10", "--seed 10 --cache-size " + std::to_string(limit));
    EXPECT_EQ(count_rows(cache_column(first.out), ""), 6) << first.out;
}

TEST(CacheRun, SeriesAreMadeOnlyWhenANodeThatRunsNeedsThem) {
    TempDir dir;
    dir.write("s.orogen",
              "orogen 1\ngrid 5\n"
              "f = generate:test-frames(frames=4)\n"
              "g = generate:test-add(f, amount=2)\n"
              "export:test-series(g, path=\"s.txt\")\n");
    const std::string env = "OROGEN_PLUGIN_PATH=" + std::string(OROGEN_FAKE_PLUGIN_DIR);
    const std::string cache = " --cache " + q(dir / "cache");
    const test::RunResult plain = run_orogen("run s.orogen --out plain --no-cache", env, dir.path());
    ASSERT_EQ(plain.exit_code, 0) << plain.err;
    ASSERT_EQ(run_orogen("run s.orogen --out a" + cache, env, dir.path()).exit_code, 0);
    const test::RunResult warm = run_orogen("run s.orogen --out b" + cache, env, dir.path());
    ASSERT_EQ(warm.exit_code, 0) << warm.err;
    EXPECT_EQ(count_rows(cache_column(warm.out), "cached"), 3) << warm.out;
    EXPECT_EQ(slurp(dir / "b" / "s.txt"), slurp(dir / "plain" / "s.txt"));
    // A changed exporter pulls the series again, through the mapped node.
    const test::RunResult sums = run_orogen("run s.orogen --out c --set g.amount=3" + cache, env, dir.path());
    ASSERT_EQ(sums.exit_code, 0) << sums.err;
    EXPECT_EQ(count_rows(cache_column(sums.out), ""), 3) << sums.out;  // the export, g, and f (series are never kept)
    const test::RunResult plain3 = run_orogen("run s.orogen --out plain3 --no-cache --set g.amount=3", env, dir.path());
    EXPECT_EQ(slurp(dir / "c" / "s.txt"), slurp(dir / "plain3" / "s.txt"));
    EXPECT_NE(slurp(dir / "c" / "s.txt"), slurp(dir / "b" / "s.txt"));
}

TEST(CacheRun, TheDefaultFolderFollowsXdgCacheHomeAndTheEnvironmentCanTurnItOff) {
    Fixture f;
    const fs::path xdg = f.dir / "xdg";
    const test::RunResult r = f.run("a", "", "OROGEN_NO_CACHE= XDG_CACHE_HOME=" + q(xdg));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(entries(xdg / "orogen").size(), 6u);
    EXPECT_NE(r.out.find("nodes reused from " + (xdg / "orogen").string()), std::string::npos) << r.out;
    const fs::path xdg2 = f.dir / "xdg2";
    ASSERT_EQ(f.run("b", "", "OROGEN_NO_CACHE=1 XDG_CACHE_HOME=" + q(xdg2)).exit_code, 0);
    EXPECT_FALSE(fs::exists(xdg2));
    ASSERT_EQ(f.run("c", "--no-cache", "OROGEN_NO_CACHE= XDG_CACHE_HOME=" + q(xdg2)).exit_code, 0);
    EXPECT_FALSE(fs::exists(xdg2));
    const test::RunResult both = f.run("d", "--no-cache --cache " + q(xdg2));
    EXPECT_EQ(both.exit_code, 2);
    const test::RunResult bad = f.run("d", "--cache-size lots");
    EXPECT_EQ(bad.exit_code, 2);
    EXPECT_NE(bad.err.find("--cache-size needs a size"), std::string::npos) << bad.err;
}

TEST(CacheCommand, InfoCountsTheEntriesAndClearRemovesThemAndNothingElse) {
    Fixture f;
    ASSERT_EQ(f.cached("a").exit_code, 0);
    const auto all = entries(f.cache);
    ASSERT_EQ(all.size(), 6u);
    std::uint64_t bytes = 0;
    for (const auto& e : all) bytes += fs::file_size(e);
    // The least and most recently used entries, set apart by an hour each way.
    const auto now = fs::file_time_type::clock::now();
    fs::last_write_time(all[0], now - std::chrono::hours(30));
    fs::last_write_time(all[1], now + std::chrono::hours(2));
    const auto utc = [](fs::file_time_type t) {
        const std::time_t s = std::chrono::system_clock::to_time_t(std::chrono::file_clock::to_sys(t));
        std::tm tm{};
        ::gmtime_r(&s, &tm);
        char buf[64];
        std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S UTC", &tm);
        return std::string(buf);
    };
    const std::string oldest = utc(fs::last_write_time(all[0])), newest = utc(fs::last_write_time(all[1]));
    // Something of the user's in the folder, and a run's temporary.
    const fs::path mine = f.cache / "notes.txt";
    std::ofstream(mine) << "keep me";
    std::ofstream(f.cache / ".tmp-0123456789abcdef-1-0") << "half an entry";

    const test::RunResult info = run_orogen("cache info --cache " + q(f.cache) + " --cache-size 1M");
    ASSERT_EQ(info.exit_code, 0) << info.err;
    EXPECT_NE(info.out.find("cache folder: " + f.cache.string() + "\n"), std::string::npos) << info.out;
    EXPECT_NE(info.out.find("entries:      6 ("), std::string::npos) << info.out;
    EXPECT_NE(info.out.find("limit:        1.0 MiB (--cache-size)"), std::string::npos) << info.out;
    EXPECT_NE(info.out.find("oldest:       " + oldest), std::string::npos) << info.out;
    EXPECT_NE(info.out.find("newest:       " + newest), std::string::npos) << info.out;
    EXPECT_NE(info.out.find("temporaries:  1 (13 bytes)"), std::string::npos) << info.out;
    // The size, to the byte when small enough, else to a tenth of the unit.
    char expected_size[64];
    std::snprintf(expected_size, sizeof expected_size,
                  bytes < 1024             ? "%.0f bytes"
                      : bytes < (1u << 20) ? "%.1f KiB"
                                           : "%.1f MiB",
                  bytes < 1024             ? double(bytes)
                      : bytes < (1u << 20) ? double(bytes) / 1024
                                           : double(bytes) / (1 << 20));
    EXPECT_NE(info.out.find(std::string("entries:      6 (") + expected_size + ")"), std::string::npos) << info.out;

    const test::RunResult clear = run_orogen("cache clear --cache " + q(f.cache));
    ASSERT_EQ(clear.exit_code, 0) << clear.err;
    EXPECT_NE(clear.out.find("removed 6 cache entries (" + std::string(expected_size) + ")"), std::string::npos)
        << clear.out;
    EXPECT_TRUE(entries(f.cache).empty());
    EXPECT_TRUE(fs::exists(mine));  // not an entry: left alone
    EXPECT_TRUE(fs::exists(f.cache / ".tmp-0123456789abcdef-1-0"));  // a run in progress may be writing it
    const test::RunResult after = run_orogen("cache info --cache " + q(f.cache));
    EXPECT_NE(after.out.find("entries:      0 (0 bytes)"), std::string::npos) << after.out;
    EXPECT_EQ(after.out.find("oldest"), std::string::npos) << after.out;
    EXPECT_NE(after.out.find("limit:        2.0 GiB (the default"), std::string::npos) << after.out;
    // Cleared means recomputed: the next run reuses nothing.
    const test::RunResult again = f.cached("b");
    ASSERT_EQ(again.exit_code, 0) << again.err;
    EXPECT_EQ(count_rows(cache_column(again.out), ""), 6) << again.out;
}

TEST(CacheCommand, TheDefaultFolderAndBadUsage) {
    Fixture f;
    const fs::path xdg = f.dir / "xdg";
    ASSERT_EQ(f.run("a", "", "OROGEN_NO_CACHE= XDG_CACHE_HOME=" + q(xdg)).exit_code, 0);
    // Without --cache: the user's cache folder, even where OROGEN_NO_CACHE turns caching off for runs.
    const test::RunResult info = run_orogen("cache info", "XDG_CACHE_HOME=" + q(xdg));
    ASSERT_EQ(info.exit_code, 0) << info.err;
    EXPECT_NE(info.out.find("cache folder: " + (xdg / "orogen").string()), std::string::npos) << info.out;
    EXPECT_NE(info.out.find("entries:      6 ("), std::string::npos) << info.out;
    EXPECT_EQ(run_orogen("cache clear", "XDG_CACHE_HOME=" + q(xdg)).exit_code, 0);
    EXPECT_TRUE(entries(xdg / "orogen").empty());

    const test::RunResult missing = run_orogen("cache info --cache " + q(f.dir / "none"));
    EXPECT_EQ(missing.exit_code, 0) << missing.err;
    EXPECT_NE(missing.out.find("does not exist yet"), std::string::npos) << missing.out;
    EXPECT_FALSE(fs::exists(f.dir / "none"));  // looking creates nothing
    EXPECT_EQ(run_orogen("cache clear --cache " + q(f.dir / "none")).exit_code, 0);

    const test::RunResult file = run_orogen("cache info --cache " + q(f.spec));
    EXPECT_EQ(file.exit_code, 2);
    EXPECT_NE(file.err.find("is not a folder"), std::string::npos) << file.err;
    const test::RunResult no_verb = run_orogen("cache");
    EXPECT_EQ(no_verb.exit_code, 2);
    EXPECT_NE(no_verb.err.find("cache needs 'info' or 'clear'"), std::string::npos) << no_verb.err;
    const test::RunResult bad_verb = run_orogen("cache purge");
    EXPECT_EQ(bad_verb.exit_code, 2);
    EXPECT_NE(bad_verb.err.find("got 'purge'"), std::string::npos) << bad_verb.err;
    EXPECT_EQ(run_orogen("cache info --no-cache").exit_code, 2);
    const test::RunResult help = run_orogen("--help");
    EXPECT_NE(help.out.find("orogen cache clear [--cache DIR]"), std::string::npos) << help.out;
}

TEST(CacheRun, AnImporterAlwaysRunsAndWhatFollowsIsKeyedByWhatItRead) {
    TempDir dir;
    const auto make_png = [&](int seed) {
        dir.write("gen.orogen",
                  "orogen 1\ngrid 65 cell=10\nh = generate:diamond-square(amplitude=300)\n"
                  "export:png(h, path=\"in.png\", bits=16)\n");
        const test::RunResult r =
            run_orogen("run gen.orogen --out png --no-cache --seed " + std::to_string(seed), "", dir.path());
        ASSERT_EQ(r.exit_code, 0) << r.err;
        fs::copy_file(dir / "png" / "in.png", dir / "in.png", fs::copy_options::overwrite_existing);
    };
    make_png(1);
    dir.write("use.orogen",
              "orogen 1\ngrid 65 cell=10\nh = import:png(path=\"in.png\", low=0, high=300)\n"
              "s = erode:thermal(h, talus=30, iterations=5)\nexport:png(s, path=\"s.png\", bits=16)\n");
    const std::string cache = " --cache " + q(dir / "cache");
    ASSERT_EQ(run_orogen("run use.orogen --out a" + cache, "", dir.path()).exit_code, 0);
    const test::RunResult same = run_orogen("run use.orogen --out b" + cache, "", dir.path());
    ASSERT_EQ(same.exit_code, 0) << same.err;
    auto rows = cache_column(same.out);
    EXPECT_EQ(row(rows, "h"), "") << same.out;  // the file may have changed: it is read again
    EXPECT_EQ(row(rows, "s"), "cached") << same.out;  // it had not: the rest is reused
    EXPECT_EQ(slurp(dir / "b" / "s.png"), slurp(dir / "a" / "s.png"));

    make_png(2);  // the same path, other heights
    const test::RunResult changed = run_orogen("run use.orogen --out c" + cache, "", dir.path());
    ASSERT_EQ(changed.exit_code, 0) << changed.err;
    rows = cache_column(changed.out);
    EXPECT_EQ(row(rows, "s"), "") << changed.out;
    EXPECT_EQ(count_rows(rows, ""), 3) << changed.out;
    const test::RunResult plain = run_orogen("run use.orogen --out plain --no-cache", "", dir.path());
    EXPECT_EQ(slurp(dir / "c" / "s.png"), slurp(dir / "plain" / "s.png"));
    EXPECT_NE(slurp(dir / "c" / "s.png"), slurp(dir / "a" / "s.png"));
}

TEST(CacheRun, WhatACachedNodeSaidIsSaidAgainWithoutReadingItsValues) {
    TempDir dir;
    dir.write("p.orogen",
              "orogen 1\nseed 5\ngrid 65 cell=100\ncrust = generate:diamond-square(amplitude=100)\n"
              "plates = tectonics:plates(crust, plates=3, steps=20)\n"
              "export:png(plates, path=\"p.png\", bits=16)\n");
    const std::string cache = " --cache " + q(dir / "cache");
    const test::RunResult first = run_orogen("run p.orogen --out a" + cache, "", dir.path());
    ASSERT_EQ(first.exit_code, 0) << first.err;
    const auto said = first.err.find("plates: ");
    ASSERT_NE(said, std::string::npos) << first.err;
    const std::string line = first.err.substr(said, first.err.find('\n', said) - said);
    const test::RunResult again = run_orogen("run p.orogen --out b" + cache, "", dir.path());
    ASSERT_EQ(again.exit_code, 0) << again.err;
    EXPECT_NE(again.err.find(line + "\n"), std::string::npos) << again.err;
    const auto rows = cache_column(again.out);
    EXPECT_EQ(row(rows, "plates"), "cached") << again.out;  // not ", read": the messages have their own hash
}
