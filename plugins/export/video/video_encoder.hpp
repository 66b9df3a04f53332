// video_encoder.hpp — frames into a video file with FFmpeg's libraries
// (libavcodec, libavformat, libswscale from Debian): H.264 in .mp4 or the
// thesis's MPEG-2 in .mpg. Frames are pulled one at a time from a callback
// and streamed into the encoder, so memory stays at a few frames whatever the
// length. The file is written under a temporary name and renamed when
// complete: a failed encode leaves no partial video.
//
// Plain C++ over orogen::Image; FFmpeg's headers stay in video_encoder.cpp.
#pragma once

#include <orogen/formats/image_srgb.hpp>

#include <orogen/values.hpp>

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace orogen::video {

enum class Codec { h264, mpeg2 };

/// "h264" | "mpeg2"; throws orogen::BadInput naming the choices otherwise.
Codec parse_codec(std::string_view name);
/// The file extension each codec is written in: ".mp4" or ".mpg".
std::string_view extension_for(Codec codec);
/// The codec for a file name's extension (.mp4 → h264, .mpg/.mpeg → mpeg2);
/// throws orogen::BadInput for any other extension.
Codec codec_for(const std::filesystem::path& path);

/// One reason `codec` cannot encode a video, and the parameter it concerns
/// ("fps", or "" for the frames' size).
struct Problem {
    std::string param;
    std::string message;
};

/// Every reason `codec` cannot encode at `fps` and width × height, all at once
/// (odd sizes: 4:2:0 chroma needs even ones; MPEG-2 takes only the standard
/// frame rates 23.976, 24, 25, 29.97, 30, 50, 59.94 and 60, and at most 4095
/// pixels a side). Empty if it can.
std::vector<Problem> problems(Codec codec, double fps, int width, int height);

/// The problems above in one sentence, "" if none.
std::string why_not(Codec codec, double fps, int width, int height);

struct VideoSettings {
    Codec codec = Codec::h264;
    double fps = 30.0;  ///< frames per second
    /// Quality: H.264 constant rate factor (0 lossless .. 51; 18 looks lossless) / MPEG-2 quantiser (2 best .. 31).
    int quality = 18;
    formats::srgb::Tonemap tonemap = formats::srgb::Tonemap::aces;  ///< as export:png, so frames match the PNGs
    double exposure = 0.0;
};

/// Encode frames 0 .. count−1, each made by `frame(i)` when needed (all the
/// same size), into `target`. `progress(i)` (optional) is called after frame i.
/// Throws orogen::BadInput for a size or rate the codec cannot take, a frame
/// of another size, or no frames; orogen::Error if FFmpeg fails (its message
/// included). Deterministic: a fixed encoder thread count, no timestamps of
/// the wall clock in the file.
void encode_video(const std::filesystem::path& target, std::size_t count,
                  const std::function<Image(std::size_t)>& frame, const VideoSettings& settings,
                  const std::function<void(std::size_t)>& progress = {});

/// "libx264" / "mpeg2video": the encoder libavcodec picks for `codec`, or "" if none.
std::string encoder_name(Codec codec);

}  // namespace orogen::video
