// Golden outputs of the shipped pipelines. When a change to a node alters them
// on purpose, regenerate with OROGEN_UPDATE_GOLDEN=1 build/tests/test_pipelines
// and say so in the commit. (pipelines/rmp-* and plates-* have their own golden
// tests in tests/plugins/generate/rmp and tests/plugins/tectonics/plates.)
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
    const char* name;  ///< pipelines/<name>.orogen
    const char* overrides;  ///< to keep the test short (the full run is what users get)
    /// Appended in the sanitizer builds (CI's ASan+UBSan phase), where the erosion loops run 10-25x slower:
    /// fewer steps, every node still run. A case with these is not compared with its golden hashes there
    /// (1 and 2 threads still must agree); the others are, under clang as under GCC.
    const char* sanitized = "";
};

#ifdef OROGEN_SANITIZED
constexpr bool sanitized_build = true;
#else
constexpr bool sanitized_build = false;
#endif

const Case cases[] = {
    {"default",
     "--set range.dt=3e5 --set beauty.width=320 --set beauty.height=180 --set beauty.samples=1 "
     "--set spin.frames=4 --set spin.width=160 --set spin.height=90",
     "--set plates.steps=200 --set range.dt=1e6 --set scree.iterations=10 --set spin.frames=2"},
    {"erosion-pipe-rain", "--set storm.steps=300 --set after.steps=50", "--set storm.steps=40 --set after.steps=10"},
    {"erosion-shapes-4.1", "",
     "--set olsen_crooked.iterations=40 --set olsen_pyramid.iterations=40 --set olsen_hemisphere.iterations=40 "
     "--set pipe_crooked.steps=60 --set pipe_pyramid.steps=60 --set pipe_hemisphere.steps=60"},
    {"erosion-thermal-4.3", ""},
    {"orogeny", "--set range.dt=3e5", "--set plates.steps=200 --set range.dt=1e6 --set scree.iterations=10"},
    {"erosion-sph-4.1",
     "--set sph_crooked.steps=8 --set sph_pyramid.steps=8 --set sph_hemisphere.steps=8 "
     "--set olsen_crooked.iterations=30 --set olsen_pyramid.iterations=30 "
     "--set olsen_hemisphere.iterations=30 --set pipe_crooked.steps=60 --set pipe_pyramid.steps=60 "
     "--set pipe_hemisphere.steps=60"},
    {"sph-rain", "--set rain.steps=30"},
    {"starter", "", "--set range.dt=5e5"},
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
                                       " --quiet " + c.overrides + " " + (sanitized_build ? c.sanitized : ""));
        ASSERT_EQ(r.exit_code, 0) << r.err;
    }
    const auto one = hashes(dir / "1");
    EXPECT_FALSE(one.empty());
    EXPECT_EQ(one, hashes(dir / "2"));
    EXPECT_EQ(slurp(dir / "1" / "manifest.json"), slurp(dir / "2" / "manifest.json"));

    const fs::path golden =
        fs::path(OROGEN_SOURCE_DIR) / "tests" / "pipelines" / "golden" / (std::string(c.name) + ".sha256");
    std::string text;  // the `sha256sum` format: "<hash>  <file>"
    for (const auto& [file, hash] : one) {
        // Frames drawn by llvmpipe repeat exactly on one machine (checked above) but their
        // bytes follow the CPU's vector width (AVX2 or AVX-512 code); tests/plugins/render/terrain
        // compares rendered frames to golden images by PSNR instead.
        if (file == "beauty.png" || file == "turntable.mp4") continue;
        text += hash + "  " + file + "\n";
    }
    if (std::string(c.name) == "default") {
        EXPECT_EQ(one.count("beauty.png"), 1u);
        EXPECT_EQ(one.count("turntable.mp4"), 1u);
    }
    if (sanitized_build && *c.sanitized) return;  // shortened: no golden for these sizes (above)
    if (std::getenv("OROGEN_UPDATE_GOLDEN")) std::ofstream(golden, std::ios::binary) << text;
    EXPECT_EQ(text, slurp(golden)) << "outputs of pipelines/" << c.name
                                   << ".orogen changed; if on purpose, rerun with OROGEN_UPDATE_GOLDEN=1";
}

INSTANTIATE_TEST_SUITE_P(Shipped, Pipeline, testing::ValuesIn(cases), [](const testing::TestParamInfo<Case>& info) {
    std::string n = info.param.name;
    std::replace_if(
        n.begin(), n.end(), [](char ch) { return !std::isalnum(static_cast<unsigned char>(ch)); }, '_');
    return n;
});

// Every spec in pipelines/ checks out with the plugins built here, so none of
// them rots when a node's parameters change.
TEST(Pipelines, EveryShippedSpecChecks) {
    std::vector<fs::path> specs;
    for (const auto& e : fs::directory_iterator(fs::path(OROGEN_SOURCE_DIR) / "pipelines"))
        if (e.path().extension() == ".orogen") specs.push_back(e.path());
    std::sort(specs.begin(), specs.end());
    EXPECT_GE(specs.size(), 10u);
    for (const auto& spec : specs) {
        const RunResult r = run_orogen("check " + q(spec));
        EXPECT_EQ(r.exit_code, 0) << spec.filename() << ":\n" << r.err;
    }
}

// The time-lapse pipeline, small: the plates' snapshots become video frames
// through the kernel's series mapping (render:terrain and render:bloom run
// once per snapshot); ffprobe counts them.
TEST(Pipelines, ThePlatesTimelapseBecomesAVideoWithAFramePerSnapshot) {
    TempDir dir;
    const fs::path spec = fs::path(OROGEN_SOURCE_DIR) / "pipelines" / "plates-timelapse.orogen";
    const RunResult r = run_orogen("run " + q(spec) + " --out " + q(dir / "out") +
                                   " --quiet --set plates.steps=60 --set plates.timelapse_every=20"
                                   " --set frames.width=160 --set frames.height=90");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string probe =
        "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
        "stream=nb_read_frames,width,height -of csv=p=0 " +
        q(dir / "out" / "plates-timelapse.mp4") + " > " + q(dir / "probe.txt");
    ASSERT_EQ(std::system(probe.c_str()), 0);
    EXPECT_EQ(slurp(dir / "probe.txt"), "160,90,4\n");  // steps 0, 20, 40 and 60
}
