// orogen::Image ⇄ GL textures and framebuffers.
#define GL_GLEXT_PROTOTYPES 1
#include <orogen/gl_context.hpp>
#include <orogen/gl_image.hpp>

#include <orogen/error.hpp>
#include <orogen/parallel.hpp>

#include <GL/gl.h>
#include <GL/glext.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

namespace orogen::gl {

Texture& Texture::operator=(Texture&& o) noexcept {
    if (this != &o) {
        if (id) glDeleteTextures(1, &id);
        id = o.id;
        width = o.width;
        height = o.height;
        o.id = 0;
    }
    return *this;
}

Texture::~Texture() {
    if (id) glDeleteTextures(1, &id);
}

float srgb_to_linear(std::uint8_t code) {
    const double c = code / 255.0;
    return float(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
}

Texture upload(const Image& image) {
    Texture t;
    t.width = image.width;
    t.height = image.height;
    const std::size_t size = std::size_t(image.width) * 4 * std::size_t(image.height);
    std::vector<float> decoded;  // only for 8-bit images: a float image goes up as it is, without a copy
    const float* pixels = image.rgba32f.data();
    if (image.format == Image::Format::rgba32f) {
        if (image.rgba32f.size() != size) throw Error("internal error: image data does not match its size");
    } else {
        if (image.rgba8.size() != size) throw Error("internal error: image data does not match its size");
        float table[256];
        for (int i = 0; i < 256; ++i) table[i] = srgb_to_linear(std::uint8_t(i));
        decoded.resize(size);
        parallel_for(0, std::int64_t(size / 4), 1 << 16, [&](std::int64_t p0, std::int64_t p1) {
            for (std::size_t i = std::size_t(p0) * 4; i < std::size_t(p1) * 4; ++i)
                decoded[i] = i % 4 == 3 ? image.rgba8[i] / 255.0f : table[image.rgba8[i]];
        });
        pixels = decoded.data();
    }
    glGenTextures(1, &t.id);
    glBindTexture(GL_TEXTURE_2D, t.id);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, image.width, image.height, 0, GL_RGBA, GL_FLOAT, pixels);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return t;
}

Target::Target(int width, int height, bool with_depth) {
    colour.width = width;
    colour.height = height;
    glGenTextures(1, &colour.id);
    glBindTexture(GL_TEXTURE_2D, colour.id);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, width, height, 0, GL_RGBA, GL_FLOAT, nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glGenFramebuffers(1, &framebuffer);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, colour.id, 0);
    if (with_depth) {
        glGenRenderbuffers(1, &depth);
        glBindRenderbuffer(GL_RENDERBUFFER, depth);
        glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, width, height);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
    }
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        throw Error("OSMesa could not set up a " + std::to_string(width) + " × " + std::to_string(height) +
                    " float framebuffer");
}

Target& Target::operator=(Target&& o) noexcept {
    if (this != &o) {
        if (framebuffer) glDeleteFramebuffers(1, &framebuffer);
        if (depth) glDeleteRenderbuffers(1, &depth);
        framebuffer = o.framebuffer;
        depth = o.depth;
        colour = std::move(o.colour);
        o.framebuffer = 0;
        o.depth = 0;
    }
    return *this;
}

Target::~Target() {
    if (framebuffer) glDeleteFramebuffers(1, &framebuffer);
    if (depth) glDeleteRenderbuffers(1, &depth);
}

void Target::bind() const {
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    glViewport(0, 0, width(), height());
}

Image read_rgba32f(int width, int height, Rows rows) {
    Image out;
    out.width = width;
    out.height = height;
    out.format = Image::Format::rgba32f;
    const std::size_t row = std::size_t(width) * 4;
    out.rgba32f.resize(row * std::size_t(height));
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, out.rgba32f.data());
    if (rows == Rows::flip) {
        parallel_for(0, height / 2, 32, [&](std::int64_t y0, std::int64_t y1) {
            for (std::int64_t y = y0; y < y1; ++y)
                std::swap_ranges(out.rgba32f.begin() + std::ptrdiff_t(std::size_t(y) * row),
                                 out.rgba32f.begin() + std::ptrdiff_t(std::size_t(y + 1) * row),
                                 out.rgba32f.begin() + std::ptrdiff_t(std::size_t(height - 1 - y) * row));
        });
    }
    return out;
}

void draw_fullscreen() {
    static GLuint vao = 0;  // core profile needs a vertex array object, even an empty one
    if (!vao) glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glDrawArrays(GL_TRIANGLES, 0, 3);
}

void check_frame_size(std::string_view who, int width, int height, double bytes_per_pixel) {
    const int limit = max_framebuffer_size();
    if (width < 1 || height < 1 || width > limit || height > limit)
        throw BadInput(std::string(who) + ": a frame of " + std::to_string(width) + " × " + std::to_string(height) +
                       " pixels cannot be drawn: OSMesa draws from 1 to " + std::to_string(limit) + " pixels a side");
    const double need = double(width) * double(height) * bytes_per_pixel;
    const double memory = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE));
    if (need > memory / 2)
        throw BadInput(std::string(who) + ": a frame of " + std::to_string(width) + " × " + std::to_string(height) +
                       " pixels needs about " + std::to_string(int(std::ceil(need / 1e6))) +
                       " MB, more than half of this machine's " + std::to_string(int(memory / 1e6)) +
                       " MB; use a smaller width and height");
}

}  // namespace orogen::gl
