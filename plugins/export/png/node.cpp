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
        for (const char* p : {"bits", "layer", "scale", "hillshade", "relief", "azimuth", "elevation"})
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
    if (!ctx.flag("hillshade") && !ctx.flag("relief"))
        for (const char* p : {"azimuth", "elevation"})
            if (ctx.given(p)) ctx.error(p, "azimuth and elevation place the light of hillshade=true or relief=true");
    if (!layer.empty() && layer != "height")
        ctx.require_layer(0, "layer", layer, "use \"height\" (the default) or the name of an existing layer");
    if (ctx.text("scale") == "log" && (ctx.flag("hillshade") || ctx.flag("relief")))
        ctx.error("scale",
                  "scale=log maps the heights or a layer= to grey; hillshade= and relief= have their own scale");
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
    std::vector<std::uint8_t> rgba = terrain::bake_splat_texture(heights, heights.width, heights.height);
    const std::vector<std::uint16_t> shade = png_export::hillshade(heights, 16, azimuth, elevation);
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
            png_export::to_srgb8(image, png_export::parse_tonemap(ctx.text("tonemap")), ctx.real("exposure"));
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
    const int bits = int(ctx.integer("bits"));
    const std::string& layer = ctx.text("layer");
    std::vector<std::uint16_t> samples;
    if (ctx.flag("hillshade")) {
        samples = png_export::hillshade(hm.view(), bits, ctx.real("azimuth"), ctx.real("elevation"));
    } else {
        ConstGridView grid = layer.empty() || layer == "height" ? hm.view() : hm.layer(layer);
        std::vector<float> logs;
        if (ctx.text("scale") == "log") {
            logs = log_scaled(grid);
            grid = ConstGridView(logs.data(), grid.width, grid.height, grid.cell);
        }
        samples = png_export::quantise(grid, bits, png_export::range_of(grid));
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
            "relief=true writes a colour map: the thesis's splatting colours, hillshaded.\n"
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
