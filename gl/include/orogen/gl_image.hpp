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

/// Upload an image as an RGBA32F texture, its rows in the order they are
/// stored (image row y is texel row y: the image's top is GL's bottom). The
/// image-space passes (bloom, blur) neither know nor care, so an image goes up
/// and, read back with Rows::as_stored, comes down without being flipped or
/// copied. 8-bit sRGB images are decoded to linear first. Filtering: linear,
/// clamped to edge.
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

/// How read_rgba32f orders the rows: as_stored keeps GL's row y as image row
/// y (for a target drawn from an uploaded image); flip turns a scene drawn
/// with GL's usual bottom-up window into an image with its top row first.
enum class Rows { as_stored, flip };

/// Read the currently bound read framebuffer's colour as a linear float image.
Image read_rgba32f(int width, int height, Rows rows);

/// Draw the full-screen triangle (shaders/fullscreen.vert) with the bound program.
void draw_fullscreen();

/// Linear value of an 8-bit sRGB code (IEC 61966-2-1).
float srgb_to_linear(std::uint8_t code);

/// Check `width` × `height` against the context's limit and the memory an
/// RGBA32F frame and its working copies need (`bytes_per_pixel` in all);
/// throws orogen::BadInput naming `who`, the limit and the memory.
void check_frame_size(std::string_view who, int width, int height, double bytes_per_pixel);

}  // namespace orogen::gl
