// import:f32 — a float32 grid described by a JSON file beside it (f32_reader.hpp), as the reference
// DEMs of shared/realism/dems come.
#include "f32_reader.hpp"

#include <orogen/error.hpp>
#include <orogen/plugin.hpp>

using namespace orogen;

OROGEN_PLUGIN("import-f32", "0.1.0", registry) {
    registry.add({
        .kind = "import",
        .name = "f32",
        .summary =
            "read a little-endian float32 grid with its JSON description (nx, ny, dx_m), as shared/realism's DEMs",
        .description =
            "NAME.f32 holds nx × ny float32 heights in metres, rows north to south; NAME.json gives nx, ny and\n"
            "dx_m (or lat0, dlat, dlon in degrees: the cell is dlon at the mid latitude). The description is\n"
            "checked against the file's length and the memory budget before anything is read. NaN samples are\n"
            "kept: analyze:terrain counts them as nodata.",
        .inputs = {},
        .output = ValueType::heightmap,
        .params =
            {
                Param::path("path", PathRole::input).help("the .f32 file, relative to the spec's folder"),
                Param::real("cell", 0.0).min(0).max(1e6).unit("m").help("vertex spacing; 0 = the description's"),
            },
        .check =
            [](CheckContext& ctx) {
                try {
                    const f32::Description d = f32::read_description(ctx.resolved_path("path"));
                    ctx.output().width = d.width;
                    ctx.output().height = d.height;
                    ctx.output().cell = ctx.real("cell") > 0 ? ctx.real("cell") : d.cell;
                    ctx.output().layers_known = true;
                    if (!(ctx.output().cell > 0.0))
                        ctx.error("cell",
                                  "the description gives no cell size (dx_m, or lat0/dlat/dlon); give cell=METRES");
                } catch (const BadInput& e) { ctx.error("path", e.what()); }
            },
        .run = [](NodeContext& ctx) -> NodeOutputs {
            const f32::Description d = f32::read_description(ctx.input_path("path"));
            const double cell = ctx.real("cell") > 0 ? ctx.real("cell") : d.cell;
            auto hm =
                std::make_shared<Heightmap>(d.width, d.height, cell, f32::read_heights(ctx.input_path("path"), d));
            ctx.progress(1.0);
            return hm;
        },
    });
}
