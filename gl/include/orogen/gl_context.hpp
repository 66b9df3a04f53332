// orogen/gl_context.hpp — the process's one OpenGL context (OSMesa, llvmpipe).
//
// Every GL user in the process (the render passes, the RMP cone method) draws
// through this one OSMesa context: GL 4.5 core, created on first use, never a
// window, so it runs without a display and without a GPU. It lives in a small
// shared library (liborogen_gl.so) that every GL plugin links, so two plugins
// loaded with RTLD_LOCAL still share one context.
//
// Drawing happens into framebuffer objects; the context's own framebuffer is
// a 4 × 4 dummy. The context is current on one thread at a time: hold a
// gl::Lock for as long as you issue GL calls (it makes the context current on
// the calling thread and releases it afterwards).
//
// This header does not include GL headers; GL names are plain unsigned ints.
#pragma once

#include <mutex>
#include <string>
#include <string_view>

namespace orogen::gl {

/// Holds the context: locks the process-wide mutex, creates the context on
/// first use and makes it current on this thread. `who` names the user in
/// errors ("render:terrain"). Throws orogen::Error if OSMesa cannot create a
/// GL 4.5 core context (saying which Debian package provides it).
class Lock {
public:
    explicit Lock(std::string_view who);
    ~Lock();
    Lock(const Lock&) = delete;
    Lock& operator=(const Lock&) = delete;

private:
    std::unique_lock<std::recursive_mutex> lock_;
    bool outermost_ = false;
};

/// "llvmpipe (LLVM 15.0.6, 256 bits)": the renderer, for benchmark records.
std::string renderer_name();

/// The largest framebuffer side the context can draw (GL_MAX_RENDERBUFFER_SIZE
/// and viewport limits), pixels. Call under a Lock.
int max_framebuffer_size();

/// Compile and link a program from vertex and fragment sources (and an optional
/// geometry-free second stage). Throws orogen::Error with the compiler's log,
/// naming `what`. Call under a Lock.
unsigned link_program(std::string_view what, const char* vertex_source, const char* fragment_source);

/// Throws orogen::Error("WHO: GL error N while WHAT") if glGetError reports one.
void check_errors(std::string_view who, std::string_view what);

}  // namespace orogen::gl
