// export:png — a heightmap (or one of its layers, or its hillshade) as an 8- or 16-bit grayscale PNG.
#include "heightmap_png.hpp"

#include <orogen/io.hpp>
#include <orogen/plugin.hpp>

using namespace orogen;

namespace {

void check(CheckContext& ctx) {
    const auto bits = ctx.integer("bits");
    if (bits != 8 && bits != 16) ctx.error("bits", "bits must be 8 or 16, got " + std::to_string(bits));
    const std::string& layer = ctx.text("layer");
    if (ctx.flag("hillshade") && !layer.empty()) {
        ctx.error("layer", "hillshade shades the terrain's heights; give either layer= or hillshade=true, not both");
        return;
    }
    if (!ctx.flag("hillshade") && (ctx.given("azimuth") || ctx.given("elevation")))
        ctx.error(ctx.given("azimuth") ? "azimuth" : "elevation", "azimuth and elevation place the light of hillshade=true");
    if (!layer.empty() && layer != "height")
        ctx.require_layer(0, "layer", layer, "use \"height\" (the default) or the name of an existing layer");
}

NodeOutputs run(NodeContext& ctx) {
    const Heightmap& hm = *ctx.input(0).heightmap();
    const int bits = int(ctx.integer("bits"));
    const std::string& layer = ctx.text("layer");
    std::vector<std::uint16_t> samples;
    if (ctx.flag("hillshade")) {
        samples = png_export::hillshade(hm.view(), bits, ctx.real("azimuth"), ctx.real("elevation"));
    } else {
        const ConstGridView grid = layer.empty() || layer == "height" ? hm.view() : hm.layer(layer);
        samples = png_export::quantise(grid, bits, png_export::range_of(grid));
    }
    AtomicFile file(ctx.output_path(ctx.text("path")));
    write_gray_png(file.stream(), hm.width(), hm.height(), bits, samples);
    file.commit();
    return {};
}

}  // namespace

OROGEN_PLUGIN("png-export", "0.1.0", registry) {
    registry.add({
        .kind = "export",
        .name = "png",
        .summary = "write a heightmap, one of its layers, or its hillshade as a grayscale PNG (8 or 16 bits)",
        .description =
            "The lowest vertex becomes black and the highest white; 16 bits keep 65536 levels,\n"
            "which a 1025² terrain needs (8 bits band visibly beyond about 512²). layer= writes a layer\n"
            "(water, sediment, eroded...) min-max normalised the same way; hillshade=true writes the\n"
            "terrain lit from azimuth/elevation instead (Lambert: black = facing away, white = facing the light).",
        .inputs = {{"terrain", ValueType::heightmap, Need::required, "the heightmap to write"}},
        .output = ValueType::none,
        .params =
            {
                Param::path("path", PathRole::output, {".png"}).help("output file, relative to --out"),
                Param::integer("bits", 8).min(8).max(16).help("bits per sample: 8 or 16"),
                Param::string("layer", "").help("write this layer instead of the heights (\"\" or \"height\": the heights)"),
                Param::boolean("hillshade", false).help("write the hillshade of the heights instead"),
                Param::real("azimuth", 315.0).min(0).max(360).unit("°").help(
                    "hillshade light direction, clockwise from north (315 = north-west, the cartographers' default)"),
                Param::real("elevation", 45.0).min(0).max(90).unit("°").help("hillshade light height above the horizon"),
            },
        .check = check,
        .run = run,
    });
}
