// import:geotiff — any raster GDAL reads (GeoTIFF, SRTM .hgt, ESRI .asc, USGS .dem...) as a heightmap.
#include <orogen/geotiff/geotiff.hpp>

#include <orogen/error.hpp>
#include <orogen/plugin.hpp>

#include <cmath>
#include <sstream>

#include <unistd.h>

namespace {

using namespace orogen;

double physical_memory() { return double(::sysconf(_SC_PHYS_PAGES)) * double(::sysconf(_SC_PAGE_SIZE)); }

std::string gib(double bytes) {
    std::ostringstream s;
    s.precision(3);
    s << bytes / double(1ull << 30) << " GiB";
    return s.str();
}

geotiff::ReadOptions options_from(const std::string& resample, std::int64_t band, const std::string& holes, double cell,
                                  const std::string& square, const GridSpec& grid) {
    geotiff::ReadOptions o;
    o.band = int(band);
    if (resample != "none") {
        o.resample = geotiff::parse_resample(resample);
        o.size = std::make_pair(grid.width, grid.height);
    }
    o.holes = holes == "refuse" ? geotiff::Holes::refuse
        : holes == "mask"       ? geotiff::Holes::mask
                                : geotiff::Holes::fill;
    o.cell = cell;
    o.square = square == "refuse" ? geotiff::Square::refuse : geotiff::Square::warp;
    return o;
}

/// Resampling to a grid of other proportions than the raster's spaces the samples unequally along x and y:
/// said as a warning, never silently.
void warn_if_stretched(NodeContext& ctx, const geotiff::RasterInfo& info, std::pair<int, int> size) {
    const int W = info.warp ? info.warp->width : info.width, H = info.warp ? info.warp->height : info.height;
    const auto [w, h] = size;
    if (w < 2 || h < 2 || W < 2 || H < 2) return;
    const double sx = double(W - 1) / double(w - 1), sy = double(H - 1) / double(h - 1);
    if (std::abs(sx - sy) <= 0.01 * std::max(sx, sy)) return;
    const int fit_h = int(std::lround(double(H - 1) / sx)) + 1;
    std::ostringstream msg;
    msg.precision(3);
    msg << "resampling the raster's " << W << "×" << H << " samples to the grid's " << w << "×" << h
        << " stretches it: " << sx / sy << " times as far apart east–west as north–south, taken as square; give "
        << "the grid the raster's proportions (grid " << w << "x" << fit_h << ") or resample=none";
    ctx.warn(msg.str());
}

NodeOutputs run(NodeContext& ctx) {
    const auto o = options_from(ctx.text("resample"), ctx.integer("band"), ctx.text("holes"), ctx.real("cell"),
                                ctx.text("square"), ctx.grid());
    auto result = geotiff::read(ctx.input_path("path"), o);
    if (result.info.warp)
        ctx.info(geotiff::warp_note(result.info, ctx.text("resample") == "none" ? "cubic" : ctx.text("resample")));
    if (o.size) warn_if_stretched(ctx, result.info, *o.size);
    const double scale = ctx.real("z_scale"), offset = ctx.real("z_offset");
    if (scale != 1.0 || offset != 0.0)
        for (float& h : result.terrain->heights()) h = float(double(h) * scale + offset);
    ctx.check_finite(result.terrain->heights(), "height", 0);
    if (result.holes_filled)
        ctx.info("filled " + std::to_string(result.holes_filled) + " nodata samples from their surroundings" +
                 (ctx.text("holes") == "mask" ? " and marked them in the layer 'nodata'" : ""));
    std::ostringstream msg;
    msg << result.terrain->width() << "×" << result.terrain->height() << " vertices, cell " << result.terrain->cell()
        << " m";
    ctx.info(msg.str());
    ctx.progress(1.0);
    return result.terrain;
}

void check(CheckContext& ctx) {
    geotiff::RasterInfo info;
    try {
        info = geotiff::probe(ctx.resolved_path("path"), int(ctx.integer("band")), ctx.real("cell"));
    } catch (const BadInput& e) {
        ctx.error(ctx.given("band") ? "band" : "path", e.what());
        return;
    }
    if (info.warp && ctx.text("square") == "refuse") {
        ctx.error("square", geotiff::refuse_message(info, ctx.resolved_path("path")));
        return;
    }
    // The band is read whole before resampling (and warped whole to square cells): it and its hole mask must fit.
    double bytes = double(info.width) * double(info.height) * 5.0;
    if (info.warp) bytes += double(info.warp->width) * double(info.warp->height) * 9.0;
    if (bytes > physical_memory() / 4) {
        ctx.error("path",
                  "this raster is " + std::to_string(info.width) + "×" + std::to_string(info.height) +
                      " samples and needs " + gib(bytes) + " to read, more than the " + gib(physical_memory() / 4) +
                      " allowed here (a quarter of this machine's memory); "
                      "cut it down first, e.g. gdal_translate -outsize 25% 25%");
        return;
    }
    if (ctx.text("holes") == "mask" && ctx.text("resample") != "none")
        ctx.error("holes", "holes=mask marks the raster's own samples; add resample=none");
    if (ctx.real("cell") <= 0.0 && info.cell_metres <= 0.0)
        ctx.error("cell", "the raster has no georeference to take a cell size from; give cell=METRES");
    const bool resampled = ctx.text("resample") != "none";
    const int width = info.warp ? info.warp->width : info.width, height = info.warp ? info.warp->height : info.height;
    ValueInfo& out = ctx.output();
    out.width = resampled ? ctx.grid().width : width;
    out.height = resampled ? ctx.grid().height : height;
    if (ctx.real("cell") > 0.0) {
        out.cell = ctx.real("cell");
    } else if (info.cell_metres > 0.0) {
        out.cell = resampled && out.width > 1 ? info.cell_metres * double(width - 1) / double(out.width - 1)
                                              : info.cell_metres;
    }
    out.layers_known = true;
    if (ctx.text("holes") == "mask") out.layers_known = false;  // 'nodata' only when the raster has holes
}

}  // namespace

OROGEN_PLUGIN("import-geotiff", "0.1.0", registry) {
    registry.add({
        .kind = "import",
        .name = "geotiff",
        .summary = "read a DEM (GeoTIFF, SRTM .hgt, ESRI .asc, USGS .dem, any GDAL raster) as a heightmap",
        .description =
            "One band of any raster GDAL opens, in metres (times z_scale, plus z_offset). By default it is "
            "resampled to the spec's grid, keeping its first and last samples on the grid's corners; "
            "resample=none keeps the raster's own size. The cell size comes from the georeference unless cell is "
            "given. "
            "A raster whose cells are not square in metres (a geographic CRS's degrees, or unequal pixel sides) is "
            "never stretched: square=warp (the default) first warps it with GDAL's warper (the resample kernel; cubic "
            "for resample=none) to square cells of its "
            "longer side (or of cell=) in a local transverse Mercator projection centred on it (a projected raster "
            "stays in its CRS), saying so in the log, the corners outside it nodata; square=refuse stops with the "
            "gdalwarp command that would do it. Nodata samples are "
            "filled from their surroundings (holes=fill: layer by layer inward, each the mean of its valid "
            "neighbours), refused (holes=refuse), or filled and marked in a layer 'nodata' (holes=mask, 1 = a hole).",
        .inputs = {},
        .output = ValueType::heightmap,
        .params =
            {
                Param::path("path", PathRole::input).help("the raster, relative to the spec's folder"),
                Param::integer("band", 1).min(1).max(65535).help("band to read"),
                Param::choice("resample", {"bilinear", "cubic", "nearest", "none"}, "bilinear")
                    .help("how to resample to the spec's grid; none keeps the raster's size"),
                Param::choice("holes", {"fill", "refuse", "mask"}, "fill")
                    .help("what to do with nodata samples; mask fills them and marks them in a layer 'nodata' "
                          "(1 = hole) that analyze:terrain leaves out (needs resample=none)"),
                Param::real("cell", 0.0)
                    .min(0.0)
                    .max(1e6)
                    .unit("m")
                    .help("vertex spacing (for non-square cells, the square cell they are warped to); 0 = from the "
                          "file"),
                Param::choice("square", {"warp", "refuse"}, "warp")
                    .help("a raster whose cells are not square metres (degrees, unequal sides): warp it to square "
                          "cells in a local projection (said in the log), or refuse it"),
                Param::real("z_scale", 1.0)
                    .min(-1e6)
                    .max(1e6)
                    .help("multiplies the samples (e.g. 0.3048 for a DEM in feet)"),
                Param::real("z_offset", 0.0).min(-1e7).max(1e7).unit("m").help("added after z_scale"),
            },
        .check = check,
        .run = run,
    });
}
