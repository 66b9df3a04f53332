// render_terrain.hpp — the scene pass: a heightmap drawn through OSMesa with
// the thesis's texture splatting (§3.7.1), procedural textures, the sun with a
// shadow map, a sky, water and aerial perspective, read back as a linear float
// image (HDR: the sun's disc and glints exceed 1 so the bloom can find them).
//
// Plain C++ over orogen::Heightmap; the GL calls stay in render_terrain.cpp.
#pragma once

#include <orogen/mesh/terrain_mesh.hpp>

#include <orogen/values.hpp>

#include <array>
#include <memory>
#include <optional>
#include <string>

namespace orogen::render {

/// Where the camera is. World space as the glTF export: X east, Y up, Z
/// south, metres, origin at sample (0, 0). Points on the terrain are given as
/// fractions of its extent: (0, 0) north-west corner, (1, 1) south-east.
struct Camera {
    enum class Mode { orbit, look_at, top };
    Mode mode = Mode::orbit;
    /// orbit: the camera's bearing seen from the target, degrees clockwise
    /// from north (180: the camera stands south of the target, looking north).
    double azimuth = 200.0;
    double elevation = 20.0;  ///< orbit: degrees above the horizontal
    double distance = 0.0;  ///< orbit: metres from the target; 0 fits the land (above any sea) in view
    Point2 target{0.5, 0.5};  ///< orbit: the point looked at (fraction of the extent), at mid height
    /// orbit with distance 0 and the default target: look at the land's middle in the frame rather than the
    /// terrain's (a picture filled with land); a turntable keeps one pivot instead, so it turns steadily.
    bool centre_land = true;
    Point2 from{0.5, 1.2}, to{0.5, 0.5};  ///< look_at: eye and target (fractions of the extent) ...
    double from_height = 2000.0, to_height = 0.0;  ///< ... and their heights above the terrain's lowest point, m
    double fov = 40.0;  ///< vertical field of view, degrees, in (0, 180)
};

/// How the terrain looks.
struct Style {
    mesh::SplatRules splat;  ///< the bands and slopes (the thesis's by default)
    /// Linear albedo of sand, grass, rock, snow (default: terrain_mesh.hpp's sRGB colours, decoded, with a darker
    /// olive for the vegetation).
    std::array<std::array<float, 3>, 4> materials = default_materials();
    double jitter = 0.03;  ///< noise on the height bands, fraction of the height range
    double texture_scale = 0.0;  ///< m, size of the coarsest texture features; 0: an eighth of the terrain's width
    double exaggeration = 1.0;  ///< vertical scale
    double sun_azimuth = 250.0;  ///< degrees clockwise from north
    double sun_elevation = 22.0;  ///< degrees above the horizon
    double sun_intensity = 2.4;  ///< linear multiplier of the sun's (slightly warm) colour
    double haze = 0.3;  ///< optical depth of the air across the terrain's diagonal (0: clear)
    bool sea = false;  ///< a sea at sea_level
    double sea_level = 0.0;  ///< m
    double sea_fraction = -1.0;  ///< if ≥ 0: the sea at this fraction of the height range instead of sea_level
    std::string water_layer = "water";  ///< water from this layer when the heightmap has it ("" none)
    double water_min_depth = 0.05;  ///< m: thinner water layers are not drawn
    double wave_height = 1.0;  ///< m, amplitude of the waves
    double clarity = 4.0;  ///< m: water depth through which 1/e of the ground shows
    /// The sea mirrors the terrain (a planar reflection pass at this fraction of the frame's size; 0: the sky
    /// only). Rivers and lakes from the water layer lie at many heights and reflect the sky.
    double reflection = 0.5;
    double time = 0.0;  ///< s, moves the waves
    int shadow_size = 2048;  ///< shadow map side, texels
    int samples = 1;  ///< multisampling (1, 2, 4 or 8): 4 smooths the edges, costs ~3× the scene pass
    /// The mesh keeps every detail-th sample (normals and colours stay at full
    /// resolution); 0 picks it per frame so a triangle spans about 2.5 pixels.
    int detail = 0;
    double particle_radius = 0.0;  ///< m; 0: three cells
    std::array<float, 3> particle_colour{0.10f, 0.32f, 0.75f};  ///< linear

    enum class Output { beauty, albedo, normal };
    Output output = Output::beauty;  ///< albedo: the splatted colour alone (unlit, no fog, no water); normal: n·0.5+0.5

    static std::array<std::array<float, 3>, 4> default_materials();
};

/// Where the time of one frame went, seconds (measured with glFinish between stages).
struct Timings {
    double upload = 0, shadow = 0, scene = 0, resolve_and_read = 0;
};

/// Draws one heightmap from any camera; keeps it (and the GL objects) between
/// frames, so a turntable uploads it once.
class TerrainRenderer {
public:
    /// Throws orogen::BadInput if the heightmap is smaller than 2 × 2, the
    /// style is out of range, or the named water layer is missing... only if
    /// asked for explicitly (the default "water" is used when present).
    TerrainRenderer(std::shared_ptr<const Heightmap> terrain, Style style);
    ~TerrainRenderer();
    TerrainRenderer(const TerrainRenderer&) = delete;
    TerrainRenderer& operator=(const TerrainRenderer&) = delete;

    /// One width × height frame, linear RGBA float. Throws orogen::BadInput if
    /// the size is 0 or more than OSMesa can draw or memory holds, if the
    /// camera is under the ground, or sees none of the terrain.
    /// `particles` (optional) are drawn as lit spheres.
    Image render(int width, int height, const Camera& camera, const ParticleFrame* particles = nullptr,
                 Timings* timings = nullptr);

    const Style& style() const { return style_; }
    /// Move the waves to `seconds` (a turntable's frames animate them).
    void set_time(double seconds) { style_.time = seconds; }

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    Style style_;
};

/// Bytes of memory one frame needs per pixel (colour targets, multisampled
/// buffers, read-back), for the checks before a run.
double bytes_per_pixel(int samples);

}  // namespace orogen::render
