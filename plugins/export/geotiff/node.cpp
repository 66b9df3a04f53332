// export:geotiff — registers the GeoTIFF writer (geotiff.hpp) with the kernel.
#include <orogen/geotiff/geotiff.hpp>

#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/plugin.hpp>

#include <cmath>
#include <cstdlib>
#include <sstream>

namespace {

using namespace orogen;

/// "none" → nothing, a number → that number; anything else throws BadInput.
std::optional<double> parse_nodata(const std::string& text) {
    if (text == "none") return std::nullopt;
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0' || !std::isfinite(v))
        throw BadInput("nodata must be a number (e.g. -32768) or none, got '" + text + "'");
    return v;
}

NodeOutputs run(NodeContext& ctx) {
    const auto& hm = ctx.input(0).heightmap();
    geotiff::WriteOptions o;
    o.crs = ctx.text("crs");
    o.origin = ctx.point("origin");
    o.nodata = parse_nodata(ctx.text("nodata"));
    o.compression = geotiff::parse_compression(ctx.text("compression"));
    o.tiled = ctx.flag("tiled");
    o.cog = ctx.flag("cog");
    o.layers = split_names(ctx.text("layers"));
    if (o.layers.size() == 1 && o.layers[0] == "all") o.layers = hm->layer_names();
    const std::string& path = ctx.text("path");
    AtomicFile file(ctx.output_path(path));
    file.stream().close();  // GDAL writes the temporary by name
    geotiff::write(*hm, file.temporary(), o);
    file.commit();
    ctx.info("wrote " + path + " (" + std::to_string(1 + o.layers.size()) + " Float32 band" +
             (o.layers.empty() ? "" : "s") + ", " + ctx.text("compression") + (o.cog ? ", COG" : "") + ")");
    return {};
}

void check(CheckContext& ctx) {
    const auto crs = geotiff::check_crs(ctx.text("crs"));
    if (!crs.ok) ctx.error("crs", crs.message);
    try {
        parse_nodata(ctx.text("nodata"));
    } catch (const BadInput& e) { ctx.error("nodata", e.what()); }
    if (ctx.flag("cog") && ctx.given("tiled") && !ctx.flag("tiled"))
        ctx.error("tiled", "a Cloud-Optimized GeoTIFF is always tiled; drop tiled=false");
    const auto names = split_names(ctx.text("layers"));
    if (!(names.size() == 1 && names[0] == "all"))
        for (const auto& name : names) ctx.require_layer(0, "layers", name, "name layers the terrain has, or all");
}

}  // namespace

OROGEN_PLUGIN("export-geotiff", "0.1.0", registry) {
    registry.add({
        .kind = "export",
        .name = "geotiff",
        .summary = "write the heightmap as a georeferenced Float32 GeoTIFF (GDAL), layers as extra bands",
        .description =
            "Band 1 holds the heights in metres, then one band per layer named in `layers` (band descriptions are the "
            "layer names). Samples are vertices: the file says AREA_OR_POINT=Point and sample (x, y) lies at "
            "(origin.x + x·cell, origin.y + (height − 1 − y)·cell) in the CRS, origin being the south-west vertex. "
            "Default CRS: a local metric engineering CRS; give crs=\"EPSG:32632\" (or WKT, or a PROJ string) and "
            "origin=(easting, northing) to place the terrain on Earth. Compressed with a floating-point predictor; "
            "tiled or Cloud-Optimized "
            "(COG, with overviews) on request. QGIS, GDAL, Blender GIS and game-engine importers read it.",
        .inputs = {{"terrain", ValueType::heightmap, Need::required, "the heightmap to write"}},
        .output = ValueType::none,
        .params =
            {
                Param::path("path", PathRole::output, {".tif", ".tiff"}).help("output file: .tif or .tiff"),
                Param::string("crs", "").help("coordinate reference system: EPSG:NNNN, WKT or PROJ; \"\" = a local "
                                              "metric CRS"),
                Param::point("origin", Point2{0.0, 0.0})
                    .unit("m")
                    .help("easting and northing of the south-west vertex in the CRS's units (as xllcorner, "
                          "yllcorner)"),
                Param::string("nodata", "none").help("nodata value written in the file (a number), or none"),
                Param::choice("compression", {"deflate", "zstd", "lzw", "none"}, "deflate")
                    .help("compression, with the floating-point predictor"),
                Param::boolean("tiled", false).help("256 × 256 tiles instead of strips"),
                Param::boolean("cog", false).help("a Cloud-Optimized GeoTIFF: tiled, with overviews"),
                Param::string("layers", "")
                    .help("layers written as extra bands, comma-separated (\"water, eroded\"), "
                          "or all"),
            },
        .check = check,
        .run = run,
    });
}
