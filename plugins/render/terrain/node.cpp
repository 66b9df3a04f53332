// render:terrain — the scene pass: a heightmap drawn with splatting, shadows,
// sky, water and haze, as a linear float image.
#include "frame_params.hpp"
#include "render_terrain.hpp"

#include <orogen/error.hpp>
#include <orogen/plugin.hpp>

#include <cstdio>

using namespace orogen;
using namespace orogen::render;

namespace {

std::array<float, 3> parse_colour(const std::string& text, std::array<float, 3> fallback, const char* what) {
    if (text.empty()) return fallback;
    unsigned r = 0, g = 0, b = 0;
    if (text.size() != 7 || text[0] != '#' || std::sscanf(text.c_str() + 1, "%02x%02x%02x", &r, &g, &b) != 3)
        throw BadInput(std::string("render:terrain: ") + what +
                       " colour must be written \"#rrggbb\" (sRGB hex), got \"" + text + "\"");
    auto lin = [](unsigned c) {
        const double v = c / 255.0;
        return float(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
    };
    return {lin(r), lin(g), lin(b)};
}

}  // namespace

namespace orogen::render {

std::vector<Param> camera_params() {
    return {
        Param::choice("camera", {"orbit", "look-at", "top"}, "orbit")
            .help(
                "orbit: around target by azimuth/elevation/distance; look-at: from → to; top: orthographic, north up"),
        Param::real("azimuth", 200.0)
            .min(0)
            .max(360)
            .unit("°")
            .help("orbit: where the camera stands seen from the target, clockwise from north (180: south, looking "
                  "north)"),
        Param::real("elevation", 20.0)
            .min(-89)
            .max(89)
            .unit("°")
            .help("orbit: camera height angle above the horizontal"),
        Param::real("distance", 0.0)
            .min(0)
            .unit("m")
            .help("orbit: camera distance from the target (0: fit the land above any sea, centred in the frame when "
                  "the target is the middle)"),
        Param::point("target", Point2{0.5, 0.5})
            .help("orbit: the point looked at, as a fraction of the terrain (x east, y south)"),
        Param::point("from", Point2{0.5, 1.3}).help("look-at: the camera's place, as a fraction of the terrain"),
        Param::real("from_height", 2000.0).unit("m").help("look-at: camera height above the terrain's lowest point"),
        Param::point("to", Point2{0.5, 0.5}).help("look-at: the point looked at, as a fraction of the terrain"),
        Param::real("to_height", 0.0).unit("m").help("look-at: its height above the terrain's lowest point"),
        Param::real("fov", 40.0).min(0, true).max(180, true).unit("°").help("vertical field of view"),
    };
}

Camera camera_from(NodeContext& ctx) {
    Camera c;
    const std::string& mode = ctx.text("camera");
    c.mode = mode == "top" ? Camera::Mode::top : mode == "look-at" ? Camera::Mode::look_at : Camera::Mode::orbit;
    c.azimuth = ctx.real("azimuth");
    c.elevation = ctx.real("elevation");
    c.distance = ctx.real("distance");
    c.target = ctx.point("target");
    c.from = ctx.point("from");
    c.from_height = ctx.real("from_height");
    c.to = ctx.point("to");
    c.to_height = ctx.real("to_height");
    c.fov = ctx.real("fov");
    return c;
}

std::vector<Param> style_params() {
    return {
        Param::real("exaggeration", 1.0).min(0, true).max(100).help("vertical exaggeration"),
        Param::real("sun_azimuth", 250.0).min(0).max(360).unit("°").help("sun bearing, clockwise from north"),
        Param::real("sun_elevation", 22.0).min(-90).max(90).unit("°").help("sun height above the horizon"),
        Param::real("sun_intensity", 2.4).min(0).help("sunlight strength (linear; the sky's light is fixed)"),
        Param::real("haze", 0.3)
            .min(0)
            .help("aerial perspective: optical depth of the air across the terrain's diagonal"),
        Param::boolean("sea", false).help("draw a sea at sea_level"),
        Param::real("sea_level", 0.0).unit("m").help("height of the sea (with sea=true)"),
        Param::real("sea_fraction", -1.0)
            .min(-1)
            .max(1)
            .help("with sea=true: put the sea at this fraction of the terrain's height range instead (-1: use "
                  "sea_level)"),
        Param::string("water_layer", "water").help("draw water from this layer when the heightmap has it (\"\": none)"),
        Param::real("water_min_depth", 0.05).min(0).unit("m").help("thinner water is not drawn"),
        Param::real("wave_height", 1.0).min(0).unit("m").help("amplitude of the waves"),
        Param::real("clarity", 4.0).min(0, true).unit("m").help("water depth through which 1/e of the ground shows"),
        Param::real("reflection", 0.5)
            .min(0)
            .max(1)
            .help("the sea mirrors the terrain, drawn at this fraction of the frame's size (0: it reflects the sky "
                  "only)"),
        Param::real("time", 0.0).unit("s").help("moves the waves"),
        Param::real("grass_from", 0.25)
            .min(0, true)
            .max(1, true)
            .help("fraction of the height range where grass starts"),
        Param::real("rock_from", 0.5).min(0, true).max(1, true).help("... where rock starts"),
        Param::real("snow_from", 0.75).min(0, true).max(1, true).help("... where snow starts"),
        Param::real("blend", 0.5).min(0).max(1).help("each band blends in from the one below over this part of it"),
        Param::real("rock_slope_start", 0.75)
            .min(0)
            .max(1)
            .help("surface normal y below which rock covers grass and snow ..."),
        Param::real("rock_slope_full", 0.5).min(0).max(1).help("... and at which it covers them fully"),
        Param::real("jitter", 0.03).min(0).max(0.5).help("noise on the height bands, fraction of the height range"),
        Param::real("texture_scale", 0.0)
            .min(0)
            .unit("m")
            .help("size of the coarsest texture features (0: an eighth of the terrain)"),
        Param::string("sand", "")
            .help("sand colour \"#rrggbb\" (default: the splatting colours of the glTF/VTK exports)"),
        Param::string("grass", "").help("grass colour \"#rrggbb\""),
        Param::string("rock", "").help("rock colour \"#rrggbb\""),
        Param::string("snow", "").help("snow colour \"#rrggbb\""),
        Param::integer("shadow_size", 2048).min(64).max(kMaxFrameSide).unit("px").help("shadow map side"),
        Param::integer("samples", 1).min(1).max(8).help("multisampling per pixel: 1, 2, 4 or 8"),
        Param::integer("detail", 0)
            .min(0)
            .max(64)
            .help("the mesh keeps every detail-th sample (normals and colours stay full resolution); 0: about 2.5 "
                  "pixels a triangle"),
        Param::choice("output", {"beauty", "albedo", "normal"}, "beauty")
            .help("beauty: the lit scene; albedo: the splatted colour alone; normal: surface normals × 0.5 + 0.5"),
        Param::integer("particle_frame", -1).min(-1).help("which frame of the particles input to draw (-1: the last)"),
        Param::real("particle_radius", 0.0).min(0).unit("m").help("particle sphere radius (0: three cells)"),
    };
}

void check_style(CheckContext& ctx) {
    if (!(ctx.real("grass_from") < ctx.real("rock_from") && ctx.real("rock_from") < ctx.real("snow_from")))
        ctx.error("rock_from", "the bands must start in order: grass_from < rock_from < snow_from");
    if (!(ctx.real("rock_slope_full") < ctx.real("rock_slope_start")))
        ctx.error("rock_slope_full",
                  "rock_slope_full (normal y where rock covers fully) must be below rock_slope_start");
    const auto samples = ctx.integer("samples");
    if (samples != 1 && samples != 2 && samples != 4 && samples != 8)
        ctx.error("samples", "samples must be 1, 2, 4 or 8, got " + std::to_string(samples));
    for (const char* c : {"sand", "grass", "rock", "snow"}) {
        const std::string& t = ctx.text(c);
        if (!t.empty() &&
            (t.size() != 7 || t[0] != '#' || t.find_first_not_of("0123456789abcdefABCDEF", 1) != std::string::npos))
            ctx.error(c, std::string(c) + " colour must be written \"#rrggbb\" (sRGB hex), got \"" + t + "\"");
    }
    check_frame_memory(ctx, bytes_per_pixel(int(samples)));
}

/// The check both nodes share: the style parameters, and an image of width × height as the output (a
/// turntable's frames are such images too).
void check_frame(CheckContext& ctx) {
    check_style(ctx);
    ctx.output().type = ValueType::image;
    ctx.output().width = int(ctx.integer("width"));
    ctx.output().height = int(ctx.integer("height"));
    ctx.output().layers.clear();
}

Style style_from(NodeContext& ctx) {
    Style s;
    s.splat.band_start = {float(ctx.real("grass_from")), float(ctx.real("rock_from")), float(ctx.real("snow_from"))};
    s.splat.blend_fraction = float(ctx.real("blend"));
    s.splat.slope_start = float(ctx.real("rock_slope_start"));
    s.splat.slope_full = float(ctx.real("rock_slope_full"));
    const auto defaults = Style::default_materials();
    s.materials = {
        parse_colour(ctx.text("sand"), defaults[0], "sand"), parse_colour(ctx.text("grass"), defaults[1], "grass"),
        parse_colour(ctx.text("rock"), defaults[2], "rock"), parse_colour(ctx.text("snow"), defaults[3], "snow")};
    s.jitter = ctx.real("jitter");
    s.texture_scale = ctx.real("texture_scale");
    s.exaggeration = ctx.real("exaggeration");
    s.sun_azimuth = ctx.real("sun_azimuth");
    s.sun_elevation = ctx.real("sun_elevation");
    s.sun_intensity = ctx.real("sun_intensity");
    s.haze = ctx.real("haze");
    s.sea = ctx.flag("sea");
    s.sea_level = ctx.real("sea_level");
    s.sea_fraction = ctx.real("sea_fraction");
    s.water_layer = ctx.text("water_layer");
    s.water_min_depth = ctx.real("water_min_depth");
    s.wave_height = ctx.real("wave_height");
    s.clarity = ctx.real("clarity");
    s.reflection = ctx.real("reflection");
    s.time = ctx.real("time");
    s.shadow_size = int(ctx.integer("shadow_size"));
    s.samples = int(ctx.integer("samples"));
    s.detail = int(ctx.integer("detail"));
    s.particle_radius = ctx.real("particle_radius");
    const std::string& out = ctx.text("output");
    s.output = out == "albedo" ? Style::Output::albedo
        : out == "normal"      ? Style::Output::normal
                               : Style::Output::beauty;
    return s;
}

const ParticleFrame* particle_frame(NodeContext& ctx, std::size_t input) {
    if (!ctx.has_input(input)) return nullptr;
    const ParticleSeries& series = *ctx.input(input).particles();
    if (series.frames.empty()) return nullptr;
    const auto k = ctx.integer("particle_frame");
    if (k >= std::int64_t(series.frames.size()))
        throw BadInput("render:terrain: particle_frame=" + std::to_string(k) + " but the particles have only " +
                       std::to_string(series.frames.size()) + " frames (0.." +
                       std::to_string(series.frames.size() - 1) + ")");
    return &series.frames[k < 0 ? series.frames.size() - 1 : std::size_t(k)];
}

}  // namespace orogen::render

namespace {

std::vector<Param> terrain_params() {
    std::vector<Param> p = frame_size_params(1920, 1080);
    for (auto& q : camera_params()) p.push_back(std::move(q));
    for (auto& q : style_params()) p.push_back(std::move(q));
    return p;
}

NodeOutputs run_terrain(NodeContext& ctx) {
    TerrainRenderer renderer(ctx.input(0).heightmap(), style_from(ctx));
    ctx.progress(0.1);
    Image image = renderer.render(int(ctx.integer("width")), int(ctx.integer("height")), camera_from(ctx),
                                  particle_frame(ctx, 1));
    ctx.check_finite(image.rgba32f, "the rendered frame", 0);
    return NodeOutputs(std::make_shared<Image>(std::move(image)));
}

std::vector<Param> turntable_params() {
    std::vector<Param> p = frame_size_params(1280, 720);
    p.push_back(Param::integer("frames", 120).min(1).max(100000).help("frames in one turn (and the series' length)"));
    p.push_back(Param::real("turns", 1.0)
                    .min(-100)
                    .max(100)
                    .help("turns around the target over the frames (negative: clockwise seen from above)"));
    p.push_back(Param::real("fps", 30.0)
                    .min(0, true)
                    .max(240)
                    .unit("1/s")
                    .help("frame rate the series' times (and the waves) follow"));
    for (auto& q : camera_params())
        if (q.name != "camera" && q.name != "from" && q.name != "from_height" && q.name != "to" &&
            q.name != "to_height")
            p.push_back(std::move(q));
    for (auto& q : style_params())
        if (q.name != "particle_frame") p.push_back(std::move(q));
    for (auto& q : p)
        if (q.name == "azimuth")
            q.help_text = "where the camera starts, clockwise from north (then it circles the target)";
    return p;
}

/// A series of `frames` images orbiting the target; each frame is rendered
/// when the consumer asks for it (the encoder pulls them one at a time).
NodeOutputs run_turntable(NodeContext& ctx) {
    auto renderer = std::make_shared<TerrainRenderer>(ctx.input(0).heightmap(), style_from(ctx));
    Camera base;  // orbit: the turntable has no look-at or top camera
    base.azimuth = ctx.real("azimuth");
    base.elevation = ctx.real("elevation");
    base.distance = ctx.real("distance");
    base.target = ctx.point("target");
    base.fov = ctx.real("fov");
    base.centre_land = false;  // one pivot for the whole turn
    const int width = int(ctx.integer("width")), height = int(ctx.integer("height"));
    const auto frames = std::size_t(ctx.integer("frames"));
    const double turns = ctx.real("turns"), fps = ctx.real("fps"), start_time = ctx.real("time");
    // Fail now, not half way through an encode: the first frame's camera and size.
    renderer->render(std::min(width, 16), std::min(height, 16), base);
    auto series = std::make_shared<Series>();
    series->element = ValueType::image;
    for (std::size_t i = 0; i < frames; ++i) series->times.push_back(double(i) / fps);
    series->make = [renderer, base, width, height, frames, turns, fps, start_time](std::size_t i) -> Value {
        Camera c = base;
        c.azimuth = std::fmod(base.azimuth + 360.0 * turns * double(i) / double(frames) + 3600.0 * 100, 360.0);
        renderer->set_time(start_time + double(i) / fps);
        return Value(std::make_shared<Image>(renderer->render(width, height, c)));
    };
    return NodeOutputs(Value(std::shared_ptr<Series>(std::move(series))));
}

}  // namespace

OROGEN_PLUGIN("render-terrain", "0.1.0", registry) {
    registry.add({
        .kind = "render",
        .name = "turntable",
        .summary =
            "a series of frames orbiting the terrain (frames=N), rendered as render:terrain, one at a time on demand",
        .description =
            "The camera circles the target at the given elevation and distance, `turns` times over `frames` frames,\n"
            "starting at `azimuth`; the waves move with the frames' times (fps). Frames are made only when a\n"
            "consumer asks (export:video pulls them one by one), so a long turntable never sits in memory.\n"
            "Image passes map over it frame by frame: render:bloom(turntable).",
        .inputs = {{"terrain", ValueType::heightmap, Need::required, "the heightmap to draw"}},
        .output = ValueType::image,
        .output_series = true,
        .params = turntable_params(),
        .check =
            [](CheckContext& ctx) {
                check_frame(ctx);
                ctx.output().count = std::size_t(ctx.integer("frames"));
            },
        .run = run_turntable,
    });
    registry.add({
        .kind = "render",
        .name = "terrain",
        .summary = "draw the terrain (splatting, shadows, sky, water, haze) as a linear HDR image, through OSMesa",
        .description =
            "The thesis's texture splatting (sand, grass, rock, snow by height; steep slopes turn grass and snow\n"
            "to rock), with slope and exposure (steep faces rock at any height, vegetation in hollows, bare\n"
            "ridges, sun-facing slopes drier) and procedural textures, lit by the sun (shadow map) and the sky,\n"
            "with water from the 'water' layer (smooth shores) or a sea, and aerial perspective. Renders headless "
            "(Mesa's llvmpipe, no display).\n"
            "The image is linear float RGBA (HDR): chain render:bloom and export:png / export:video.",
        .inputs = {{"terrain", ValueType::heightmap, Need::required, "the heightmap to draw"},
                   {"particles", ValueType::particles, Need::optional, "particles to draw as lit spheres (one frame)"}},
        .output = ValueType::image,
        .params = terrain_params(),
        .check = check_frame,
        .run = run_terrain,
    });
}
