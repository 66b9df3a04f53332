// The scene pass through OSMesa. GL headers stay in this file.
#define GL_GLEXT_PROTOTYPES 1
#include "render_terrain.hpp"

#include "orogen_shaders.hpp"

#include <orogen/error.hpp>
#include <orogen/gl_context.hpp>
#include <orogen/gl_image.hpp>
#include <orogen/parallel.hpp>

#include <GL/gl.h>
#include <GL/glext.h>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

namespace orogen::render {

namespace {

constexpr double kDegree = std::numbers::pi / 180.0;
/// Optical depth of the silt in rivers and lakes, on top of depth / clarity: thin water still reads as
/// water (a 0.3 m river shows 55 % of its bed instead of 93 %).
constexpr float kRiverSilt = 0.6f;

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The programs, compiled once per process (in the one shared context).
struct Programs {
    GLuint sky = 0, terrain = 0, shadow = 0, water = 0, particles = 0;
};

const Programs& programs() {
    static Programs p = [] {
        Programs q;
        q.sky = gl::link_program("render:terrain sky", shaders::fullscreen_vert, shaders::sky_frag);
        q.terrain = gl::link_program("render:terrain", shaders::terrain_vert, shaders::terrain_frag);
        q.shadow = gl::link_program("render:terrain shadow map", shaders::terrain_vert, shaders::shadow_frag);
        q.water = gl::link_program("render:terrain water", shaders::water_vert, shaders::water_frag);
        q.particles = gl::link_program("render:terrain particles", shaders::particles_vert, shaders::particles_frag);
        return q;
    }();
    return p;
}

GLint loc(GLuint program, const char* name) { return glGetUniformLocation(program, name); }
void set(GLuint p, const char* n, float v) { glUniform1f(loc(p, n), v); }
void set(GLuint p, const char* n, int v) { glUniform1i(loc(p, n), v); }
void set(GLuint p, const char* n, glm::vec3 v) { glUniform3fv(loc(p, n), 1, glm::value_ptr(v)); }
void set(GLuint p, const char* n, glm::vec2 v) { glUniform2fv(loc(p, n), 1, glm::value_ptr(v)); }
void set(GLuint p, const char* n, glm::ivec2 v) { glUniform2iv(loc(p, n), 1, glm::value_ptr(v)); }
void set(GLuint p, const char* n, const glm::mat4& m) { glUniformMatrix4fv(loc(p, n), 1, GL_FALSE, glm::value_ptr(m)); }

/// Unit vector towards a bearing (degrees clockwise from north) and an elevation.
glm::dvec3 direction(double azimuth_degrees, double elevation_degrees) {
    const double a = azimuth_degrees * kDegree, e = elevation_degrees * kDegree;
    return {std::sin(a) * std::cos(e), std::sin(e), -std::cos(a) * std::cos(e)};
}

}  // namespace

std::array<std::array<float, 3>, 4> Style::default_materials() {
    std::array<std::array<float, 3>, 4> m{};
    // Vegetation seen from the air is darker and more olive than the exports' map green (#567d3a), which
    // read as a lawn in the lit scene; sand, rock and snow are the exports'.
    constexpr std::array<std::uint8_t, 3> vegetation{88, 104, 56};
    const std::array<std::array<std::uint8_t, 3>, 4> srgb{mesh::sand_colour, vegetation, mesh::rock_colour,
                                                          mesh::snow_colour};
    for (std::size_t i = 0; i < 4; ++i)
        for (std::size_t c = 0; c < 3; ++c) m[i][c] = gl::srgb_to_linear(srgb[i][c]);
    return m;
}

double bytes_per_pixel(int samples) {
    // multisampled RGBA16F colour + 32-bit depth, the resolved RGBA32F target,
    // the read-back buffer and the image (RGBA32F each), the reflection at a quarter.
    return double(samples) * (8 + 4) + 16 * 3 + 0.25 * (16 + 4);
}

struct TerrainRenderer::Impl {
    std::shared_ptr<const Heightmap> terrain;
    int width = 0, height = 0;  // samples
    float lo = 0, hi = 0;  // height range, m
    bool has_water = false;
    GLuint heights = 0, surface = 0, vao = 0;
    // The grid's triangle strips in four drawing orders (Order), each built on first use: drawn nearest rows
    // first, the depth test rejects most hidden fragments before the splatting shader runs for them.
    std::array<GLuint, 4> indices{};
    glm::ivec2 kept{0, 0};
    int stride = 1;
    GLuint shadow_fbo = 0, shadow_depth = 0;
    int shadow_size = 0;
    // What the shadow map holds: drawn for this light and mesh, it is kept for the next frame (a turntable's
    // sun turns with the terrain, so every frame would draw the same map).
    bool shadow_ready = false, shadow_drawn = false;
    glm::dmat4 shadow_light{0.0};
    int shadow_stride = 0;
    GLuint particle_vbo = 0, particle_vao = 0;

    ~Impl() {
        gl::Lock lock("render:terrain");
        GLuint textures[] = {heights, surface, shadow_depth};
        for (GLuint t : textures)
            if (t) glDeleteTextures(1, &t);
        for (GLuint b : indices)
            if (b) glDeleteBuffers(1, &b);
        if (particle_vbo) glDeleteBuffers(1, &particle_vbo);
        if (vao) glDeleteVertexArrays(1, &vao);
        if (particle_vao) glDeleteVertexArrays(1, &particle_vao);
        if (shadow_fbo) glDeleteFramebuffers(1, &shadow_fbo);
    }

    /// The order the grid's strips are drawn in: rows from north to south or back, columns from west to
    /// east or back. Every order keeps the triangles' winding (counter-clockwise seen from above).
    enum Order { rows_southward = 0, rows_northward = 1, columns_eastward = 2, columns_westward = 3 };

    /// Keep every stride-th sample; the index buffers are rebuilt on first use.
    void build_mesh(int new_stride) {
        if (new_stride == stride && kept.x > 0) return;
        stride = new_stride;
        kept = {(width - 1 + stride - 1) / stride + 1, (height - 1 + stride - 1) / stride + 1};
        for (GLuint& b : indices)
            if (b) {
                glDeleteBuffers(1, &b);
                b = 0;
            }
    }

    /// Binds the strips in `order` to the vertex array (one strip per row or column of quads, joined by
    /// primitive restart), building them on first use. Returns the number of indices.
    GLsizei bind_order(Order order) {
        GLuint& buffer = indices[order];
        const bool columns = order == columns_eastward || order == columns_westward;
        const bool reverse = order == rows_northward || order == columns_westward;
        const int strips = columns ? kept.x - 1 : kept.y - 1, along = columns ? kept.y : kept.x;
        const GLsizei count = GLsizei(strips) * (2 * along + 1);
        glBindVertexArray(vao);
        if (!buffer) {
            std::vector<std::uint32_t> index;
            index.reserve(std::size_t(count));
            for (int k = 0; k < strips; ++k) {
                const int strip = reverse ? strips - 1 - k : k;
                for (int i = 0; i < along; ++i) {
                    if (columns) {  // (x + 1, y) then (x, y): counter-clockwise from above, as the rows
                        index.push_back(std::uint32_t(i * kept.x + strip + 1));
                        index.push_back(std::uint32_t(i * kept.x + strip));
                    } else {
                        index.push_back(std::uint32_t(strip * kept.x + i));
                        index.push_back(std::uint32_t((strip + 1) * kept.x + i));
                    }
                }
                index.push_back(0xFFFFFFFFu);
            }
            glGenBuffers(1, &buffer);
            glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, buffer);
            glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(index.size() * 4), index.data(), GL_STATIC_DRAW);
        } else {
            glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, buffer);
        }
        return count;
    }

    /// Nearest strips first, seen from `eye` (world space): along whichever grid axis the view runs more.
    Order front_to_back(const glm::dvec3& eye) const {
        const double dx = eye.x - 0.5 * extent_x(), dz = eye.z - 0.5 * extent_z();
        if (std::abs(dz) >= std::abs(dx)) return dz > 0 ? rows_northward : rows_southward;
        return dx > 0 ? columns_westward : columns_eastward;
    }

    // ---- the steps of one frame (render() runs them in this order)
    struct Frame;
    Frame frame_box(int frame_width, int frame_height, const Style& st) const;
    void place_camera(Frame& f, const Camera& camera, const Style& st) const;
    std::vector<glm::dvec3> land_outline(const Frame& f, const Style& st) const;
    void fit_orbit(Frame& f, const Camera& camera, glm::dvec3 back, double& distance, const Style& st) const;
    void set_clip_planes(Frame& f, const Style& st) const;
    void refuse_a_view_of_nothing(const Frame& f) const;
    void set_grid(GLuint program, const glm::mat4& view_projection, double exaggeration) const;
    void prepare_shadow_map(const Frame& f, const Style& st);
    void draw_sky(const Frame& f) const;
    void draw_terrain(const Frame& f, const Style& st, const glm::mat4& matrix, bool mirrored, GLuint seen);
    void draw_particles(const Frame& f, const Style& st, const Camera& camera, const ParticleFrame& particles);
    gl::Target draw_reflection(const Frame& f, const Style& st, GLuint scene_fbo);
    void draw_water(const Frame& f, const Style& st, const gl::Target& reflection, bool reflect);

    double extent_x() const { return double(width - 1) * terrain->cell(); }
    double extent_z() const { return double(height - 1) * terrain->cell(); }

    /// Ground height (m, unexaggerated) at world x, z, bilinear; NaN outside.
    double ground(double x, double z) const {
        const double sx = x / terrain->cell(), sy = z / terrain->cell();
        if (sx < 0 || sy < 0 || sx > width - 1 || sy > height - 1) return std::numeric_limits<double>::quiet_NaN();
        const int x0 = std::min(int(sx), width - 2), y0 = std::min(int(sy), height - 2);
        const double fx = sx - x0, fy = sy - y0;
        const ConstGridView v = terrain->view();
        return (1 - fy) * ((1 - fx) * v.at(x0, y0) + fx * v.at(x0 + 1, y0)) +
            fy * ((1 - fx) * v.at(x0, y0 + 1) + fx * v.at(x0 + 1, y0 + 1));
    }
};

TerrainRenderer::TerrainRenderer(std::shared_ptr<const Heightmap> terrain, Style style)
    : impl_(std::make_unique<Impl>()), style_(std::move(style)) {
    Impl& m = *impl_;
    m.terrain = std::move(terrain);
    m.width = m.terrain->width();
    m.height = m.terrain->height();
    if (m.width < 2 || m.height < 2)
        throw BadInput("render:terrain: the heightmap is " + std::to_string(m.width) + " × " +
                       std::to_string(m.height) + " samples; it needs at least 2 × 2");
    mesh::validate(style_.splat);
    const auto span = m.terrain->view().span();
    m.lo = m.hi = span[0];
    for (float h : span) {
        if (!std::isfinite(h)) throw BadInput("render:terrain: the heightmap holds NaN or infinite heights");
        m.lo = std::min(m.lo, h);
        m.hi = std::max(m.hi, h);
    }
    if (style_.sea_fraction >= 0) style_.sea_level = m.lo + style_.sea_fraction * double(m.hi - m.lo);
    if (style_.texture_scale <= 0) style_.texture_scale = std::max(m.extent_x(), m.extent_z()) / 8.0;
    if (style_.particle_radius <= 0) style_.particle_radius = 3.0 * m.terrain->cell();

    // Water from the layer, per sample: its level (where the grid's water vertices stand), its depth and
    // whether it is wet (deeper than water_min_depth); the water shader smooths the last two into the shore.
    // The sea is one plane, drawn apart.
    const bool layer = !style_.water_layer.empty() && m.terrain->has_layer(style_.water_layer);
    std::vector<float> surface;
    if (layer) {
        surface.resize(4 * m.terrain->size());
        const ConstGridView h = m.terrain->view();
        const ConstGridView w = m.terrain->layer(style_.water_layer);
        const float min_depth = float(style_.water_min_depth);
        for (std::size_t i = 0; i < m.terrain->size(); ++i) {
            const bool wet = w.data[i] > min_depth;
            surface[4 * i] = h.data[i] + std::max(w.data[i], 0.0f);
            surface[4 * i + 1] = wet ? w.data[i] : 0.0f;
            surface[4 * i + 2] = wet ? 1.0f : 0.0f;
            m.has_water = m.has_water || wet;
        }
    }

    gl::Lock lock("render:terrain");
    programs();
    glGenTextures(1, &m.heights);
    glBindTexture(GL_TEXTURE_2D, m.heights);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_R32F, m.width, m.height, 0, GL_RED, GL_FLOAT, span.data());
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    if (m.has_water) {
        glGenTextures(1, &m.surface);
        glBindTexture(GL_TEXTURE_2D, m.surface);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, m.width, m.height, 0, GL_RGBA, GL_FLOAT, surface.data());
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);  // the shader's B-spline taps
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    }

    glGenVertexArrays(1, &m.vao);
    gl::check_errors("render:terrain", "uploading the terrain");
}

TerrainRenderer::~TerrainRenderer() = default;

namespace {

/// The sun, the sky and the haze of one frame: the uniforms every lit pass shares.
struct Light {
    glm::dvec3 sun;  // unit, towards the sun
    glm::vec3 sun_colour;  // linear, times the intensity
    glm::vec3 zenith, horizon, ambient;  // linear
    float fog_density = 0;  // 1/m

    Light(const Style& st, double radius) {
        sun = direction(st.sun_azimuth, st.sun_elevation);
        sun_colour = glm::vec3(1.0f, 0.93f, 0.82f) * float(st.sun_intensity);
        // Sky: bluer at the zenith, warmer and paler at the horizon when the sun is low.
        const float low = float(std::clamp(1.0 - st.sun_elevation / 45.0, 0.0, 1.0));
        zenith = glm::mix(glm::vec3(0.05f, 0.14f, 0.42f), glm::vec3(0.08f, 0.16f, 0.38f), low);
        horizon = glm::mix(glm::vec3(0.42f, 0.52f, 0.68f), glm::vec3(0.62f, 0.52f, 0.46f), low * 0.5f);
        ambient = (zenith * 0.6f + horizon * 0.4f) * 0.9f;
        fog_density = float(st.haze / std::max(2.0 * radius, 1e-6));
    }

    /// The light's uniforms on `p`, seen from `eye`; `disc` 1 draws the sun's disc (the sky pass only).
    void set_on(GLuint p, float disc, const glm::dvec3& eye) const {
        set(p, "sun_direction", glm::vec3(sun));
        set(p, "sun_colour", sun_colour);
        set(p, "sky_zenith", zenith);
        set(p, "sky_horizon", horizon);
        set(p, "sun_disc", disc);
        set(p, "fog_density", fog_density);
        set(p, "ambient_colour", ambient);
        set(p, "eye", glm::vec3(eye));
    }
};

/// The sun's orthographic view around the terrain's box (box_min..box_max), for the shadow map.
glm::dmat4 light_matrix(const glm::dvec3& sun, const glm::dvec3& centre, double radius, const glm::dvec3& box_min,
                        const glm::dvec3& box_max) {
    const glm::dvec3 light_up = std::abs(sun.y) > 0.999 ? glm::dvec3(0, 0, -1) : glm::dvec3(0, 1, 0);
    const glm::dmat4 light_view = glm::lookAt(centre + sun * radius * 2.0, centre, light_up);
    glm::dvec3 lo(1e300), hi(-1e300);
    for (int c = 0; c < 8; ++c) {
        const glm::dvec3 p = glm::dvec3(light_view *
                                        glm::dvec4(c & 1 ? box_max.x : box_min.x, c & 2 ? box_max.y : box_min.y,
                                                   c & 4 ? box_max.z : box_min.z, 1.0));
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    return glm::ortho(lo.x, hi.x, lo.y, hi.y, -hi.z - 1.0, -lo.z + 1.0) * light_view;
}

/// The multisampled half-float colour and float depth the scene is drawn into, deleted with it.
struct SceneTarget {
    GLuint fbo = 0, colour = 0, depth = 0;
    SceneTarget(int width, int height, int samples) {
        glGenFramebuffers(1, &fbo);
        glGenRenderbuffers(1, &colour);
        glGenRenderbuffers(1, &depth);
        glBindRenderbuffer(GL_RENDERBUFFER, colour);
        glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples > 1 ? samples : 0, GL_RGBA16F, width, height);
        glBindRenderbuffer(GL_RENDERBUFFER, depth);
        glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples > 1 ? samples : 0, GL_DEPTH_COMPONENT32F, width,
                                         height);
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
        if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
            release();
            throw Error("render:terrain: OSMesa could not set up a " + std::to_string(width) + " × " +
                        std::to_string(height) + " framebuffer with " + std::to_string(samples) + " samples");
        }
    }
    ~SceneTarget() { release(); }
    SceneTarget(const SceneTarget&) = delete;
    SceneTarget& operator=(const SceneTarget&) = delete;

private:
    void release() {
        glDeleteFramebuffers(1, &fbo);
        glDeleteRenderbuffers(1, &colour);
        glDeleteRenderbuffers(1, &depth);
        fbo = colour = depth = 0;
    }
};

}  // namespace

/// What one frame is drawn from: the terrain's box, the camera's matrices and the light.
struct TerrainRenderer::Impl::Frame {
    int width = 0, height = 0;  // pixels
    double exag = 1;  // vertical exaggeration
    double floor_height = 0;  // m, unexaggerated: the skirt's foot
    glm::dvec3 box_min, box_max, centre;
    double radius = 0, aspect = 1;
    glm::dvec3 eye, target, up{0, 1, 0};
    double near_plane = 1, far_plane = 1;
    glm::dmat4 projection{1.0}, view_projection{1.0};
    glm::dmat4 light_view_projection{1.0};
    std::optional<Light> light;
    bool shaded = true;  // the beauty output (not albedo or normals)
};

TerrainRenderer::Impl::Frame TerrainRenderer::Impl::frame_box(int frame_width, int frame_height,
                                                              const Style& st) const {
    Frame f;
    f.width = frame_width;
    f.height = frame_height;
    f.exag = st.exaggeration;
    const double skirt = 0.08 * std::max(double(hi - lo), 1.0);  // m below the lowest point (and the sea)
    f.floor_height = st.sea ? std::min(double(lo), st.sea_level) - skirt : lo - skirt;
    f.box_min = glm::dvec3(0, f.floor_height * f.exag, 0);
    f.box_max = glm::dvec3(extent_x(), hi * f.exag, extent_z());
    f.centre = (f.box_min + f.box_max) * 0.5;
    f.radius = glm::length(f.box_max - f.box_min) * 0.5;
    f.aspect = double(frame_width) / double(std::max(frame_height, 1));
    f.shaded = st.output == Style::Output::beauty;
    f.light.emplace(st, f.radius);
    return f;
}

/// What must fit in an orbit's frame: the surface itself (a lattice of at most 65 × 65 of its samples at
/// their heights) and its skirt's foot along the edges, not the box around them: the box's top corners stand
/// at the highest summit's height over every corner. With a sea, what lies under it is sea to the horizon,
/// so only the land above it counts (the skirt down to the water): fitting the drowned corners and the
/// skirt's foot under the water left the land a small slab in a wide frame.
std::vector<glm::dvec3> TerrainRenderer::Impl::land_outline(const Frame& f, const Style& st) const {
    std::vector<glm::dvec3> outline;
    const ConstGridView g = terrain->view();
    const double cell = terrain->cell();
    const int step = std::max(1, (std::max(width, height) - 1) / 64);
    std::vector<int> xs, ys;  // every step-th sample, and the last
    for (int x = 0; x < width - 1; x += step) xs.push_back(x);
    for (int y = 0; y < height - 1; y += step) ys.push_back(y);
    xs.push_back(width - 1);
    ys.push_back(height - 1);
    const double foot = st.sea ? st.sea_level * f.exag : f.box_min.y;
    for (int y : ys)
        for (int x : xs) {
            const double h = g.at(x, y);
            if (st.sea && !(h > st.sea_level)) continue;
            outline.emplace_back(x * cell, h * f.exag, y * cell);
            if (x == 0 || y == 0 || x == width - 1 || y == height - 1) outline.emplace_back(x * cell, foot, y * cell);
        }
    if (outline.empty())  // all under the sea: the terrain's box, as a frame for the sea floor
        for (int c = 0; c < 8; ++c)
            outline.emplace_back(c & 1 ? f.box_max.x : f.box_min.x, c & 2 ? f.box_max.y : f.box_min.y,
                                 c & 4 ? f.box_max.z : f.box_min.z);
    return outline;
}

/// An orbit with distance 0: the nearest distance at which all of the land is in the frame (with a 4 %
/// margin), by bisection; looking at the terrain's middle, the land is also centred in the frame.
void TerrainRenderer::Impl::fit_orbit(Frame& f, const Camera& camera, glm::dvec3 back, double& distance,
                                      const Style& st) const {
    const std::vector<glm::dvec3> outline = land_outline(f, st);
    const glm::dmat4 proj = glm::perspective(camera.fov * kDegree, f.aspect, f.radius * 1e-3, f.radius * 100);
    auto fits = [&](double d) {
        const glm::dvec3 e = f.target + back * d;
        const glm::dmat4 vp = proj * glm::lookAt(e, f.target, std::abs(back.y) > 0.9999 ? glm::dvec3(0, 0, -1) : f.up);
        for (const glm::dvec3& q : outline) {
            const glm::dvec4 p = vp * glm::dvec4(q, 1.0);
            if (p.w <= 0 || std::abs(p.x / p.w) > 0.96 || std::abs(p.y / p.w) > 0.96) return false;
        }
        return true;
    };
    auto fit = [&] {
        double near = 0, far = f.radius / std::sin(std::min(camera.fov, 179.0) * 0.5 * kDegree) * 4 + f.radius;
        for (int i = 0; i < 40; ++i) (fits(0.5 * (near + far)) ? far : near) = 0.5 * (near + far);
        return far;
    };
    distance = fit();
    // Looking at the terrain's middle (the default target), the land is centred in the frame and fitted
    // again: a few rounds of moving the target by the land's offset from the frame's middle (its extent at the
    // target's distance), so the land fills the frame instead of leaving a band of sky above it.
    if (!(camera.centre_land && camera.target.x == 0.5 && camera.target.y == 0.5 && std::abs(back.y) < 0.9999)) return;
    const glm::dvec3 right = glm::normalize(glm::cross(f.up, back)), upward = glm::cross(back, right);
    for (int round = 0; round < 4; ++round) {
        const glm::dvec3 e = f.target + back * distance;
        const glm::dmat4 vp = proj * glm::lookAt(e, f.target, f.up);
        glm::dvec2 low(1e300), high(-1e300);
        for (const glm::dvec3& q : outline) {
            const glm::dvec4 p = vp * glm::dvec4(q, 1.0);
            low = glm::min(low, glm::dvec2(p) / p.w);
            high = glm::max(high, glm::dvec2(p) / p.w);
        }
        const glm::dvec2 off = 0.5 * (low + high);  // the land's middle, in the frame's -1..1
        const double half_height = distance * std::tan(camera.fov * 0.5 * kDegree);
        f.target += right * (off.x * half_height * f.aspect) + upward * (off.y * half_height);
        distance = fit();
    }
}

/// The eye, the target and the projection; refuses a camera inside or under the terrain.
void TerrainRenderer::Impl::place_camera(Frame& f, const Camera& camera, const Style& st) const {
    if (camera.mode == Camera::Mode::top) {
        f.target = f.centre;
        f.eye = {f.centre.x, f.box_max.y + f.radius, f.centre.z};
        f.up = {0, 0, -1};  // north up
        double half_w = extent_x() * 0.5, half_h = extent_z() * 0.5;
        if (half_w / half_h > f.aspect) half_h = half_w / f.aspect;
        else half_w = half_h * f.aspect;
        f.near_plane = f.radius * 0.5;
        f.far_plane = f.eye.y - f.box_min.y + f.radius * 0.5;
        f.projection = glm::ortho(-half_w, half_w, -half_h, half_h, f.near_plane, f.far_plane);
    } else {
        if (camera.mode == Camera::Mode::orbit) {
            f.target = {camera.target.x * extent_x(), f.centre.y, camera.target.y * extent_z()};
            double distance = camera.distance;
            const glm::dvec3 back = direction(camera.azimuth, camera.elevation);
            if (distance <= 0) fit_orbit(f, camera, back, distance, st);
            f.eye = f.target + back * distance;
        } else {
            f.eye = {camera.from.x * extent_x(), (lo + camera.from_height) * f.exag, camera.from.y * extent_z()};
            f.target = {camera.to.x * extent_x(), (lo + camera.to_height) * f.exag, camera.to.y * extent_z()};
            if (glm::length(f.target - f.eye) < 1e-6)
                throw BadInput("render:terrain: the camera's from and to are the same point; move one of them");
        }
        const glm::dvec3 forward = glm::normalize(f.target - f.eye);
        if (std::abs(forward.y) > 0.9999) f.up = {0, 0, -1};
        const double g = ground(f.eye.x, f.eye.z);
        if (!std::isnan(g) && f.eye.y <= g * f.exag)
            throw BadInput("render:terrain: the camera is inside the terrain (at " +
                           std::to_string(int(f.eye.y / f.exag)) + " m where the ground is " + std::to_string(int(g)) +
                           " m); raise its elevation, distance or height");
        // Beside the terrain and below its lowest point (or below the sea): only the underside and the skirt show.
        const double lowest = st.sea ? std::max(double(lo), st.sea_level) : double(lo);
        if (std::isnan(g) && f.eye.y < lowest * f.exag)
            throw BadInput(
                "render:terrain: the camera is below the terrain (at " + std::to_string(int(f.eye.y / f.exag)) +
                " m, under its lowest point" + (st.sea ? std::string(" or the sea") : std::string()) + " at " +
                std::to_string(int(lowest)) +
                " m), where it sees only its underside; raise its elevation (above 0° for an orbit) or height");
        set_clip_planes(f, st);
        f.projection = glm::perspective(camera.fov * kDegree, f.aspect, f.near_plane, f.far_plane);
    }
    f.view_projection = f.projection * glm::lookAt(f.eye, f.target, f.up);
}

/// Near and far around the terrain's bounding sphere (out to the horizon with a sea).
void TerrainRenderer::Impl::set_clip_planes(Frame& f, const Style& st) const {
    const double to_centre = glm::length(f.centre - f.eye);
    f.far_plane = to_centre + f.radius * (st.sea ? 40.0 : 1.05);  // a sea reaches the horizon
    f.near_plane = std::max(std::max(to_centre - f.radius, 0.0) * 0.8, f.far_plane * 2e-5);
    // The sea comes up to the camera: a ray at most 60° off the view axis meets it no nearer (along the
    // axis) than half the camera's height above it, so keep the near plane inside that.
    if (st.sea && f.eye.y > st.sea_level * f.exag)
        f.near_plane = std::max(std::min(f.near_plane, 0.5 * (f.eye.y - st.sea_level * f.exag)), f.far_plane * 2e-6);
}

/// Looking at nothing: every corner of the terrain's box outside one clip plane.
void TerrainRenderer::Impl::refuse_a_view_of_nothing(const Frame& f) const {
    bool outside_all[6] = {true, true, true, true, true, true};
    for (int c = 0; c < 8; ++c) {
        const glm::dvec4 p = f.view_projection *
            glm::dvec4(c & 1 ? f.box_max.x : f.box_min.x, c & 2 ? f.box_max.y : f.box_min.y,
                       c & 4 ? f.box_max.z : f.box_min.z, 1.0);
        const double v[6] = {p.x + p.w, p.w - p.x, p.y + p.w, p.w - p.y, p.z + p.w, p.w - p.z};
        for (int k = 0; k < 6; ++k) outside_all[k] = outside_all[k] && v[k] < 0;
    }
    for (bool o : outside_all)
        if (o)
            throw BadInput(
                "render:terrain: the camera sees none of the terrain; point it at the terrain "
                "(target, to, azimuth/elevation) or widen the field of view");
}

void TerrainRenderer::Impl::set_grid(GLuint p, const glm::mat4& view_projection, double exaggeration) const {
    set(p, "grid", glm::ivec2(width, height));
    set(p, "stride", stride);
    set(p, "kept", kept);
    set(p, "cell", float(terrain->cell()));
    set(p, "exaggeration", float(exaggeration));
    set(p, "view_projection", view_projection);
}

/// The shadow map: depth seen from the sun, orthographic around the terrain's box. Kept from the last frame
/// when the light and the mesh are the same.
void TerrainRenderer::Impl::prepare_shadow_map(const Frame& f, const Style& st) {
    if (shadow_size != st.shadow_size) {
        if (shadow_fbo) glDeleteFramebuffers(1, &shadow_fbo);
        if (shadow_depth) glDeleteTextures(1, &shadow_depth);
        shadow_size = st.shadow_size;
        shadow_ready = false;
        glGenTextures(1, &shadow_depth);
        glBindTexture(GL_TEXTURE_2D, shadow_depth);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT32F, shadow_size, shadow_size, 0, GL_DEPTH_COMPONENT, GL_FLOAT,
                     nullptr);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
        const float white[4] = {1, 1, 1, 1};
        glTexParameterfv(GL_TEXTURE_2D, GL_TEXTURE_BORDER_COLOR, white);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
        glGenFramebuffers(1, &shadow_fbo);
        glBindFramebuffer(GL_FRAMEBUFFER, shadow_fbo);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, shadow_depth, 0);
        glDrawBuffer(GL_NONE);
        glReadBuffer(GL_NONE);
        if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
            throw Error("render:terrain: OSMesa could not set up the shadow map");
    }
    const bool draw_shadows = f.shaded && st.sun_elevation > 0;
    if (shadow_ready && shadow_light == f.light_view_projection && shadow_stride == stride &&
        shadow_drawn == draw_shadows)
        return;
    glBindFramebuffer(GL_FRAMEBUFFER, shadow_fbo);
    glViewport(0, 0, shadow_size, shadow_size);
    glClear(GL_DEPTH_BUFFER_BIT);
    if (draw_shadows) {
        const GLuint program = programs().shadow;
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glDepthMask(GL_TRUE);
        glEnable(GL_POLYGON_OFFSET_FILL);
        glPolygonOffset(1.5f, 2.0f);
        glUseProgram(program);
        glActiveTexture(GL_TEXTURE0);
        glBindTexture(GL_TEXTURE_2D, heights);
        set(program, "heights", 0);
        set_grid(program, glm::mat4(f.light_view_projection), f.exag);
        set(program, "skirt_edge", -1);
        glDrawElements(GL_TRIANGLE_STRIP, bind_order(rows_southward), GL_UNSIGNED_INT, nullptr);
        glDisable(GL_POLYGON_OFFSET_FILL);
    }
    shadow_ready = true;
    shadow_drawn = draw_shadows;
    shadow_light = f.light_view_projection;
    shadow_stride = stride;
}

/// The sky, which also clears the colour.
void TerrainRenderer::Impl::draw_sky(const Frame& f) const {
    const GLuint program = programs().sky;
    glUseProgram(program);
    f.light->set_on(program, 1.0f, f.eye);
    set(program, "inverse_view_projection", glm::mat4(glm::inverse(f.view_projection)));
    gl::draw_fullscreen();
}

/// The surface, nearest strips first and its back faces culled (a heightfield seen from above the ground only
/// ever shows its front faces), then the skirt down to below the lowest point (and below the sea).
/// `mirrored`: the matrix mirrors the world (the sea's reflection), which turns the winding over.
/// `seen`: a query that learns whether any of the surface (not the skirt) reached the frame.
void TerrainRenderer::Impl::draw_terrain(const Frame& f, const Style& st, const glm::mat4& matrix, bool mirrored,
                                         GLuint seen) {
    const GLuint program = programs().terrain;
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glUseProgram(program);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, heights);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, shadow_depth);
    glActiveTexture(GL_TEXTURE0);
    set(program, "heights", 0);
    set(program, "shadow_map", 1);
    set_grid(program, matrix, f.exag);
    f.light->set_on(program, 0.0f, f.eye);
    set(program, "height_min", lo);
    set(program, "height_max", hi);
    const float starts[4] = {0.0f, st.splat.band_start[0], st.splat.band_start[1], st.splat.band_start[2]};
    glUniform1fv(loc(program, "band_start"), 4, starts);
    set(program, "blend_fraction", st.splat.blend_fraction);
    set(program, "slope_start", st.splat.slope_start);
    set(program, "slope_full", st.splat.slope_full);
    float materials[12];
    for (int i = 0; i < 4; ++i)
        for (int c = 0; c < 3; ++c) materials[3 * i + c] = st.materials[std::size_t(i)][std::size_t(c)];
    glUniform3fv(loc(program, "material"), 4, materials);
    set(program, "jitter", float(st.jitter));
    set(program, "texture_scale", float(st.texture_scale));
    set(program, "output_mode", int(st.output));
    set(program, "light_view_projection", glm::mat4(f.light_view_projection));
    set(program, "shadow_texel", 1.0f / float(shadow_size));
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glFrontFace(mirrored ? GL_CW : GL_CCW);
    set(program, "skirt_edge", -1);
    if (seen) glBeginQuery(GL_ANY_SAMPLES_PASSED, seen);
    glDrawElements(GL_TRIANGLE_STRIP, bind_order(front_to_back(f.eye)), GL_UNSIGNED_INT, nullptr);
    if (seen) glEndQuery(GL_ANY_SAMPLES_PASSED);
    glDisable(GL_CULL_FACE);
    glFrontFace(GL_CCW);
    set(program, "floor_height", float(f.floor_height * f.exag));
    for (int edge = 0; edge < 4; ++edge) {
        set(program, "skirt_edge", edge);
        glDrawArrays(GL_TRIANGLE_STRIP, 0, 2 * (edge % 2 == 0 ? kept.x : kept.y));
    }
}

/// Particles: lit spheres (points).
void TerrainRenderer::Impl::draw_particles(const Frame& f, const Style& st, const Camera& camera,
                                           const ParticleFrame& particles) {
    const auto it = particles.attributes.find("position");
    if (it == particles.attributes.end() || it->second.components != 3)
        throw BadInput("render:terrain: the particle frame has no 3-component 'position' attribute");
    if (!particle_vao) {
        glGenVertexArrays(1, &particle_vao);
        glGenBuffers(1, &particle_vbo);
    }
    glBindVertexArray(particle_vao);
    glBindBuffer(GL_ARRAY_BUFFER, particle_vbo);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(it->second.data.size() * sizeof(float)), it->second.data.data(),
                 GL_STREAM_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    glEnable(GL_PROGRAM_POINT_SIZE);
    const GLuint program = programs().particles;
    glUseProgram(program);
    set(program, "view_projection", glm::mat4(f.view_projection));
    set(program, "exaggeration", float(f.exag));
    set(program, "radius", float(st.particle_radius));
    const double ppm = camera.mode == Camera::Mode::top ? 0.0 : f.height / (2.0 * std::tan(camera.fov * 0.5 * kDegree));
    set(program, "pixels_per_metre_at_unit_distance", float(ppm));
    set(program, "particle_colour", glm::vec3(st.particle_colour[0], st.particle_colour[1], st.particle_colour[2]));
    f.light->set_on(program, 0.0f, f.eye);
    glDrawArrays(GL_POINTS, 0, GLsizei(particles.count()));
    glDisable(GL_PROGRAM_POINT_SIZE);
}

/// The sea's reflection: the terrain above the water mirrored in its plane, drawn into a smaller texture
/// (alpha 1 where terrain is, 0 where the water shader keeps its analytic sky), from the mirrored eye so fog
/// and glints follow the reflected ray's length. Binds `scene_fbo` again when done.
gl::Target TerrainRenderer::Impl::draw_reflection(const Frame& f, const Style& st, GLuint scene_fbo) {
    gl::Target reflection(std::max(1, int(std::lround(f.width * st.reflection))),
                          std::max(1, int(std::lround(f.height * st.reflection))), true);
    reflection.bind();
    glClearColor(0, 0, 0, 0);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    const double water_y = st.sea_level * f.exag;
    // y → 2·water_y − y: the mirror in the plane y = water_y
    const glm::dmat4 mirror = glm::translate(glm::dmat4(1.0), glm::dvec3(0, 2 * water_y, 0)) *
        glm::scale(glm::dmat4(1.0), glm::dvec3(1, -1, 1));
    const Programs& prog = programs();
    glEnable(GL_CLIP_DISTANCE0);
    for (GLuint p : {prog.shadow, prog.terrain})
        glProgramUniform4f(p, loc(p, "clip_plane"), 0.0f, 1.0f, 0.0f, float(-water_y));
    // Lit from the mirrored eye; the strips' order is the same (the mirror keeps x and z).
    Frame mirrored = f;
    mirrored.eye = glm::dvec3(mirror * glm::dvec4(f.eye, 1.0));
    draw_terrain(mirrored, st, glm::mat4(f.view_projection * mirror), true, 0);
    glDisable(GL_CLIP_DISTANCE0);
    for (GLuint p : {prog.shadow, prog.terrain}) glProgramUniform4f(p, loc(p, "clip_plane"), 0.0f, 0.0f, 0.0f, 0.0f);
    glBindFramebuffer(GL_FRAMEBUFFER, scene_fbo);
    glViewport(0, 0, f.width, f.height);
    return reflection;
}

/// Water, blended over the terrain: what shows through is scaled by alpha.
void TerrainRenderer::Impl::draw_water(const Frame& f, const Style& st, const gl::Target& reflection, bool reflect) {
    const GLuint program = programs().water;
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_ONE, GL_SRC_ALPHA, GL_ZERO, GL_ONE);  // the frame stays opaque
    glUseProgram(program);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, surface);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, heights);
    set(program, "surface", 0);
    set(program, "heights", 1);
    set_grid(program, glm::mat4(f.view_projection), f.exag);
    f.light->set_on(program, 0.0f, f.eye);
    set(program, "time", float(st.time));
    set(program, "wave_height", float(st.wave_height));
    set(program, "water_colour", glm::vec3(0.02f, 0.09f, 0.12f));
    set(program, "clarity", float(st.clarity));
    set(program, "has_reflection", 0);
    glActiveTexture(GL_TEXTURE2);
    glBindTexture(GL_TEXTURE_2D, reflection.colour.id);
    set(program, "reflection", 2);
    glActiveTexture(GL_TEXTURE0);  // the unit every other pass and gl::upload expect to be active
    set(program, "viewport", glm::vec2(float(f.width), float(f.height)));
    set(program, "sea_level", float(st.sea_level));
    glBindVertexArray(vao);
    if (has_water) {
        // Farthest strips first: the water is blended, and where it overlaps itself the nearer must come last.
        // Where the ground is dry the grid lies on the terrain's own triangles, and the shader draws water
        // there wherever the layer (at full resolution, between the mesh's vertices) says: in front of them.
        set(program, "sea_plane", 0);
        set(program, "turbidity", kRiverSilt);
        glDepthFunc(GL_LEQUAL);
        glEnable(GL_POLYGON_OFFSET_FILL);
        glPolygonOffset(-1.0f, -4.0f);
        const auto back_to_front = Order(int(front_to_back(f.eye)) ^ 1);
        glDrawElements(GL_TRIANGLE_STRIP, bind_order(back_to_front), GL_UNSIGNED_INT, nullptr);
        glDisable(GL_POLYGON_OFFSET_FILL);
        glDepthFunc(GL_LESS);
    }
    if (st.sea) {
        const double reach = f.radius * 38.0;
        set(program, "sea_plane", 1);
        set(program, "has_reflection", reflect ? 1 : 0);
        const glm::vec4 extent(float(f.centre.x - reach), float(f.centre.z - reach), float(f.centre.x + reach),
                               float(f.centre.z + reach));
        glUniform4fv(loc(program, "plane_extent"), 1, glm::value_ptr(extent));
        glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
    }
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
}

Image TerrainRenderer::render(int width, int height, const Camera& camera, const ParticleFrame* particles,
                              Timings* timings) {
    Impl& m = *impl_;
    const Style& st = style_;
    if (!(camera.fov > 0 && camera.fov < 180))
        throw BadInput("render:terrain: the field of view must be between 0 and 180 degrees (exclusive), got " +
                       std::to_string(camera.fov));
    Impl::Frame f = m.frame_box(width, height, st);
    m.place_camera(f, camera, st);
    m.refuse_a_view_of_nothing(f);

    gl::Lock lock("render:terrain");
    programs();
    gl::check_frame_size("render:terrain", width, height, bytes_per_pixel(st.samples));
    // Auto detail: at most one kept sample per 2.5 pixels of the frame's longer side
    // (llvmpipe pays per triangle; normals and colours come from the full grid anyway).
    m.build_mesh(st.detail > 0
                     ? st.detail
                     : std::max(1, int(std::ceil(std::max(m.width, m.height) / (std::max(width, height) / 2.5)))));
    auto t0 = std::chrono::steady_clock::now();
    auto mark = [&](double Timings::*field) {
        if (!timings) return;
        glFinish();
        timings->*field += seconds_since(t0);
        t0 = std::chrono::steady_clock::now();
    };
    glEnable(GL_PRIMITIVE_RESTART);
    glPrimitiveRestartIndex(0xFFFFFFFFu);
    glDisable(GL_CULL_FACE);

    f.light_view_projection = light_matrix(f.light->sun, f.centre, f.radius, f.box_min, f.box_max);
    m.prepare_shadow_map(f, st);
    mark(&Timings::shadow);

    SceneTarget scene(width, height, std::max(1, st.samples));
    glViewport(0, 0, width, height);
    glDepthMask(GL_TRUE);
    glClearDepth(1.0);
    glClear(GL_DEPTH_BUFFER_BIT);
    m.draw_sky(f);
    // A camera that sees none of the surface (looking past it, from under it, or from inside its box at the
    // sky) renders a picture of nothing: refused, as the frustum test above refuses one that looks away.
    {
        struct Query {
            GLuint id = 0;
            Query() { glGenQueries(1, &id); }
            ~Query() { glDeleteQueries(1, &id); }
        } seen;
        m.draw_terrain(f, st, glm::mat4(f.view_projection), false, seen.id);
        GLuint any = 0;
        glGetQueryObjectuiv(seen.id, GL_QUERY_RESULT, &any);
        if (!any)
            throw BadInput(
                "render:terrain: the camera sees none of the terrain; point it at the terrain "
                "(target, to, azimuth/elevation) or widen the field of view");
    }
    if (f.shaded && particles && particles->count() > 0) m.draw_particles(f, st, camera, *particles);
    const bool reflect = f.shaded && st.sea && st.reflection > 0;
    const gl::Target reflection = reflect ? m.draw_reflection(f, st, scene.fbo) : gl::Target();
    if (f.shaded && (m.has_water || st.sea)) m.draw_water(f, st, reflection, reflect);
    mark(&Timings::scene);

    // ---- resolve the samples into a float target and read it back
    gl::Target resolved(width, height);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, scene.fbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolved.framebuffer);
    glBlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, resolved.framebuffer);
    Image image = gl::read_rgba32f(width, height, gl::Rows::flip);
    gl::check_errors("render:terrain", "drawing the frame");
    mark(&Timings::resolve_and_read);
    return image;
}

}  // namespace orogen::render
