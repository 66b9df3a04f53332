// orogen/gl_image.hpp — orogen::Image in and out of the GL context: float
// textures, offscreen float targets, full-screen passes and read-back. Call
// everything here under a gl::Lock. No GL headers: names are unsigned ints.
#pragma once

#include <orogen/values.hpp>

#include <string_view>

namespace orogen::gl {

/// A 2-D texture (RGBA32F unless said otherwise), deleted with the object.
struct Texture {
    unsigned id = 0;
    int width = 0, height = 0;
    Texture() = default;
    Texture(Texture&& o) noexcept : id(o.id), width(o.width), height(o.height) { o.id = 0; }
    Texture& operator=(Texture&& o) noexcept;
    ~Texture();
};

/// Upload an image as an RGBA32F texture (rows top to bottom become GL's
/// bottom-up rows flipped, so texel (x, 0) is the bottom row). 8-bit sRGB
/// images are decoded to linear first. Filtering: linear, clamped to edge.
Texture upload(const Image& image);

/// An offscreen RGBA32F colour target, with a 32-bit float depth buffer if asked.
struct Target {
    unsigned framebuffer = 0;
    unsigned depth = 0;  ///< renderbuffer, 0 without depth
    Texture colour;
    Target() = default;
    Target(int width, int height, bool with_depth = false);
    Target(Target&& o) noexcept : framebuffer(o.framebuffer), depth(o.depth), colour(std::move(o.colour)) {
        o.framebuffer = 0;
        o.depth = 0;
    }
    Target& operator=(Target&& o) noexcept;
    ~Target();
    int width() const { return colour.width; }
    int height() const { return colour.height; }
    void bind() const;  ///< as the draw framebuffer, viewport covering it
};

/// Read the currently bound read framebuffer's colour as a linear float image
/// (rows top to bottom).
Image read_rgba32f(int width, int height);

/// Draw the full-screen triangle (shaders/fullscreen.vert) with the bound program.
void draw_fullscreen();

/// Linear value of an 8-bit sRGB code (IEC 61966-2-1).
float srgb_to_linear(std::uint8_t code);

/// Check `width` × `height` against the context's limit and the memory an
/// RGBA32F frame and its working copies need (`bytes_per_pixel` in all);
/// throws orogen::BadInput naming `who`, the limit and the memory.
void check_frame_size(std::string_view who, int width, int height, double bytes_per_pixel);

}  // namespace orogen::gl
