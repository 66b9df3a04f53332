// export:gltf — registers the glTF terrain writer (gltf_writer.hpp) with the kernel.
#include <orogen/gltf/gltf_writer.hpp>

#include <orogen/plugin.hpp>

namespace {

using namespace orogen;

NodeOutputs run(NodeContext& ctx) {
    const auto& hm = ctx.input(0).heightmap();
    gltf::Options o;
    o.vertical_scale = ctx.real("scale");
    o.decimate = int(ctx.integer("decimate"));
    o.chunks = int(ctx.integer("chunks"));
    o.texture_size = int(ctx.integer("texture"));
    const auto path = ctx.output_path(ctx.text("path"));
    const auto s = gltf::write_gltf(hm->view(), o, path);
    ctx.info("wrote " + ctx.text("path") + ": " + std::to_string(s.meshes) + (s.meshes == 1 ? " mesh, " : " meshes, ") +
             std::to_string(s.vertices) + " vertices, " + std::to_string(s.triangles) + " triangles, texture " +
             std::to_string(s.texture_width) + "x" + std::to_string(s.texture_height));
    return {};
}

void check(CheckContext& ctx) {
    const ValueInfo* in = ctx.input(0);
    if (!in || in->width == 0) return;
    const std::int64_t k = ctx.integer("decimate");
    if (k > 1 && (in->width - 1) / k < 1 && (in->height - 1) / k < 1)
        ctx.error("decimate",
                  "decimate=" + std::to_string(k) + " keeps only the corners of a " + std::to_string(in->width) +
                      " x " + std::to_string(in->height) + " heightmap; use at most " +
                      std::to_string(std::max(in->width, in->height) - 1));
}

}  // namespace

OROGEN_PLUGIN("export-gltf", "0.1.0", registry) {
    registry.add({
        .kind = "export",
        .name = "gltf",
        .summary = "write the terrain as a textured glTF 2.0 mesh (.glb or .gltf + .bin)",
        .description =
            "A triangle mesh of the heightmap (two counter-clockwise triangles per tile), positions in metres with "
            "Y up (X east, Z south), normals, texture coordinates and an embedded base-colour texture baked from "
            "height and slope (sand, grass, rock, snow, as the thesis's splatting). Big terrains are split into "
            "chunks that each stay under 65535 vertices, so every mesh uses 16-bit indices. Passes the Khronos glTF "
            "validator with no errors or warnings.",
        .inputs = {{"terrain", ValueType::heightmap, Need::required, "the heightmap to write"}},
        .output = ValueType::none,
        .params =
            {
                Param::path("path", PathRole::output, {".glb", ".gltf"})
                    .help("output file: .glb (one binary file) or .gltf (JSON, with <stem>.bin beside it)"),
                Param::real("scale", 1.0)
                    .min(0, true)
                    .max(1000)
                    .help("vertical exaggeration: heights are multiplied by it"),
                Param::integer("decimate", 1)
                    .min(1)
                    .max(4096)
                    .help("keep every k-th vertex along each axis (the last row and column are always kept); 1 keeps "
                          "all"),
                Param::integer("chunks", 0)
                    .min(0)
                    .max(1024)
                    .help("split the terrain into chunks x chunks meshes; 0 picks the fewest that keep each mesh under "
                          "65535 vertices (16-bit indices); meshes over that use 32-bit indices"),
                Param::integer("texture", 2048)
                    .min(1)
                    .max(16384)
                    .unit("px")
                    .help("largest side of the baked colour texture (never more than the terrain's tiles)"),
            },
        .check = check,
        .run = run,
    });
}
