// The process's OSMesa context. The OSMesa/GL headers stay in this file.
#define GL_GLEXT_PROTOTYPES 1
#include <orogen/gl_context.hpp>

#include <orogen/error.hpp>

#include <GL/osmesa.h>
#include <GL/gl.h>
#include <GL/glext.h>

#include <algorithm>
#include <array>
#include <cstdint>

namespace orogen::gl {

namespace {

std::recursive_mutex& context_mutex() {
    static std::recursive_mutex m;
    return m;
}

// Created once, never destroyed: tearing it down during static destruction
// races llvmpipe's own worker threads, and the process ends right after.
OSMesaContext g_context = nullptr;
std::array<std::uint8_t, 4 * 4 * 4> g_dummy{};  // the context's own 4 × 4 framebuffer, unused
thread_local int g_depth = 0;  // nested Locks on this thread

void create(std::string_view who) {
    const int attribs[] = {OSMESA_FORMAT,
                           OSMESA_RGBA,
                           OSMESA_DEPTH_BITS,
                           0,
                           OSMESA_PROFILE,
                           OSMESA_CORE_PROFILE,
                           OSMESA_CONTEXT_MAJOR_VERSION,
                           4,
                           OSMESA_CONTEXT_MINOR_VERSION,
                           5,
                           0};
    g_context = OSMesaCreateContextAttribs(attribs, nullptr);
    if (!g_context)
        throw Error(std::string(who) +
                    ": OSMesa could not create an OpenGL 4.5 core context (is Mesa's libOSMesa with the llvmpipe "
                    "driver installed? Debian: apt-get install libosmesa6)");
}

}  // namespace

Lock::Lock(std::string_view who) : lock_(context_mutex()) {
    if (!g_context) create(who);
    if (g_depth++ == 0) {
        outermost_ = true;
        if (!OSMesaMakeCurrent(g_context, g_dummy.data(), GL_UNSIGNED_BYTE, 4, 4)) {
            --g_depth;
            throw Error(std::string(who) + ": OSMesa could not make its GL context current");
        }
    }
}

Lock::~Lock() {
    if (outermost_) {
        glFinish();
        OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);  // free for another thread
    }
    --g_depth;
}

std::string renderer_name() {
    Lock lock("gl");
    const auto* s = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    return s ? s : "unknown";
}

int max_framebuffer_size() {
    GLint max_rb = 0, max_vp[2] = {0, 0}, max_tex = 0;
    glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_rb);
    glGetIntegerv(GL_MAX_VIEWPORT_DIMS, max_vp);
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_tex);
    return std::min({max_rb, max_vp[0], max_vp[1], max_tex});
}

namespace {
GLuint compile(std::string_view what, GLenum kind, const char* source) {
    const GLuint s = glCreateShader(kind);
    glShaderSource(s, 1, &source, nullptr);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[4096] = {};
        glGetShaderInfoLog(s, sizeof log, nullptr, log);
        glDeleteShader(s);
        throw Error(std::string(what) + ": the " + (kind == GL_VERTEX_SHADER ? "vertex" : "fragment") +
                    " shader did not compile: " + log);
    }
    return s;
}
}  // namespace

unsigned link_program(std::string_view what, const char* vertex_source, const char* fragment_source) {
    const GLuint vs = compile(what, GL_VERTEX_SHADER, vertex_source);
    const GLuint fs = compile(what, GL_FRAGMENT_SHADER, fragment_source);
    const GLuint p = glCreateProgram();
    glAttachShader(p, vs);
    glAttachShader(p, fs);
    glLinkProgram(p);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[4096] = {};
        glGetProgramInfoLog(p, sizeof log, nullptr, log);
        glDeleteProgram(p);
        throw Error(std::string(what) + ": the shader program did not link: " + log);
    }
    return p;
}

void check_errors(std::string_view who, std::string_view what) {
    if (const GLenum e = glGetError(); e != GL_NO_ERROR)
        throw Error(std::string(who) + ": GL error " + std::to_string(e) + " while " + std::string(what));
}

}  // namespace orogen::gl
