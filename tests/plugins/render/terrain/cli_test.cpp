// The render nodes through the orogen binary: a spec renders, blooms and
// writes an 8-bit sRGB PNG; bad sizes, fields of view and cameras exit 2.
#include "render_support.hpp"

#include "orogen_test.hpp"

#include <gtest/gtest.h>

using namespace orogen::test;

namespace {

const auto* const no_display = ::testing::AddGlobalTestEnvironment(new NoDisplay);

const char* kHeader =
    "orogen 1\nseed 1\ngrid 65 cell=20\n"
    "hill = generate:shape(kind=cone, height=500)\n";

}  // namespace

TEST(RenderCli, ASpecRendersBloomsAndWritesAnSrgbPng) {
    TempDir dir;
    dir.write("r.orogen",
              std::string(kHeader) +
                  "frame = render:terrain(hill, width=80, height=48, sea=true, sea_level=20)\n"
                  "glow = render:bloom(frame)\n"
                  "x = render:blur(glow, axis=x, sigma=0.02)\n"
                  "export:png(x, path=\"frame.png\")\n");
    const RunResult r = run_orogen("run " + q(dir / "r.orogen") + " --out " + q(dir / "out"), "DISPLAY=");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string png = slurp(dir / "out/frame.png");
    ASSERT_GT(png.size(), 33u);
    EXPECT_EQ(png.substr(1, 3), "PNG");
    // IHDR: width 80, height 48, 8 bits, colour type 6 (RGBA).
    EXPECT_EQ(std::uint8_t(png[19]), 80);
    EXPECT_EQ(std::uint8_t(png[23]), 48);
    EXPECT_EQ(png[24], 8);
    EXPECT_EQ(png[25], 6);
}

TEST(RenderCli, BadSizesFieldsOfViewAndCamerasExitTwo) {
    TempDir dir;
    struct Case {
        std::string node, words;
    } cases[] = {
        {"render:terrain(hill, width=0)", "width"},
        {"render:terrain(hill, fov=180)", "fov"},
        {"render:terrain(hill, fov=0)", "fov"},
        {"render:terrain(hill, width=16384, height=16384, samples=8)", "MB"},
        {"render:terrain(hill, camera=look-at, from=(0.5, 0.5), from_height=-100)", "inside the terrain"},
        {"render:terrain(hill, camera=look-at, from=(0.5, 3), to=(0.5, 9), from_height=600)",
         "sees none of the terrain"},
        {"render:terrain(hill, grass_from=0.6, rock_from=0.5)", "in order"},
        // Issue 32, item 8: an orbit from below shows the underside; one inside the box looking up, the sky.
        {"render:terrain(hill, width=32, height=32, elevation=-60)", "below the terrain"},
        {"render:terrain(hill, width=32, height=32, target=(0.02, 0.02), distance=1, elevation=-80)",
         "sees none of the terrain"},
    };
    for (const auto& c : cases) {
        dir.write("bad.orogen", std::string(kHeader) + "f = " + c.node + "\nexport:png(f, path=\"f.png\")\n");
        const RunResult r = run_orogen("run " + q(dir / "bad.orogen") + " --out " + q(dir / "out"), "DISPLAY=");
        EXPECT_EQ(r.exit_code, 2) << c.node << "\n" << r.err;
        EXPECT_NE(r.err.find(c.words), std::string::npos) << c.node << "\n" << r.err;
    }
    // export:png's heightmap options do not apply to an image.
    dir.write("png.orogen",
              std::string(kHeader) +
                  "f = render:terrain(hill, width=16, height=16)\n"
                  "export:png(f, path=\"f.png\", bits=16)\n");
    const RunResult r = run_orogen("check " + q(dir / "png.orogen"));
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find("applies to a heightmap"), std::string::npos) << r.err;
}

TEST(RenderCli, ATurntableBloomedFrameByFrameBecomesAVideo) {
    TempDir dir;
    dir.write("t.orogen",
              std::string(kHeader) +
                  "spin = render:turntable(hill, frames=5, width=64, height=48, fps=10)\n"
                  "glow = render:bloom(spin)\n"
                  "export:video(glow, path=\"spin.mp4\", fps=10)\n"
                  "export:video(spin, path=\"spin.mpg\", fps=25)\n");
    const RunResult r = run_orogen("run " + q(dir / "t.orogen") + " --out " + q(dir / "out"), "DISPLAY=");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string probe =
        "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
        "stream=codec_name,nb_read_frames,width,r_frame_rate -of csv=p=0 ";
    FILE* p = ::popen((probe + q(dir / "out/spin.mp4") + " 2>&1").c_str(), "r");
    char buf[256] = {};
    ASSERT_NE(p, nullptr);
    const std::size_t n = std::fread(buf, 1, sizeof buf - 1, p);
    ::pclose(p);
    EXPECT_EQ(std::string(buf, n), "h264,64,10/1,5\n");
}

TEST(RenderCli, VideoCodecsAndExtensionsAreCheckedBeforeAnythingRuns) {
    TempDir dir;
    struct Case {
        std::string line, words;
    } cases[] = {
        {"export:video(spin, path=\"spin.avi\")", "extension"},
        {"export:video(spin, path=\"spin.mp4\", codec=mpeg2)", "change one of them"},
        {"export:video(spin, path=\"spin.mpg\", fps=17)", "MPEG-2"},
        {"export:video(hill, path=\"spin.mp4\")", "series"},
    };
    for (const auto& c : cases) {
        dir.write(
            "v.orogen",
            std::string(kHeader) + "spin = render:turntable(hill, frames=3, width=64, height=48)\n" + c.line + "\n");
        const RunResult r = run_orogen("check " + q(dir / "v.orogen"));
        EXPECT_EQ(r.exit_code, 2) << c.line << "\n" << r.err;
        EXPECT_NE(r.err.find(c.words), std::string::npos) << c.line << "\n" << r.err;
    }
    // An odd size is known at check time from the turntable's parameters.
    dir.write("odd.orogen",
              std::string(kHeader) +
                  "spin = render:turntable(hill, frames=3, width=65, height=48)\n"
                  "export:video(spin, path=\"spin.mp4\")\n");
    const RunResult r = run_orogen("check " + q(dir / "odd.orogen"));
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find("even"), std::string::npos) << r.err;
}

// Issue 32, item 7: a video's codec, frame rate and frame size mistakes are reported together.
TEST(RenderCli, EveryVideoMistakeIsReportedAtOnce) {
    TempDir dir;
    dir.write("v.orogen",
              std::string(kHeader) +
                  "spin = render:turntable(hill, frames=2, width=33, height=31)\n"
                  "export:video(spin, path=\"v.mpg\", codec=h264, fps=17)\n");
    const RunResult r = run_orogen("check " + q(dir / "v.orogen"), "DISPLAY=");
    EXPECT_EQ(r.exit_code, 2);
    for (const char* want : {"v.orogen:6:40: error: export:video: codec=h264 is written to .mp4 files",
                             "v.orogen:6:50: error: export:video: MPEG-2 takes only the frame rates",
                             "v.orogen:6:1: error: export:video: the frames are 33 × 31 pixels"})
        EXPECT_NE(r.err.find(want), std::string::npos) << "missing: " << want << "\n" << r.err;
    EXPECT_NE(r.err.find("3 errors in"), std::string::npos) << r.err;
}
