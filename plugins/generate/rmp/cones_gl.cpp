// The OSMesa side of the cone method: kept in this file so no other
// translation unit sees the GL headers.
#define GL_GLEXT_PROTOTYPES 1
#include "cones.hpp"

#include <orogen/relief/voronoi.hpp>

#include <GL/gl.h>
#include <GL/glext.h>

#include <orogen/error.hpp>
#include <orogen/gl_context.hpp>
#include <orogen/parallel.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>

namespace orogen::rmp {

using relief::cell_amount;
using relief::random_sites;
using relief::SiteIndex;

namespace {

// Cones are drawn as fans of this many segments circumscribing the circle;
// the fragment shader discards what lies beyond the radius and writes the
// exact distance as depth, so the count only trades geometry for overdraw.
constexpr int kSegments = 12;

const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec2 corner;  // fan vertex of a unit cone footprint
layout(location = 1) in vec3 cone;    // per instance: apex x, y and radius, samples
uniform vec2 grid;                    // width, height in vertices (= pixels)
flat out vec2 v_site;
flat out float v_radius;
flat out int v_id;
void main() {
    vec2 site = cone.xy;
    float radius = cone.z;
    v_site = site;
    v_radius = radius;
    v_id = gl_InstanceID;
    // Pixel i covers [i, i+1) in window coordinates, so its centre i + 0.5
    // is vertex i: sample x maps to window x + 0.5.
    vec2 p = site + corner * radius;
    gl_Position = vec4((p + 0.5) / grid * 2.0 - 1.0, 0.0, 1.0);
}
)";

const char* kFragmentShader = R"(#version 330 core
flat in vec2 v_site;
flat in float v_radius;
flat in int v_id;
uniform float depth_scale;  // a distance every cone's depth fits under
out vec4 colour;
void main() {
    float d = distance(gl_FragCoord.xy - 0.5, v_site);
    if (d > v_radius) discard;
    gl_FragDepth = d / depth_scale;  // a cone: deeper away from its apex
    int k = v_id + 1;                // 0 stays "no cone"
    colour = vec4(float(k & 255), float((k >> 8) & 255), float((k >> 16) & 255), 255.0) / 255.0;
}
)";

}  // namespace

struct ConeRenderer::Impl {
    bool made = false;  // GL objects exist (in the process's shared context)
    int width = 0, height = 0;
    GLuint program = 0, vao = 0, fan = 0, instances = 0, fbo = 0, colour_rb = 0, depth_rb = 0;
    GLint u_grid = -1, u_depth_scale = -1;
    std::vector<std::uint32_t> pixels;
    std::vector<float> site_data;
    std::vector<double> radii;

    ~Impl() {
        if (!made) return;
        gl::Lock lock("cones");
        if (fbo) glDeleteFramebuffers(1, &fbo);
        if (colour_rb) glDeleteRenderbuffers(1, &colour_rb);
        if (depth_rb) glDeleteRenderbuffers(1, &depth_rb);
        if (fan) glDeleteBuffers(1, &fan);
        if (instances) glDeleteBuffers(1, &instances);
        if (vao) glDeleteVertexArrays(1, &vao);
        if (program) glDeleteProgram(program);
    }
};

ConeRenderer::ConeRenderer(int width, int height) : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    m.width = width;
    m.height = height;
    // The process's one GL context (gl_context.hpp), shared with the render passes.
    std::optional<gl::Lock> lock;
    try {
        lock.emplace("cones");
    } catch (const Error& e) {
        throw Error(std::string(e.what()) + "; or use method=voronoi, which gives the same diagram on the CPU");
    }
    m.made = true;
    const int limit = gl::max_framebuffer_size();
    if (width < 1 || height < 1 || width > limit || height > limit)
        throw BadInput("cones: the grid is " + std::to_string(width) + " × " + std::to_string(height) +
                       " vertices but OSMesa draws at most " + std::to_string(limit) + " × " + std::to_string(limit) +
                       " pixels (one per vertex); use method=voronoi for larger grids");

    m.program = gl::link_program("cones", kVertexShader, kFragmentShader);
    m.u_grid = glGetUniformLocation(m.program, "grid");
    m.u_depth_scale = glGetUniformLocation(m.program, "depth_scale");

    // A fan whose edges are tangent to the unit circle: it covers the disc.
    std::vector<float> fan{0.0f, 0.0f};
    const double outer = 1.0 / std::cos(std::numbers::pi / kSegments);
    for (int k = 0; k <= kSegments; ++k) {
        const double a = 2.0 * std::numbers::pi * k / kSegments;
        fan.push_back(float(outer * std::cos(a)));
        fan.push_back(float(outer * std::sin(a)));
    }
    glGenVertexArrays(1, &m.vao);
    glBindVertexArray(m.vao);
    glGenBuffers(1, &m.fan);
    glBindBuffer(GL_ARRAY_BUFFER, m.fan);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(fan.size() * sizeof(float)), fan.data(), GL_STATIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
    glGenBuffers(1, &m.instances);
    glBindBuffer(GL_ARRAY_BUFFER, m.instances);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    glVertexAttribDivisor(1, 1);

    // Offscreen target: 8-bit RGBA ids and a 32-bit float depth.
    glGenRenderbuffers(1, &m.colour_rb);
    glBindRenderbuffer(GL_RENDERBUFFER, m.colour_rb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
    glGenRenderbuffers(1, &m.depth_rb);
    glBindRenderbuffer(GL_RENDERBUFFER, m.depth_rb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, width, height);
    glGenFramebuffers(1, &m.fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, m.fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, m.colour_rb);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, m.depth_rb);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        throw Error("cones: OSMesa could not set up a " + std::to_string(width) + " × " + std::to_string(height) +
                    " offscreen framebuffer; use method=voronoi instead");
    if (glGetError() != GL_NO_ERROR) throw Error("cones: OSMesa reported an error while setting up");
    m.pixels.resize(std::size_t(width) * std::size_t(height));
}

ConeRenderer::~ConeRenderer() = default;

std::string ConeRenderer::renderer_name() const { return gl::renderer_name(); }

const std::vector<std::uint32_t>& ConeRenderer::render(std::span<const Point2> sites, double radius) {
    impl_->radii.assign(sites.size(), radius);
    const std::vector<double> radii = std::move(impl_->radii);
    return render(sites, radii);
}

const std::vector<std::uint32_t>& ConeRenderer::render(std::span<const Point2> sites, std::span<const double> radii) {
    Impl& m = *impl_;
    if (radii.size() != sites.size()) throw Error("cones: one radius per site is needed");
    double max_radius = 0;
    for (double r : radii) max_radius = std::max(max_radius, r);
    if (sites.size() >= (1u << 24) - 1) throw BadInput("cones: at most 16777214 cones fit in a 24-bit colour id");
    gl::Lock lock("cones");
    glBindFramebuffer(GL_FRAMEBUFFER, m.fbo);
    glViewport(0, 0, m.width, m.height);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);  // equal depths: the first drawn (lowest index) stays, as in SiteIndex
    glClearColor(0, 0, 0, 0);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);

    m.site_data.resize(sites.size() * 3);
    for (std::size_t i = 0; i < sites.size(); ++i) {
        m.site_data[3 * i] = float(sites[i].x);
        m.site_data[3 * i + 1] = float(sites[i].y);
        m.site_data[3 * i + 2] = float(radii[i]);
    }
    glUseProgram(m.program);
    glUniform2f(m.u_grid, float(m.width), float(m.height));
    glUniform1f(m.u_depth_scale, float(std::hypot(m.width, m.height) + max_radius + 1.0));
    glBindVertexArray(m.vao);
    glBindBuffer(GL_ARRAY_BUFFER, m.instances);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(m.site_data.size() * sizeof(float)), m.site_data.data(), GL_STREAM_DRAW);
    glDrawArraysInstanced(GL_TRIANGLE_FAN, 0, kSegments + 2, GLsizei(sites.size()));
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, m.width, m.height, GL_RGBA, GL_UNSIGNED_BYTE, m.pixels.data());
    if (const GLenum e = glGetError(); e != GL_NO_ERROR)
        throw Error("cones: OSMesa failed while drawing (GL error " + std::to_string(e) + ")");
    // Little-endian RGBA: id = r | g << 8 | b << 16; drop alpha.
    parallel_for(0, std::int64_t(m.pixels.size()), 1 << 16, [&](std::int64_t b, std::int64_t e) {
        for (std::int64_t i = b; i < e; ++i) m.pixels[std::size_t(i)] &= 0x00FFFFFFu;
    });
    return m.pixels;
}

std::vector<std::int32_t> ConeRenderer::labels(std::span<const Point2> sites, double radius) {
    const auto& ids = render(sites, radius);
    std::vector<std::int32_t> out(ids.size());
    for (std::size_t i = 0; i < ids.size(); ++i) out[i] = std::int32_t(ids[i]) - 1;
    return out;
}

void rmp_cones(GridView terrain, const RmpParams& p, std::uint64_t seed, const IterationHook& hook) {
    validate(p);
    ConeRenderer renderer(terrain.width, terrain.height);
    std::vector<std::size_t> peaks;  // vertex under each peak
    for (const Point2& q : p.peaks) {
        const Point2 s = peak_vertex(q, terrain.width, terrain.height);
        peaks.push_back(std::size_t(s.y) * std::size_t(terrain.width) + std::size_t(s.x));
    }
    for (int k = 0; k < p.iterations; ++k) {
        const std::uint64_t s = iteration_seed(seed, k);
        const std::vector<Point2> sites = random_sites(p.cones, terrain.width, terrain.height, s);
        // Each cone as wide as a bound of its cell (+1 sample for float rounding).
        std::vector<double> radii = SiteIndex(sites, terrain.width, terrain.height).cell_radius_bounds();
        for (double& r : radii) r += 1.0;
        const std::vector<std::uint32_t>& ids = renderer.render(sites, radii);
        // The colours under the peaks, each raised once.
        std::vector<std::uint32_t> picked;
        for (std::size_t v : peaks)
            if (ids[v] != 0 && std::find(picked.begin(), picked.end(), ids[v]) == picked.end())
                picked.push_back(ids[v]);
        if (picked.empty()) throw Error("cones: no cone covered the peak; the cone radius is too small");
        std::vector<float> amount;
        for (std::uint32_t id : picked)
            amount.push_back(float(cell_amount(iteration_height(p, k), p.jitter, s, int(id) - 1)));
        parallel_for(0, terrain.height, 16, [&](std::int64_t y0, std::int64_t y1) {
            for (std::int64_t y = y0; y < y1; ++y) {
                float* row = terrain.row(int(y));
                const std::uint32_t* id_row = ids.data() + std::size_t(y) * std::size_t(terrain.width);
                for (int x = 0; x < terrain.width; ++x)
                    for (std::size_t c = 0; c < picked.size(); ++c)
                        if (id_row[x] == picked[c]) row[x] += amount[c];
            }
        });
        if (hook) hook(k);
    }
}

}  // namespace orogen::rmp
