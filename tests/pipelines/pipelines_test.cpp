// Golden outputs of the shipped pipelines. When a change to a node alters them
// on purpose, regenerate with OROGEN_UPDATE_GOLDEN=1 build/tests/test_pipelines
// and say so in the commit. (pipelines/rmp-* and plates-* have their own golden
// tests in tests/plugins/rmp and tests/plugins/plates.)
#include <orogen/io.hpp>

#include <gtest/gtest.h>

#include "orogen_test.hpp"

#include <algorithm>
#include <map>

using namespace orogen;
using namespace orogen::test;
namespace fs = std::filesystem;

namespace {

struct Case {
    const char* name;       ///< pipelines/<name>.orogen
    const char* overrides;  ///< to keep the test short (the full run is what users get)
};

const Case cases[] = {
    {"default", "--set rivers.steps=400"},
    {"erosion-pipe-rain", "--set storm.steps=300 --set after.steps=50"},
    {"erosion-shapes-4.1", ""},
    {"erosion-thermal-4.3", ""},
    {"erosion-sph-4.1", "--set sph_crooked.steps=8 --set sph_pyramid.steps=8 --set sph_hemisphere.steps=8 "
                        "--set olsen_crooked.iterations=30 --set olsen_pyramid.iterations=30 "
                        "--set olsen_hemisphere.iterations=30 --set pipe_crooked.steps=60 --set pipe_pyramid.steps=60 "
                        "--set pipe_hemisphere.steps=60"},
    {"sph-rain", "--set rain.steps=30"},
};

/// relative path → sha256 of every file under `dir` but the manifest (which names plugin versions).
std::map<std::string, std::string> hashes(const fs::path& dir) {
    std::map<std::string, std::string> out;
    for (const auto& e : fs::recursive_directory_iterator(dir)) {
        if (!e.is_regular_file() || e.path().filename() == "manifest.json") continue;
        out[fs::relative(e.path(), dir).string()] = sha256_file(e.path());
    }
    return out;
}

}  // namespace

class Pipeline : public testing::TestWithParam<Case> {};

TEST_P(Pipeline, GivesTheSameBytesOnOneAndTwoThreadsAndMatchesItsGoldenHashes) {
    const Case& c = GetParam();
    TempDir dir;
    const fs::path spec = fs::path(OROGEN_SOURCE_DIR) / "pipelines" / (std::string(c.name) + ".orogen");
    for (const char* threads : {"1", "2"}) {
        const RunResult r = run_orogen("run " + q(spec) + " --out " + q(dir / threads) + " --threads " + threads +
                                       " --quiet " + c.overrides);
        ASSERT_EQ(r.exit_code, 0) << r.err;
    }
    const auto one = hashes(dir / "1");
    EXPECT_FALSE(one.empty());
    EXPECT_EQ(one, hashes(dir / "2"));
    EXPECT_EQ(slurp(dir / "1" / "manifest.json"), slurp(dir / "2" / "manifest.json"));

    const fs::path golden = fs::path(OROGEN_SOURCE_DIR) / "tests" / "pipelines" / "golden" / (std::string(c.name) + ".sha256");
    std::string text;  // the `sha256sum` format: "<hash>  <file>"
    for (const auto& [file, hash] : one) text += hash + "  " + file + "\n";
    if (std::getenv("OROGEN_UPDATE_GOLDEN")) std::ofstream(golden, std::ios::binary) << text;
    EXPECT_EQ(text, slurp(golden)) << "outputs of pipelines/" << c.name
                                   << ".orogen changed; if on purpose, rerun with OROGEN_UPDATE_GOLDEN=1";
}

INSTANTIATE_TEST_SUITE_P(Shipped, Pipeline, testing::ValuesIn(cases), [](const testing::TestParamInfo<Case>& info) {
    std::string n = info.param.name;
    std::replace_if(n.begin(), n.end(), [](char ch) { return !std::isalnum(static_cast<unsigned char>(ch)); }, '_');
    return n;
});
