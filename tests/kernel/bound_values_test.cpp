// Values the caller binds to a run by name (run/runner.hpp BoundValues, the Python module's node()): the
// checker reads them as values an earlier line made, the runner hands them to their readers with no file,
// a run that writes no files touches no folder, and the cache keys them by their content.
#include "run/loader.hpp"
#include "run/runner.hpp"
#include "spec/plan.hpp"
#include "spec/spec.hpp"

#include <gtest/gtest.h>

#include "orogen_test.hpp"

#include <cstring>

using namespace orogen;
namespace fs = std::filesystem;

namespace {

PluginSet& plugins() {
    static PluginSet* set = [] {
        auto* s = new PluginSet;
        s->load_all(fs::path(OROGEN_BINARY_DIR) / "bin" / "orogen");
        return s;
    }();
    return *set;
}

/// `text` checked with `bound` described to the checker; diagnostics in `diags`.
Plan check_text(const std::string& text, const BoundValues& bound, spec::Diagnostics& diags,
                const fs::path& out_dir = "out") {
    CheckOptions options;
    options.out_dir = out_dir;
    for (const auto& [name, v] : bound) options.bound[name] = describe_bound(v);
    auto source = std::make_shared<spec::Source>("<spec>", text);
    const spec::Spec parsed = spec::parse(source, diags);
    return check(parsed, plugins().registry(), fs::current_path() / "<spec>", options, diags);
}

/// Runs `text` with `bound`, every named value kept; fails the test on a check error.
RunResult run_text(const std::string& text, BoundValues bound, RunOptions options = {}) {
    spec::Diagnostics diags;
    Plan plan = check_text(text, bound, diags, options.out_dir.empty() ? fs::path("out") : options.out_dir);
    EXPECT_FALSE(diags.has_errors()) << diags.format();
    for (const PlannedNode& n : plan.nodes)
        if (!n.value_name.empty()) plan.last_use[n.value_name] = plan.nodes.size();
    options.plugins = plugins().plugins();
    return run(plan, options, std::move(bound));
}

const std::string made_in_the_spec = "orogen 1\nseed 6\ngrid 33x25 cell=10\ndem = generate:diamond-square(amplitude=90)\n"
                                     "t = erode:thermal(dem, talus=30, iterations=12)\n";
const std::string reading_a_bound_dem = "orogen 1\nseed 6\ngrid 33x25 cell=10\nt = erode:thermal(dem, talus=30, iterations=12)\n";

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

}  // namespace

TEST(KernelBoundValues, ANodeReadsABoundValueAsIfAnEarlierLineMadeItWithNoFileAnywhere) {
    RunOptions writing;
    test::TempDir dir;
    writing.out_dir = dir / "made";
    const RunResult whole = run_text(made_in_the_spec, {}, writing);
    ASSERT_EQ(whole.exit_code, 0) << whole.error;
    const auto dem = whole.values.at("dem").heightmap();
    const std::vector<float> dem_before = dem->heights();

    RunOptions quiet;  // out_dir empty: no folder, no staging, no manifest
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
    const ValueInfo info = describe_bound(bound.at("dem"));
    EXPECT_EQ(info.layers.size(), 1u);
    EXPECT_EQ(info.layers.count("water"), 1u);
    EXPECT_EQ(info.cell, 2.0);
    EXPECT_EQ(info.width, 9);
    spec::Diagnostics again;
    check_text("orogen 1\ngrid 9\ndem = generate:fault()\n", bound, again);
    ASSERT_TRUE(again.has_errors());
    EXPECT_NE(again.format().find("'dem' is a value the caller hands to the run"), std::string::npos) << again.format();
    spec::Diagnostics unbound;  // without it, the name is undefined as ever
    check_text(reading_a_bound_dem, {}, unbound);
    EXPECT_NE(unbound.format().find("'dem' is not defined"), std::string::npos) << unbound.format();
}

TEST(KernelBoundValues, ARunThatWritesNoFilesRefusesANodeThatAsksForAnOutputPath) {
    auto hm = std::make_shared<Heightmap>(9, 9, 1.0, 1.0f);
    spec::Diagnostics diags;
    const std::string text = "orogen 1\ngrid 9\nexport:raw(dem, path=\"d.r32\")\n";
    const BoundValues bound{{"dem", Value(hm)}};
    Plan plan = check_text(text, bound, diags);
    ASSERT_FALSE(diags.has_errors()) << diags.format();
    EXPECT_TRUE(writes_files(plan));
    RunOptions quiet;
    quiet.out_dir.clear();
    const RunResult r = run(plan, quiet, bound);
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.error.find("declares no output path"), std::string::npos) << r.error;
    spec::Diagnostics d2;
    EXPECT_FALSE(writes_files(check_text(reading_a_bound_dem, bound, d2)));
}

TEST(KernelBoundValues, TheCacheKeysABoundValueByItsContentNotItsName) {
    test::TempDir dir;
    RunOptions options;
    options.out_dir = dir / "out";
    options.cache = cache::Settings{dir / "cache"};
    for (const auto* n : plugins().registry().nodes())
        for (const auto& p : plugins().plugins())
            if (p.file == plugins().registry().provider(n->qualified_name())) options.node_plugins[n->qualified_name()] = p;
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
    EXPECT_TRUE(thermal_cached(dem(2.0f)));   // another heightmap with the same bits: reused
    EXPECT_FALSE(thermal_cached(dem(2.5f)));  // other bits: runs
}
