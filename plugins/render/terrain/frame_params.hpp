// frame_params.hpp — render:terrain's frame parameters (size,
// camera) and the camera's placement; beside its one user (a second render node that makes frames would
// move it to libs/).
#pragma once

#include <orogen/node.hpp>

#include <unistd.h>

#include <cmath>
#include <string>
#include <vector>

namespace orogen::render {

/// The largest frame side OSMesa's llvmpipe draws (GL_MAX_RENDERBUFFER_SIZE).
inline constexpr int kMaxFrameSide = 16384;

inline std::vector<Param> frame_size_params(int width, int height) {
    return {
        Param::integer("width", width).min(1).max(kMaxFrameSide).unit("px").help("frame width (4K: 3840)"),
        Param::integer("height", height).min(1).max(kMaxFrameSide).unit("px").help("frame height (4K: 2160)"),
    };
}

/// At check time: the frame must fit in half of physical memory at
/// `bytes_per_pixel`; reports at "width" saying how much it needs.
inline void check_frame_memory(CheckContext& ctx, double bytes_per_pixel) {
    const double w = double(ctx.integer("width")), h = double(ctx.integer("height"));
    const double need = w * h * bytes_per_pixel;
    const double memory = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE));
    if (need > memory / 2)
        ctx.error("width",
                  "a " + std::to_string(std::int64_t(w)) + " × " + std::to_string(std::int64_t(h)) +
                      " frame needs about " + std::to_string(std::int64_t(std::ceil(need / 1e6))) +
                      " MB, more than half of this machine's " + std::to_string(std::int64_t(memory / 1e6)) +
                      " MB of memory; use a smaller width and height");
}

}  // namespace orogen::render
