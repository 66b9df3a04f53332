// export:video — an image series (render:turntable, a rendered time-lapse) as
// H.264 .mp4 or MPEG-2 .mpg, frames pulled one at a time into the encoder.
#include "video_encoder.hpp"

#include <orogen/error.hpp>
#include <orogen/plugin.hpp>

using namespace orogen;

namespace {

// Every mistake at once: a codec that does not match the path, a frame rate the codec refuses, odd sizes.
void check(CheckContext& ctx) {
    const std::filesystem::path path = ctx.text("path");
    video::Codec codec{};
    try {
        codec = video::codec_for(path);
    } catch (const BadInput& e) {
        ctx.error("path", e.what());
        return;  // no codec to check the rest against
    }
    const std::string& named = ctx.text("codec");
    if (named != "auto" && video::parse_codec(named) != codec)
        ctx.error("codec",
                  "codec=" + named + " is written to " + std::string(video::extension_for(video::parse_codec(named))) +
                      " files, but path is " + path.filename().string() + "; change one of them");
    const ValueInfo* in = ctx.input(0);
    const int w = in && in->width > 0 ? in->width : 2, h = in && in->height > 0 ? in->height : 2;
    for (const video::Problem& p : video::problems(codec, ctx.real("fps"), w, h)) ctx.error(p.param, p.message);
}

NodeOutputs run(NodeContext& ctx) {
    const Series& frames = *ctx.input(0).series();
    video::VideoSettings s;
    s.codec = video::codec_for(ctx.text("path"));
    s.fps = ctx.real("fps");
    s.quality = int(ctx.integer("quality"));
    s.tonemap = formats::srgb::parse_tonemap(ctx.text("tonemap"));
    s.exposure = ctx.real("exposure");
    const std::size_t n = frames.size();
    video::encode_video(
        ctx.output_path(ctx.text("path")), n,
        [&](std::size_t i) {
            ctx.check_cancelled();
            const Value v = frames.at(i);
            return *v.image();
        },
        s, [&](std::size_t i) { ctx.progress(double(i + 1) / double(n)); });
    return {};
}

}  // namespace

OROGEN_PLUGIN("export-video", "0.1.0", registry) {
    registry.add({
        .kind = "export",
        .name = "video",
        .summary = "write an image series (render:turntable, a rendered time-lapse) as H.264 .mp4 or MPEG-2 .mpg",
        .description =
            "FFmpeg's libavcodec/libavformat encode the frames as they are made (never all held); the file appears\n"
            "only when complete. Colours as export:png (tone curve, then sRGB), so a frame matches its PNG.\n"
            "MPEG-2 (the thesis's format) takes only the standard rates 23.976, 24, 25, 29.97, 30, 50, 59.94, 60.",
        .inputs = {{"frames", ValueType::image, Need::required, "the frames", Many::series}},
        .output = ValueType::none,
        .params =
            {
                Param::path("path", PathRole::output, {".mp4", ".mpg", ".mpeg"})
                    .help("output file (.mp4: H.264, .mpg: MPEG-2)"),
                Param::choice("codec", {"auto", "h264", "mpeg2"}, "auto")
                    .help("must match the extension; auto: from it"),
                Param::real("fps", 30.0).min(0, true).max(240).unit("1/s").help("frames per second"),
                Param::integer("quality", 18)
                    .min(0)
                    .max(51)
                    .help("H.264 constant rate factor (lower is better; 18 looks lossless); MPEG-2 quantiser = "
                          "quality/6 + 1"),
                Param::choice("tonemap", {"clamp", "reinhard", "aces"}, "aces").help("as export:png"),
                Param::real("exposure", 0.0).min(-20).max(20).help("as export:png: colours × 2^exposure first"),
            },
        .check = check,
        .run = run,
    });
}
