// The bloom passes through OSMesa. GL headers stay in this file.
#define GL_GLEXT_PROTOTYPES 1
#include "bloom.hpp"

#include "orogen_shaders.hpp"

#include <orogen/error.hpp>
#include <orogen/gl_context.hpp>
#include <orogen/gl_image.hpp>

#include <GL/gl.h>
#include <GL/glext.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace orogen::render {

namespace {

struct Programs {
    GLuint bright = 0, blur = 0, combine = 0;
};

const Programs& programs() {
    static Programs p = [] {
        Programs q;
        q.bright = gl::link_program("render:bright-pass", shaders::fullscreen_vert, shaders::bright_pass_frag);
        q.blur = gl::link_program("render:blur", shaders::fullscreen_vert, shaders::blur_frag);
        q.combine = gl::link_program("render:combine", shaders::fullscreen_vert, shaders::combine_frag);
        return q;
    }();
    return p;
}

void check_image(const char* who, const Image& image) {
    const std::size_t n = std::size_t(image.width) * std::size_t(image.height) * 4;
    if (image.width < 1 || image.height < 1)
        throw BadInput(std::string(who) + ": the image is empty (" + std::to_string(image.width) + " × " +
                       std::to_string(image.height) + ")");
    if ((image.format == Image::Format::rgba32f ? image.rgba32f.size() : image.rgba8.size()) != n)
        throw Error(std::string(who) + ": internal error: the image's pixels do not match its size");
}

// Each pass draws `source` into a new target with the bound program.
gl::Target bright_pass_gl(const gl::Texture& source, const BrightPass& s) {
    const Programs& p = programs();
    const int scale = std::max(1, s.scale);
    gl::Target out((source.width + scale - 1) / scale, (source.height + scale - 1) / scale);
    out.bind();
    glUseProgram(p.bright);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, source.id);
    glUniform1i(glGetUniformLocation(p.bright, "image"), 0);
    glUniform1i(glGetUniformLocation(p.bright, "scale"), scale);
    glUniform1f(glGetUniformLocation(p.bright, "average_luminance"), float(s.average_luminance));
    glUniform1f(glGetUniformLocation(p.bright, "middle_grey"), float(s.middle_grey));
    glUniform1f(glGetUniformLocation(p.bright, "white"), float(s.white));
    glUniform1f(glGetUniformLocation(p.bright, "threshold"), float(s.threshold));
    gl::draw_fullscreen();
    return out;
}

gl::Target blur_gl(const gl::Texture& source, Axis axis, double sigma) {
    const Programs& p = programs();
    const std::vector<float> w = gaussian_weights(sigma);
    gl::Target out(source.width, source.height);
    out.bind();
    glUseProgram(p.blur);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, source.id);
    glUniform1i(glGetUniformLocation(p.blur, "image"), 0);
    glUniform2i(glGetUniformLocation(p.blur, "direction"), axis == Axis::x ? 1 : 0, axis == Axis::y ? 1 : 0);
    glUniform1i(glGetUniformLocation(p.blur, "radius"), int(w.size()) - 1);
    glUniform1fv(glGetUniformLocation(p.blur, "weights"), GLsizei(w.size()), w.data());
    gl::draw_fullscreen();
    return out;
}

gl::Target combine_gl(const gl::Texture& original, const gl::Texture& bloom, double strength) {
    const Programs& p = programs();
    gl::Target out(original.width, original.height);
    out.bind();
    glUseProgram(p.combine);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, original.id);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, bloom.id);
    glUniform1i(glGetUniformLocation(p.combine, "image"), 0);
    glUniform1i(glGetUniformLocation(p.combine, "bloom"), 1);
    glUniform1f(glGetUniformLocation(p.combine, "strength"), float(strength));
    gl::draw_fullscreen();
    return out;
}

Image read(const gl::Target& t, const char* who) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, t.framebuffer);
    Image out = gl::read_rgba32f(t.width(), t.height(), gl::Rows::as_stored);
    gl::check_errors(who, "drawing");
    return out;
}

}  // namespace

Image to_linear_float(const Image& image) {
    if (image.format == Image::Format::rgba32f) return image;
    Image out;
    out.width = image.width;
    out.height = image.height;
    out.format = Image::Format::rgba32f;
    out.rgba32f.resize(image.rgba8.size());
    for (std::size_t i = 0; i < image.rgba8.size(); ++i)
        out.rgba32f[i] = i % 4 == 3 ? image.rgba8[i] / 255.0f : gl::srgb_to_linear(image.rgba8[i]);
    return out;
}

std::vector<float> gaussian_weights(double sigma) {
    if (!(sigma >= 0)) throw BadInput("render:blur: sigma must be 0 or more, got " + std::to_string(sigma));
    if (sigma == 0) return {1.0f};
    const int radius = std::min(256, std::max(1, int(std::ceil(3.0 * sigma))));
    std::vector<double> w(std::size_t(radius) + 1);
    double total = 0;
    for (int k = 0; k <= radius; ++k) {
        w[std::size_t(k)] = std::exp(-0.5 * double(k) * double(k) / (sigma * sigma));
        total += k == 0 ? w[0] : 2 * w[std::size_t(k)];
    }
    std::vector<float> out(w.size());
    for (std::size_t k = 0; k < w.size(); ++k) out[k] = float(w[k] / total);
    return out;
}

Image bright_pass(const Image& image, const BrightPass& settings) {
    check_image("render:bright-pass", image);
    gl::Lock lock("render:bright-pass");
    gl::check_frame_size("render:bright-pass", image.width, image.height, 64);
    const gl::Texture source = gl::upload(image);
    return read(bright_pass_gl(source, settings), "render:bright-pass");
}

Image blur(const Image& image, Axis axis, double sigma) {
    check_image("render:blur", image);
    gl::Lock lock("render:blur");
    gl::check_frame_size("render:blur", image.width, image.height, 64);
    const gl::Texture source = gl::upload(image);
    return read(blur_gl(source, axis, sigma), "render:blur");
}

Image combine(const Image& original, const Image& bloom, double strength) {
    check_image("render:combine", original);
    check_image("render:combine", bloom);
    gl::Lock lock("render:combine");
    gl::check_frame_size("render:combine", original.width, original.height, 64);
    const gl::Texture a = gl::upload(original);
    const gl::Texture b = gl::upload(bloom);
    return read(combine_gl(a, b, strength), "render:combine");
}

Image bloom(const Image& image, const Bloom& s) {
    check_image("render:bloom", image);
    gl::Lock lock("render:bloom");
    gl::check_frame_size("render:bloom", image.width, image.height, 80);
    const gl::Texture source = gl::upload(image);
    gl::Target bright = bright_pass_gl(source, s.bright);
    const double sigma = s.sigma * image.width / std::max(1, s.bright.scale);
    gl::Target bx = blur_gl(bright.colour, Axis::x, sigma);
    gl::Target by = blur_gl(bx.colour, Axis::y, sigma);
    return read(combine_gl(source, by.colour, s.strength), "render:bloom");
}

}  // namespace orogen::render
