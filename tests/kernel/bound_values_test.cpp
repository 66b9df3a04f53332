// Values the caller binds to a run by name (orogen/session.hpp BoundValues, the Python module's node()): the
// checker reads them as values an earlier line made, the runner hands them to their readers with no file,
// a run that writes no files touches no folder, and the cache keys them by their content. Through the
// kernel's front door, as the CLI and the Python module.
#include <orogen/session.hpp>

#include <gtest/gtest.h>

#include "orogen_test.hpp"

#include <cstring>

using namespace orogen;
namespace fs = std::filesystem;

namespace {

const Session& session() {
    static const Session* s = new Session(fs::path(OROGEN_BINARY_DIR) / "bin" / "orogen");
    return *s;
}

/// `text` checked with `bound` described to the checker.
Checked check_text(const std::string& text, const BoundValues& bound, const fs::path& out_dir = "out") {
    CheckSettings settings;
    settings.out_dir = out_dir;
    settings.bound = &bound;
    return session().check(SpecText::of("<spec>", text, fs::current_path()), settings);
}

/// Runs `text` with `bound`, every named value kept; fails the test on a check error.
RunResult run_text(const std::string& text, BoundValues bound, RunSettings settings = {}) {
    Checked checked = check_text(text, bound, settings.out_dir.empty() ? fs::path("out") : settings.out_dir);
    EXPECT_TRUE(checked.ok()) << checked.report().text();
    checked.keep_named_values();
    settings.progress = nullptr;
    return session().run(checked, settings, std::move(bound));
}

const std::string made_in_the_spec =
    "orogen 1\nseed 6\ngrid 33x25 cell=10\ndem = generate:diamond-square(amplitude=90)\n"
    "t = erode:thermal(dem, talus=30, iterations=12)\n";
const std::string reading_a_bound_dem =
    "orogen 1\nseed 6\ngrid 33x25 cell=10\nt = erode:thermal(dem, talus=30, iterations=12)\n";

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

}  // namespace

TEST(KernelBoundValues, ANodeReadsABoundValueAsIfAnEarlierLineMadeItWithNoFileAnywhere) {
    RunSettings writing;
    test::TempDir dir;
    writing.out_dir = dir / "made";
    const RunResult whole = run_text(made_in_the_spec, {}, writing);
    ASSERT_EQ(whole.exit_code, 0) << whole.error;
    const auto dem = whole.values.at("dem").heightmap();
    const std::vector<float> dem_before = dem->heights();

    RunSettings quiet;  // out_dir empty: no folder, no staging, no manifest
    quiet.out_dir.clear();
    const fs::path cwd = fs::current_path();
    fs::current_path(dir / "made");
    const auto files_before = std::distance(fs::directory_iterator("."), fs::directory_iterator());
    const RunResult bound = run_text(reading_a_bound_dem, {{"dem", Value(dem)}}, quiet);
    const auto files_after = std::distance(fs::directory_iterator("."), fs::directory_iterator());
    fs::current_path(cwd);
    ASSERT_EQ(bound.exit_code, 0) << bound.error;
    EXPECT_EQ(files_after, files_before);  // no "out" folder made where it ran
    EXPECT_TRUE(bound.outputs.empty());
    // The same seed (label t, spec seed 6), the same input bits: the same result, layers and all.
    const Heightmap& a = *whole.values.at("t").heightmap();
    const Heightmap& b = *bound.values.at("t").heightmap();
    EXPECT_TRUE(same_bits(a.heights(), b.heights()));
    ASSERT_EQ(a.layer_names(), b.layer_names());
    for (const auto& name : a.layer_names()) {
        const auto la = a.layer(name), lb = b.layer(name);
        EXPECT_EQ(std::memcmp(la.data, lb.data, a.size() * sizeof(float)), 0) << name;
    }
    // The caller still held the bound value: thermal worked on a copy, and the caller's heights are as they were.
    EXPECT_TRUE(same_bits(dem->heights(), dem_before));
}

TEST(KernelBoundValues, TheCheckerKnowsABoundValuesLayersAndRefusesALineThatRedefinesIt) {
    auto hm = std::make_shared<Heightmap>(9, 9, 2.0, 1.0f);
    hm->layer("water", 0.5f);
    const BoundValues bound{{"dem", Value(hm)}};
    // Its layers: export:png's check finds 'water' and refuses 'sand', naming the layers the value has.
    EXPECT_TRUE(check_text("orogen 1\ngrid 9\nexport:png(dem, layer=\"water\", path=\"w.png\")\n", bound).ok());
    const Checked sand = check_text("orogen 1\ngrid 9\nexport:png(dem, layer=\"sand\", path=\"w.png\")\n", bound);
    ASSERT_FALSE(sand.ok());
    EXPECT_NE(sand.report().text().find("water"), std::string::npos) << sand.report().text();
    const Checked again = check_text("orogen 1\ngrid 9\ndem = generate:fault()\n", bound);
    ASSERT_FALSE(again.ok());
    EXPECT_NE(again.report().text().find("'dem' is a value the caller hands to the run"), std::string::npos)
        << again.report().text();
    EXPECT_EQ(again.report().count_line(), "1 error in <spec>\n");
    const Checked unbound = check_text(reading_a_bound_dem, {});  // without it, the name is undefined as ever
    EXPECT_NE(unbound.report().text().find("'dem' is not defined"), std::string::npos) << unbound.report().text();
}

TEST(KernelBoundValues, ARunThatWritesNoFilesRefusesANodeThatAsksForAnOutputPath) {
    auto hm = std::make_shared<Heightmap>(9, 9, 1.0, 1.0f);
    const std::string text = "orogen 1\ngrid 9\nexport:raw(dem, path=\"d.r32\")\n";
    const BoundValues bound{{"dem", Value(hm)}};
    const Checked checked = check_text(text, bound);
    ASSERT_TRUE(checked.ok()) << checked.report().text();
    EXPECT_TRUE(checked.writes_files());
    RunSettings quiet;
    quiet.out_dir.clear();
    quiet.progress = nullptr;
    const RunResult r = session().run(checked, quiet, bound);
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.error.find("declares no output path"), std::string::npos) << r.error;
    EXPECT_FALSE(check_text(reading_a_bound_dem, bound).writes_files());
}

TEST(KernelBoundValues, TheCacheKeysABoundValueByItsContentNotItsName) {
    test::TempDir dir;
    RunSettings options;
    options.out_dir = dir / "out";
    options.cache = cache::Settings{dir / "cache"};
    const auto dem = [](float top) {
        auto hm = std::make_shared<Heightmap>(33, 25, 10.0, 0.0f);
        for (std::size_t i = 0; i < hm->size(); ++i) hm->heights()[i] = float(i % 33) * top;
        return Value(hm);
    };
    const auto thermal_cached = [&](Value v) {
        const RunResult r = run_text(reading_a_bound_dem, {{"dem", std::move(v)}}, options);
        EXPECT_EQ(r.exit_code, 0) << r.error;
        return r.timings.at(0).cached;
    };
    EXPECT_FALSE(thermal_cached(dem(2.0f)));  // first time: runs
    EXPECT_TRUE(thermal_cached(dem(2.0f)));  // another heightmap with the same bits: reused
    EXPECT_FALSE(thermal_cached(dem(2.5f)));  // other bits: runs
}
