// The FFmpeg side of export:video.
#include "video_encoder.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/imgutils.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

namespace orogen::video {

Codec parse_codec(std::string_view name) {
    if (name == "h264") return Codec::h264;
    if (name == "mpeg2") return Codec::mpeg2;
    throw BadInput("unknown codec '" + std::string(name) + "'; use h264 (.mp4) or mpeg2 (.mpg)");
}

std::string_view extension_for(Codec codec) { return codec == Codec::h264 ? ".mp4" : ".mpg"; }

Codec codec_for(const std::filesystem::path& path) {
    const std::string ext = path.extension().string();
    if (ext == ".mp4") return Codec::h264;
    if (ext == ".mpg" || ext == ".mpeg") return Codec::mpeg2;
    throw BadInput("cannot tell the video format of '" + path.string() + "': use .mp4 (H.264) or .mpg (MPEG-2)");
}

namespace {

/// The standard MPEG-2 frame rates, as num/den.
const AVRational kMpeg2Rates[] = {{24000, 1001}, {24, 1}, {25, 1},       {30000, 1001},
                                  {30, 1},       {50, 1}, {60000, 1001}, {60, 1}};

bool rational_matches(double fps, AVRational r) { return std::abs(fps - av_q2d(r)) < 1e-3; }

AVRational rate_of(double fps) {
    for (AVRational r : kMpeg2Rates)
        if (rational_matches(fps, r)) return r;
    return av_d2q(fps, 1 << 16);
}

std::string av_error(int code) {
    char text[AV_ERROR_MAX_STRING_SIZE] = {};
    av_strerror(code, text, sizeof text);
    return text;
}

const AVCodec* find_encoder(Codec codec) {
    return avcodec_find_encoder(codec == Codec::h264 ? AV_CODEC_ID_H264 : AV_CODEC_ID_MPEG2VIDEO);
}

}  // namespace

std::string encoder_name(Codec codec) {
    const AVCodec* c = find_encoder(codec);
    return c ? c->name : "";
}

std::vector<Problem> problems(Codec codec, double fps, int width, int height) {
    std::vector<Problem> found;
    if (!(fps > 0) || fps > 240) {
        found.push_back({"fps", "the frame rate must be above 0 and at most 240 frames per second"});
    } else if (codec == Codec::mpeg2) {
        bool standard = false;
        for (AVRational r : kMpeg2Rates) standard = standard || rational_matches(fps, r);
        if (!standard)
            found.push_back({"fps", "MPEG-2 takes only the frame rates 23.976, 24, 25, 29.97, 30, 50, 59.94 and 60"});
    }
    if (width % 2 || height % 2)
        found.push_back({"",
                         "the frames are " + std::to_string(width) + " × " + std::to_string(height) +
                             " pixels; video with 4:2:0 colour needs even sizes (use an even width and height)"});
    if (codec == Codec::mpeg2 && (width > 4095 || height > 4095))
        found.push_back({"", "MPEG-2 frames are at most 4095 pixels a side"});
    return found;
}

std::string why_not(Codec codec, double fps, int width, int height) {
    std::string all;
    for (const Problem& p : problems(codec, fps, width, height)) all += (all.empty() ? "" : "; and ") + p.message;
    return all;
}

void encode_video(const std::filesystem::path& target, std::size_t count,
                  const std::function<Image(std::size_t)>& frame, const VideoSettings& s,
                  const std::function<void(std::size_t)>& progress) {
    if (count == 0) throw BadInput("export:video: the sequence has no frames");
    av_log_set_level(AV_LOG_ERROR);  // libx264 reports its statistics on stderr otherwise
    const AVCodec* encoder = find_encoder(s.codec);
    if (!encoder)
        throw Error(std::string("export:video: this FFmpeg has no ") + (s.codec == Codec::h264 ? "H.264" : "MPEG-2") +
                    " encoder (Debian's libavcodec59 has libx264 and mpeg2video)");

    Image first = frame(0);
    const int width = first.width, height = first.height;
    if (const std::string why = why_not(s.codec, s.fps, width, height); !why.empty())
        throw BadInput("export:video: " + why);

    AtomicFile file(target);
    file.stream().close();  // FFmpeg writes the temporary file by name
    const std::string temporary = file.temporary().string();

    // Everything FFmpeg allocates, freed in reverse order whatever happens.
    struct State {
        AVFormatContext* format = nullptr;
        AVCodecContext* codec = nullptr;
        AVFrame* picture = nullptr;
        AVPacket* packet = nullptr;
        SwsContext* scale = nullptr;
        ~State() {
            sws_freeContext(scale);
            av_packet_free(&packet);
            av_frame_free(&picture);
            avcodec_free_context(&codec);
            if (format) {
                if (format->pb) avio_closep(&format->pb);
                avformat_free_context(format);
            }
        }
    } st;
    auto check = [](int code, const char* what) {
        if (code < 0) throw Error(std::string("export:video: FFmpeg failed ") + what + ": " + av_error(code));
    };

    check(
        avformat_alloc_output_context2(&st.format, nullptr, s.codec == Codec::h264 ? "mp4" : "mpeg", temporary.c_str()),
        "to set up the container");
    st.format->flags |= AVFMT_FLAG_BITEXACT;  // no library versions or times that change between runs
    AVStream* stream = avformat_new_stream(st.format, nullptr);
    if (!stream) throw Error("export:video: FFmpeg could not add a video stream");
    st.codec = avcodec_alloc_context3(encoder);
    const AVRational rate = rate_of(s.fps);
    st.codec->width = width;
    st.codec->height = height;
    st.codec->pix_fmt = AV_PIX_FMT_YUV420P;
    st.codec->time_base = av_inv_q(rate);
    st.codec->framerate = rate;
    st.codec->gop_size = std::max(1, int(std::lround(2 * s.fps)));  // a key frame every 2 s
    st.codec->thread_count = 2;  // fixed, so the bytes do not depend on the machine's cores
    st.codec->colorspace = AVCOL_SPC_SMPTE170M;  // what libswscale's default RGB → YUV matrix is
    st.codec->color_primaries = AVCOL_PRI_BT709;  // sRGB's primaries
    st.codec->color_trc = AVCOL_TRC_IEC61966_2_1;  // sRGB's transfer
    st.codec->color_range = AVCOL_RANGE_MPEG;
    st.codec->flags |= AV_CODEC_FLAG_BITEXACT;
    if (st.format->oformat->flags & AVFMT_GLOBALHEADER) st.codec->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
    AVDictionary* options = nullptr;
    if (s.codec == Codec::h264) {
        // No B-frames: frame i is packet i, no negative decode times or edit list that
        // some players (and ffprobe's frame count) trip over; a few % larger files.
        st.codec->max_b_frames = 0;
        av_dict_set(&options, "preset", "veryfast", 0);
        av_dict_set(&options, "crf", std::to_string(s.quality).c_str(), 0);
    } else {
        st.codec->max_b_frames = 2;
        st.codec->flags |= AV_CODEC_FLAG_QSCALE;
        st.codec->global_quality = FF_QP2LAMBDA * std::max(2, std::min(31, s.quality / 6 + 1));
    }
    const int opened = avcodec_open2(st.codec, encoder, &options);
    av_dict_free(&options);
    check(opened, "to open the encoder");
    check(avcodec_parameters_from_context(stream->codecpar, st.codec), "to describe the stream");
    stream->time_base = st.codec->time_base;
    check(avio_open(&st.format->pb, temporary.c_str(), AVIO_FLAG_WRITE), "to open the file");
    AVDictionary* mux = nullptr;
    // No MP4 edit list: at some rates FFmpeg 5.1's wrote one a frame short, which hid the last frame.
    if (s.codec == Codec::h264) av_dict_set(&mux, "use_editlist", "0", 0);
    const int header = avformat_write_header(st.format, &mux);
    av_dict_free(&mux);
    check(header, "to write the header");

    st.picture = av_frame_alloc();
    st.packet = av_packet_alloc();
    st.picture->format = AV_PIX_FMT_YUV420P;
    st.picture->width = width;
    st.picture->height = height;
    check(av_frame_get_buffer(st.picture, 0), "to allocate a frame");
    st.scale = sws_getContext(width, height, AV_PIX_FMT_RGBA, width, height, AV_PIX_FMT_YUV420P,
                              SWS_BICUBIC | SWS_ACCURATE_RND | SWS_BITEXACT, nullptr, nullptr, nullptr);
    if (!st.scale) throw Error("export:video: libswscale could not set up the RGB → YUV conversion");

    auto drain = [&](bool final) {
        for (;;) {
            const int r = avcodec_receive_packet(st.codec, st.packet);
            if (r == AVERROR(EAGAIN) || (final && r == AVERROR_EOF)) return;
            check(r, "to encode");
            av_packet_rescale_ts(st.packet, st.codec->time_base, stream->time_base);
            st.packet->stream_index = stream->index;
            check(av_interleaved_write_frame(st.format, st.packet), "to write a frame");
        }
    };
    for (std::size_t i = 0; i < count; ++i) {
        Image image = i == 0 ? std::move(first) : frame(i);
        if (image.width != width || image.height != height)
            throw BadInput("export:video: frame " + std::to_string(i) + " is " + std::to_string(image.width) + " × " +
                           std::to_string(image.height) + " but the first was " + std::to_string(width) + " × " +
                           std::to_string(height) + "; every frame must have the same size");
        const std::vector<std::uint8_t> rgba = formats::srgb::to_srgb8(image, s.tonemap, s.exposure);
        image = Image{};  // the float frame is not needed any more
        check(av_frame_make_writable(st.picture), "to reuse a frame");
        const std::uint8_t* src[1] = {rgba.data()};
        const int stride[1] = {4 * width};
        sws_scale(st.scale, src, stride, 0, height, st.picture->data, st.picture->linesize);
        st.picture->pts = std::int64_t(i);
        check(avcodec_send_frame(st.codec, st.picture), "to encode");
        drain(false);
        if (progress) progress(i);
    }
    check(avcodec_send_frame(st.codec, nullptr), "to finish encoding");
    drain(true);
    check(av_write_trailer(st.format), "to finish the file");
    avio_closep(&st.format->pb);
    file.commit();
}

}  // namespace orogen::video
