// import:vti — the heights of a VTK XML image (.vti) as a heightmap (vti_reader.hpp).
#include "vti_reader.hpp"

#include <orogen/error.hpp>
#include <orogen/plugin.hpp>

using namespace orogen;

OROGEN_PLUGIN("import-vti", "0.1.0", registry) {
    registry.add({
        .kind = "import",
        .name = "vti",
        .summary = "read the heights of a VTK XML image (.vti, as export:vtk writes it) as a heightmap",
        .description =
            "The point array 'height' of a 2-D image: X east and Y north (export:vtk up=z) or X east and Z\n"
            "south (up=y); the cell size is the spacing along X unless cell is given. Other arrays are not read.",
        .inputs = {},
        .output = ValueType::heightmap,
        .params =
            {
                Param::path("path", PathRole::input).help("the .vti file, relative to the spec's folder"),
                Param::real("cell", 0.0).min(0).max(1e6).unit("m").help("vertex spacing; 0 = the image's spacing"),
            },
        .check =
            [](CheckContext& ctx) {
                try {
                    const vti::Header h = vti::read_header(ctx.resolved_path("path"));
                    ctx.output().width = h.width;
                    ctx.output().height = h.height;
                    ctx.output().cell = ctx.real("cell") > 0 ? ctx.real("cell") : h.cell;
                    if (!(ctx.output().cell > 0.0))
                        ctx.error("cell",
                                  ctx.resolved_path("path").string() +
                                      " has no positive spacing to take the cell size from; give cell=METRES");
                    ctx.output().layers_known = true;
                } catch (const BadInput& e) { ctx.error("path", e.what()); }
            },
        .run = [](NodeContext& ctx) -> NodeOutputs {
            auto hm = vti::read(ctx.input_path("path"), ctx.real("cell"));
            ctx.check_finite(hm->heights(), "height", 0);
            ctx.progress(1.0);
            return hm;
        },
    });
}
