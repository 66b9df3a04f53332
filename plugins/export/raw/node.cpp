// export:raw — registers the RAW heightmap writer (raw.hpp) with the kernel.
#include <orogen/formats/raw.hpp>

#include <orogen/error.hpp>
#include <orogen/plugin.hpp>

namespace {

using namespace orogen;

NodeOutputs run(NodeContext& ctx) {
    const auto& hm = ctx.input(0).heightmap();
    std::optional<formats::raw::Range> range;
    if (ctx.real("low") != 0.0 || ctx.real("high") != 0.0)
        range = formats::raw::Range{ctx.real("low"), ctx.real("high")};
    const std::string& path = ctx.text("path");
    const auto w = formats::raw::write_raw(hm->view(), ctx.output_path(path), range);
    if (w.clamped > 0)
        ctx.warn(std::to_string(w.clamped) + " samples lie outside low..high and were clamped to its ends");
    ctx.info("wrote " + path + " and " + path + ".json (heights " + std::to_string(w.range.low) + " to " +
             std::to_string(w.range.high) + " m)");
    return {};
}

void check(CheckContext& ctx) {
    const bool low = ctx.given("low"), high = ctx.given("high");
    if (low != high) {
        ctx.error(low ? "low" : "high",
                  "give both low and high (the heights mapped to 0 and 65535), or neither "
                  "to use the terrain's own lowest and highest point");
        return;
    }
    if (low && !(ctx.real("high") > ctx.real("low"))) ctx.error("high", "high must be above low");
}

}  // namespace

OROGEN_PLUGIN("export-raw", "0.1.0", registry) {
    registry.add({
        .kind = "export",
        .name = "raw",
        .summary = "write the heightmap as headerless RAW (.r16 unsigned 16-bit, .r32 float) plus a JSON sidecar",
        .description =
            "Little-endian samples, rows north to south, no header, as World Machine, Unity and Unreal import them. "
            ".r16 maps low..high (default: the terrain's own lowest..highest point) to 0..65535; .r32 holds metres. "
            "<path>.json gives width, height, cell size, height range and format.",
        .inputs = {{"terrain", ValueType::heightmap, Need::required, "the heightmap to write"}},
        .output = ValueType::none,
        .params =
            {
                Param::path("path", PathRole::output, {".r16", ".r32"}).help("output file: .r16 or .r32"),
                Param::real("low", 0.0)
                    .unit("m")
                    .help("height written as 0 in .r16 (with high; both 0 = the terrain's lowest point)"),
                Param::real("high", 0.0)
                    .unit("m")
                    .help("height written as 65535 in .r16 (with low; both 0 = the terrain's highest point)"),
            },
        .check = check,
        .run = run,
    });
}
