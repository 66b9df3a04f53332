// export:png — a heightmap (or one of its layers, or its hillshade) as an 8- or 16-bit grayscale PNG,
// or a colour relief map (the thesis's splatting colours, hillshaded); or an image (a rendered
// frame) as 8-bit sRGB.
#include <orogen/formats/heightmap_png.hpp>
#include <orogen/formats/image_srgb.hpp>
#include <orogen/mesh/terrain_mesh.hpp>

#include <orogen/io.hpp>
#include <orogen/plugin.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

using namespace orogen;

namespace {

// Every mistake at once (orogen check lists them together), not the first.
void check(CheckContext& ctx) {
    const ValueInfo* in = ctx.input(0);
    if (in && in->type != ValueType::heightmap && in->type != ValueType::image) {
        ctx.error("",
                  "export:png writes a heightmap or an image, but its input is " + std::string(to_string(in->type)));
        return;  // nothing else can be judged without knowing what is written
    }
    if (in && in->type == ValueType::image) {
        for (const char* p : {"bits", "layer", "scale", "colours", "hillshade", "relief", "azimuth", "elevation"})
            if (ctx.given(p))
                ctx.error(p,
                          std::string(p) +
                              "= applies to a heightmap; an image is written as 8-bit sRGB "
                              "(tonemap= and exposure= set how its linear colours are encoded)");
        return;
    }
    for (const char* p : {"tonemap", "exposure"})
        if (ctx.given(p))
            ctx.error(p, std::string(p) + "= applies to an image input; a heightmap's PNG holds its heights");
    const auto bits = ctx.integer("bits");
    if (bits != 8 && bits != 16) ctx.error("bits", "bits must be 8 or 16, got " + std::to_string(bits));
    const std::string& layer = ctx.text("layer");
    if (ctx.flag("relief") && (ctx.flag("hillshade") || !layer.empty() || ctx.given("bits")))
        ctx.error("relief", "relief=true writes an 8-bit colour map of the heights; drop hillshade=, layer= and bits=");
    else if (ctx.flag("hillshade") && !layer.empty())
        ctx.error("layer", "hillshade shades the terrain's heights; give either layer= or hillshade=true, not both");
    if (!ctx.flag("hillshade") && !ctx.flag("relief") && ctx.text("colours") == "grey")
        for (const char* p : {"azimuth", "elevation"})
            if (ctx.given(p))
                ctx.error(p, "azimuth and elevation place the light of hillshade=true, relief=true or colours=");
    if (!layer.empty() && layer != "height")
        ctx.require_layer(0, "layer", layer, "use \"height\" (the default) or the name of an existing layer");
    if (ctx.text("scale") == "log" && (ctx.flag("hillshade") || ctx.flag("relief")))
        ctx.error("scale",
                  "scale=log maps the heights or a layer= to grey; hillshade= and relief= have their own scale");
    const std::string& colours = ctx.text("colours");
    if (colours != "grey") {
        if (ctx.flag("hillshade") || ctx.flag("relief"))
            ctx.error("colours",
                      "colours=" + colours +
                          " colours the heights or a layer=; hillshade= and relief= "
                          "have their own colours");
        if (ctx.given("bits")) ctx.error("bits", "colours=" + colours + " writes an 8-bit colour PNG; drop bits=");
    }
    if (colours == "rivers") {
        if (!layer.empty() && layer != "drainage")
            ctx.error("layer", "colours=rivers draws the drainage layer's rivers over the shaded terrain; drop layer=");
        ctx.require_layer(0, "colours", "drainage",
                          "colours=rivers draws the rivers of the upstream area that erode:evolve's flow() writes");
    }
}

/// The values at quantiles lo and hi (0..1, lo <= hi) of the finite samples of `grid`, from one copy.
std::pair<float, float> quantiles(ConstGridView grid, double lo, double hi) {
    std::vector<float> v;
    v.reserve(grid.size());
    for (std::size_t i = 0; i < grid.size(); ++i)
        if (std::isfinite(grid.data[i])) v.push_back(grid.data[i]);
    if (v.empty()) return {0.0f, 0.0f};
    auto at = [&](double q) { return v.begin() + std::ptrdiff_t(std::clamp(q, 0.0, 1.0) * double(v.size() - 1)); };
    const auto h = at(hi);
    std::nth_element(v.begin(), h, v.end());
    const auto l = at(lo);
    std::nth_element(v.begin(), l, h);  // the lower one lies among those before the upper
    return {*l, *h};
}

/// A soft light from the heights: 0.55 in shadow to 1 facing the light, so colours stay readable.
std::vector<float> soft_light(ConstGridView heights, double azimuth, double elevation) {
    const std::vector<std::uint16_t> shade = formats::png::hillshade(heights, 16, azimuth, elevation);
    std::vector<float> light(shade.size());
    for (std::size_t i = 0; i < shade.size(); ++i) light[i] = 0.55f + 0.45f * float(shade[i]) / 65535.0f;
    return light;
}

/// colours=auto: a layer whose 2–98 % range straddles zero (erosion and deposition, a change) on a diverging
/// map, blue below zero, white at it, red above, symmetric to the larger side's 98th percentile; any other on a
/// sequential map (dark blue, teal, yellow) over its 2–98 % range, so outliers do not wash it out. Shaded
/// by the terrain, so the map reads as ground.
std::vector<std::uint8_t> colour_map(ConstGridView values, ConstGridView heights, double azimuth, double elevation) {
    const auto [lo, hi] = quantiles(values, 0.02, 0.98);
    const bool diverging = lo < 0.0f && hi > 0.0f;
    const float reach = std::max(std::abs(lo), std::abs(hi));
    const std::vector<float> light = soft_light(heights, azimuth, elevation);
    struct Stop {
        float at, r, g, b;
    };
    static const Stop div[] = {{0.0f, 33, 102, 172},
                               {0.25f, 103, 169, 207},
                               {0.5f, 247, 247, 247},
                               {0.75f, 239, 138, 98},
                               {1.0f, 178, 24, 43}};
    static const Stop seq[] = {{0.0f, 37, 52, 148},
                               {0.35f, 44, 127, 184},
                               {0.65f, 65, 182, 196},
                               {0.85f, 161, 218, 180},
                               {1.0f, 255, 255, 204}};
    const Stop* stops = diverging ? div : seq;
    std::vector<std::uint8_t> rgba(values.size() * 4);
    for (std::size_t i = 0; i < values.size(); ++i) {
        const float v = std::isfinite(values.data[i]) ? values.data[i] : 0.0f;
        float t = diverging ? 0.5f + 0.5f * v / reach : (hi > lo ? (v - lo) / (hi - lo) : 0.5f);
        t = std::clamp(t, 0.0f, 1.0f);
        int k = 0;
        while (k < 3 && t > stops[k + 1].at) ++k;
        const float f = (t - stops[k].at) / (stops[k + 1].at - stops[k].at);
        const float c[3] = {stops[k].r + f * (stops[k + 1].r - stops[k].r),
                            stops[k].g + f * (stops[k + 1].g - stops[k].g),
                            stops[k].b + f * (stops[k + 1].b - stops[k].b)};
        for (int ch = 0; ch < 3; ++ch)
            rgba[4 * i + std::size_t(ch)] = std::uint8_t(std::clamp(c[ch] * light[i], 0.0f, 255.0f));
        rgba[4 * i + 3] = 255;
    }
    return rgba;
}

/// colours=rivers: the terrain, pale and shaded, with its rivers in blue where the upstream area (the
/// drainage layer, m²) passes 40 cells or 0.05 km², whichever is larger; a river is drawn wider and deeper
/// blue as its area grows (radius 0.5 px at the threshold, up to 2.5 px at 10⁴ times it), so the trunk
/// streams read at a glance and the tributaries stay thin.
std::vector<std::uint8_t> river_map(const Heightmap& hm, double azimuth, double elevation) {
    const ConstGridView area = hm.layer("drainage");
    const int w = hm.width(), h = hm.height();
    const double cell_area = hm.cell() * hm.cell();
    const double threshold = std::max(40.0 * cell_area, 5e4);
    const std::vector<float> light = soft_light(hm.view(), azimuth, elevation);
    std::vector<std::uint8_t> rgba(std::size_t(w) * std::size_t(h) * 4);
    for (std::size_t i = 0; i < light.size(); ++i) {
        const float grey = 236.0f * light[i];
        rgba[4 * i] = std::uint8_t(grey * 0.97f);
        rgba[4 * i + 1] = std::uint8_t(grey * 0.96f);
        rgba[4 * i + 2] = std::uint8_t(grey * 0.92f);
        rgba[4 * i + 3] = 255;
    }
    // Rivers from the smallest to the largest, so a trunk is drawn over its tributaries.
    std::vector<std::pair<float, std::size_t>> rivers;
    for (std::size_t i = 0; i < area.size(); ++i)
        if (std::isfinite(area.data[i]) && area.data[i] >= threshold) rivers.emplace_back(area.data[i], i);
    std::sort(rivers.begin(), rivers.end());
    for (const auto& [a, i] : rivers) {
        const float t = float(std::clamp(std::log10(double(a) / threshold) / 4.0, 0.0, 1.0));
        const float radius = 0.5f + 2.0f * t;
        const float r = 120.0f - 100.0f * t, g = 170.0f - 95.0f * t, b = 230.0f - 60.0f * t;
        const int x0 = int(i % std::size_t(w)), y0 = int(i / std::size_t(w)), reach = int(std::ceil(radius));
        for (int dy = -reach; dy <= reach; ++dy)
            for (int dx = -reach; dx <= reach; ++dx) {
                const int x = x0 + dx, y = y0 + dy;
                if (x < 0 || y < 0 || x >= w || y >= h) continue;
                // Coverage of the pixel by the disc, approximated by the distance to its centre.
                const float cover = std::clamp(radius + 0.5f - std::sqrt(float(dx * dx + dy * dy)), 0.0f, 1.0f);
                if (cover <= 0.0f) continue;
                std::uint8_t* px = &rgba[(std::size_t(y) * std::size_t(w) + std::size_t(x)) * 4];
                const float c[3] = {r, g, b};
                for (int ch = 0; ch < 3; ++ch) px[ch] = std::uint8_t(float(px[ch]) + cover * (c[ch] - float(px[ch])));
            }
    }
    return rgba;
}

/// log10 of each positive sample; zero, negative and NaN samples become the smallest positive one's log
/// (black), so a layer such as drainage area (m², 10³–10⁹) spreads its orders of magnitude over the greys.
std::vector<float> log_scaled(ConstGridView grid) {
    float smallest = std::numeric_limits<float>::infinity();
    for (std::size_t i = 0; i < grid.size(); ++i)
        if (grid.data[i] > 0.0f) smallest = std::min(smallest, grid.data[i]);
    const float floor = std::isfinite(smallest) ? std::log10(smallest) : 0.0f;
    std::vector<float> out(grid.size());
    for (std::size_t i = 0; i < grid.size(); ++i)
        out[i] = grid.data[i] > 0.0f && std::isfinite(grid.data[i]) ? std::log10(grid.data[i]) : floor;
    return out;
}

/// Splat colour (sand, grass, rock, snow by height and slope, as the glTF
/// texture) times a soft hillshade: 35 % ambient light plus 65 % Lambert.
std::vector<std::uint8_t> relief_map(ConstGridView heights, double azimuth, double elevation) {
    std::vector<std::uint8_t> rgba = mesh::bake_splat_texture(heights, heights.width, heights.height);
    const std::vector<std::uint16_t> shade = formats::png::hillshade(heights, 16, azimuth, elevation);
    for (std::size_t i = 0; i < shade.size(); ++i) {
        const float light = 0.35f + 0.65f * float(shade[i]) / 65535.0f;
        for (int c = 0; c < 3; ++c)
            rgba[4 * i + std::size_t(c)] = std::uint8_t(float(rgba[4 * i + std::size_t(c)]) * light + 0.5f);
    }
    return rgba;
}

NodeOutputs run(NodeContext& ctx) {
    if (ctx.input(0).type() == ValueType::image) {
        const Image& image = *ctx.input(0).image();
        const auto rgba =
            formats::srgb::to_srgb8(image, formats::srgb::parse_tonemap(ctx.text("tonemap")), ctx.real("exposure"));
        AtomicFile file(ctx.output_path(ctx.text("path")));
        write_rgba_png(file.stream(), image.width, image.height, rgba, int(ctx.integer("compression")));
        file.commit();
        return {};
    }
    const Heightmap& hm = *ctx.input(0).heightmap();
    if (ctx.flag("relief")) {
        const auto rgba = relief_map(hm.view(), ctx.real("azimuth"), ctx.real("elevation"));
        AtomicFile file(ctx.output_path(ctx.text("path")));
        write_rgba_png(file.stream(), hm.width(), hm.height(), rgba, int(ctx.integer("compression")));
        file.commit();
        return {};
    }
    const std::string& layer = ctx.text("layer");
    if (const std::string& colours = ctx.text("colours"); colours != "grey") {
        ConstGridView grid = layer.empty() || layer == "height" ? hm.view() : hm.layer(layer);
        std::vector<float> logs;
        if (ctx.text("scale") == "log") {
            logs = log_scaled(grid);
            grid = ConstGridView(logs.data(), grid.width, grid.height, grid.cell);
        }
        const auto rgba = colours == "rivers" ? river_map(hm, ctx.real("azimuth"), ctx.real("elevation"))
                                              : colour_map(grid, hm.view(), ctx.real("azimuth"), ctx.real("elevation"));
        AtomicFile file(ctx.output_path(ctx.text("path")));
        write_rgba_png(file.stream(), hm.width(), hm.height(), rgba, int(ctx.integer("compression")));
        file.commit();
        return {};
    }
    const int bits = int(ctx.integer("bits"));
    std::vector<std::uint16_t> samples;
    if (ctx.flag("hillshade")) {
        samples = formats::png::hillshade(hm.view(), bits, ctx.real("azimuth"), ctx.real("elevation"));
    } else {
        ConstGridView grid = layer.empty() || layer == "height" ? hm.view() : hm.layer(layer);
        std::vector<float> logs;
        if (ctx.text("scale") == "log") {
            logs = log_scaled(grid);
            grid = ConstGridView(logs.data(), grid.width, grid.height, grid.cell);
        }
        samples = formats::png::quantise(grid, bits, formats::png::range_of(grid));
    }
    AtomicFile file(ctx.output_path(ctx.text("path")));
    write_gray_png(file.stream(), hm.width(), hm.height(), bits, samples, int(ctx.integer("compression")));
    file.commit();
    return {};
}

}  // namespace

OROGEN_PLUGIN("export-png", "0.1.0", registry) {
    registry.add({
        .kind = "export",
        .name = "png",
        .summary = "write a heightmap (grayscale 8/16-bit, a layer, hillshade or colour relief) or an image (8-bit "
                   "sRGB) as PNG",
        .description =
            "The lowest vertex becomes black and the highest white; 16 bits keep 65536 levels,\n"
            "which a 1025² terrain needs (8 bits band visibly beyond about 512²). layer= writes a layer\n"
            "(water, sediment, eroded...) min-max normalised the same way; hillshade=true writes the\n"
            "terrain lit from azimuth/elevation instead (Lambert: black = facing away, white = facing the light);\n"
            "relief=true writes a colour map: the thesis's splatting colours, hillshaded. colours=auto writes a\n"
            "layer in colour (diverging around zero when it has both signs), colours=rivers the rivers over the\n"
            "shaded terrain.\n"
            "An image (render:terrain, render:bloom...) is written as 8-bit sRGB RGBA: its linear colours times\n"
            "2^exposure, through the tone curve (aces by default, so the HDR sun and snow roll off instead of "
            "clipping).",
        .inputs = {{"input", ValueType::none, Need::required, "the heightmap or image to write"}},
        .output = ValueType::none,
        .params =
            {
                Param::path("path", PathRole::output, {".png"}).help("output file, relative to --out"),
                Param::integer("bits", 8).min(8).max(16).help("bits per sample: 8 or 16"),
                Param::integer("compression", 6)
                    .min(0)
                    .max(12)
                    .help("deflate level (libdeflate): 0 stores, 1 is fastest (4x libpng's speed, files 1/4 larger), "
                          "12 smallest; 6 writes libpng's size about twice as fast"),
                Param::string("layer", "")
                    .help("write this layer instead of the heights (\"\" or \"height\": the heights)"),
                Param::choice("scale", {"linear", "log"}, "linear")
                    .help("how values map to grey: linear (min black, max white) or log (log10 of the positive "
                          "values; zero and below black): for layers spanning orders of magnitude, e.g. drainage"),
                Param::choice("colours", {"grey", "auto", "rivers"}, "grey")
                    .help("grey: the values as grey levels (bits= of them); auto: 8-bit colour, a layer that is "
                          "both below and above zero (eroded, a change) on a diverging map around zero, any other "
                          "on a sequential map, each over its 2-98 % range and shaded by the terrain; rivers: the "
                          "shaded terrain with its rivers (the drainage layer) in blue, wider as they grow"),
                Param::boolean("hillshade", false).help("write the hillshade of the heights instead"),
                Param::boolean("relief", false)
                    .help("write a colour relief map instead: sand, grass, rock and snow by height and slope (the "
                          "thesis's "
                          "splatting), hillshaded (8-bit RGBA)"),
                Param::real("azimuth", 315.0)
                    .min(0)
                    .max(360)
                    .unit("°")
                    .help("hillshade light direction, clockwise from north (315 = north-west, the cartographers' "
                          "default)"),
                Param::real("elevation", 45.0)
                    .min(0)
                    .max(90)
                    .unit("°")
                    .help("hillshade light height above the horizon"),
                Param::choice("tonemap", {"clamp", "reinhard", "aces"}, "aces")
                    .help("image input: how linear colours above 1 become 8-bit (clamp: clip)"),
                Param::real("exposure", 0.0)
                    .min(-20)
                    .max(20)
                    .help("image input: scale the colours by 2^exposure first"),
            },
        .check = check,
        .run = run,
    });
}
