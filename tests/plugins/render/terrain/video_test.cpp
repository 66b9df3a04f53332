// export:video's encoder: H.264 .mp4 and MPEG-2 .mpg that FFmpeg's own tools
// read back (ffprobe, ffmpeg), first frame equal to its PNG, atomic writes.
#include "render_support.hpp"
#include "render_terrain.hpp"
#include "video_encoder.hpp"

#include "orogen_test.hpp"

#include <orogen/error.hpp>

#include <gtest/gtest.h>

#include <cstdio>
#include <map>

using namespace orogen;
using namespace orogen::test;
namespace fs = std::filesystem;

namespace {

const auto* const no_display = ::testing::AddGlobalTestEnvironment(new NoDisplay);

std::string run(const std::string& cmd) {
    std::string out;
    FILE* p = ::popen(cmd.c_str(), "r");
    if (!p) return out;
    char buf[4096];
    std::size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
    ::pclose(p);
    return out;
}

std::map<std::string, std::string> probe(const fs::path& video) {
    const std::string text =
        run("ffprobe -v error -select_streams v:0 -count_frames -show_entries "
            "stream=codec_name,width,height,r_frame_rate,nb_read_frames -of default=nw=1 " +
            q(video) + " 2>&1");
    std::map<std::string, std::string> m;
    std::size_t start = 0;
    while (start < text.size()) {
        const std::size_t end = text.find('\n', start);
        const std::string line = text.substr(start, end == std::string::npos ? std::string::npos : end - start);
        const auto eq = line.find('=');
        if (eq != std::string::npos) m[line.substr(0, eq)] = line.substr(eq + 1);
        if (end == std::string::npos) break;
        start = end + 1;
    }
    return m;
}

// A turntable of a small hill: frame i seen from azimuth 30·i degrees.
struct Turntable {
    std::shared_ptr<render::TerrainRenderer> renderer;
    Turntable() {
        auto hm = std::make_shared<Heightmap>(65, 65, 20.0);
        for (int y = 0; y < 65; ++y)
            for (int x = 0; x < 65; ++x)
                hm->view().at(x, y) = float(400 * std::exp(-((x - 32) * (x - 32) + (y - 30) * (y - 30)) / 300.0));
        renderer = std::make_shared<render::TerrainRenderer>(hm, render::Style{});
    }
    Image frame(std::size_t i, int w = 96, int h = 64) const {
        render::Camera c;
        c.azimuth = 30.0 * double(i);
        return renderer->render(w, h, c);
    }
};

}  // namespace

TEST(Video, FfprobeReadsTheH264AndMpeg2FilesBack) {
    ASSERT_EQ(std::system("ffprobe -version >/dev/null 2>&1"), 0) << "ffprobe is missing: apt-get install ffmpeg";
    TempDir dir;
    const Turntable t;
    const auto frame = [&](std::size_t i) { return t.frame(i); };
    video::encode_video(dir / "t.mp4", 12, frame, {.codec = video::Codec::h264, .fps = 24});
    video::encode_video(dir / "t.mpg", 12, frame, {.codec = video::Codec::mpeg2, .fps = 25});
    auto m = probe(dir / "t.mp4");
    EXPECT_EQ(m["codec_name"], "h264");
    EXPECT_EQ(m["width"], "96");
    EXPECT_EQ(m["height"], "64");
    EXPECT_EQ(m["r_frame_rate"], "24/1");
    EXPECT_EQ(m["nb_read_frames"], "12");
    m = probe(dir / "t.mpg");
    EXPECT_EQ(m["codec_name"], "mpeg2video");
    EXPECT_EQ(m["r_frame_rate"], "25/1");
    EXPECT_EQ(m["nb_read_frames"], "12");
    // The same frames twice: the same bytes.
    video::encode_video(dir / "u.mp4", 12, frame, {.codec = video::Codec::h264, .fps = 24});
    EXPECT_EQ(slurp(dir / "t.mp4"), slurp(dir / "u.mp4"));
}

TEST(Video, TheFirstFrameMatchesThePngOfTheSameFrame) {
    TempDir dir;
    const Turntable t;
    video::encode_video(dir / "t.mp4", 6, [&](std::size_t i) { return t.frame(i, 128, 96); }, {.fps = 30});
    const auto png = formats::srgb::to_srgb8(t.frame(0, 128, 96), formats::srgb::Tonemap::aces, 0);
    // FFmpeg decodes frame 0 to RGB with the matrix the file is tagged with.
    const std::string raw = run("ffmpeg -v error -i " + q(dir / "t.mp4") +
                                " -frames:v 1 -vf scale=in_color_matrix=bt601:in_range=tv -f rawvideo -pix_fmt rgba -");
    ASSERT_EQ(raw.size(), png.size());
    std::vector<std::uint8_t> decoded(raw.begin(), raw.end());
    // H.264 at crf 18 with 4:2:0 chroma: about 35–40 dB on a frame this small; a wrong frame,
    // flipped rows or swapped channels fall below 20 dB.
    EXPECT_GE(psnr(decoded, png), 30.0);
}

TEST(Video, AFailedEncodeLeavesNoFile) {
    TempDir dir;
    const Turntable t;
    EXPECT_THROW(video::encode_video(dir / "t.mp4", 10,
                                     [&](std::size_t i) {
                                         if (i == 4) throw Error("the renderer failed");
                                         return t.frame(i);
                                     },
                                     {}),
                 Error);
    EXPECT_TRUE(fs::is_empty(dir.path())) << "a partial video or temporary file was left";
    // A frame of another size is refused the same way.
    EXPECT_THROW(
        video::encode_video(dir / "t.mp4", 3, [&](std::size_t i) { return t.frame(i, 96 + 2 * int(i), 64); }, {}),
        BadInput);
    EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(Video, CodecsExtensionsAndRatesAreChecked) {
    EXPECT_EQ(video::codec_for("a/b.mp4"), video::Codec::h264);
    EXPECT_EQ(video::codec_for("b.mpg"), video::Codec::mpeg2);
    EXPECT_THROW(video::codec_for("b.avi"), BadInput);
    EXPECT_THROW(video::parse_codec("vp9"), BadInput);
    EXPECT_EQ(video::why_not(video::Codec::h264, 30, 1920, 1080), "");
    EXPECT_NE(video::why_not(video::Codec::h264, 30, 1921, 1080).find("even"), std::string::npos);
    EXPECT_NE(video::why_not(video::Codec::mpeg2, 17, 640, 480).find("MPEG-2"), std::string::npos);
    EXPECT_EQ(video::why_not(video::Codec::mpeg2, 29.97, 640, 480), "");
    EXPECT_FALSE(video::encoder_name(video::Codec::h264).empty());
}
