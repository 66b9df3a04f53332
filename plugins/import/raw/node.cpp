// import:raw — a .r16/.r32 heightmap with its JSON sidecar (what export:raw writes) as a heightmap.
#include <orogen/formats/raw.hpp>

#include <orogen/error.hpp>
#include <orogen/plugin.hpp>

using namespace orogen;

OROGEN_PLUGIN("import-raw", "0.1.0", registry) {
    registry.add({
        .kind = "import",
        .name = "raw",
        .summary = "read a headerless RAW heightmap (.r16 or .r32) and its JSON sidecar, as export:raw writes them",
        .description = "The sidecar (<file>.json) gives the size, the cell size and, for .r16, the heights of 0 and\n"
                       "65535. The size is checked against the memory budget and the file's length before anything\n"
                       "is read, so a damaged or hostile pair fails at check time with one message.",
        .inputs = {},
        .output = ValueType::heightmap,
        .params =
            {
                Param::path("path", PathRole::input).help("the .r16 or .r32 file, relative to the spec's folder"),
                Param::real("cell", 0.0).min(0).max(1e6).unit("m").help("vertex spacing; 0 = the sidecar's"),
            },
        .check =
            [](CheckContext& ctx) {
                try {
                    const formats::raw::Sidecar s = formats::raw::read_raw_header(ctx.resolved_path("path"));
                    ctx.output().width = s.width;
                    ctx.output().height = s.height;
                    ctx.output().cell = ctx.real("cell") > 0 ? ctx.real("cell") : s.cell;
                    ctx.output().layers_known = true;
                } catch (const BadInput& e) { ctx.error("path", e.what()); }
            },
        .run = [](NodeContext& ctx) -> NodeOutputs {
            formats::raw::Sidecar s;
            std::vector<float> heights = formats::raw::read_raw(ctx.input_path("path"), s);
            auto hm = std::make_shared<Heightmap>(s.width, s.height, ctx.real("cell") > 0 ? ctx.real("cell") : s.cell);
            hm->heights() = std::move(heights);
            ctx.progress(1.0);
            return hm;
        },
    });
}
