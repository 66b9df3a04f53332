// export:splatmap, export:normalmap — texture maps for game-engine terrain layers (maps.hpp).
#include "maps.hpp"

#include <orogen/io.hpp>
#include <orogen/plugin.hpp>

using namespace orogen;

namespace {

void write_png(NodeContext& ctx, const Heightmap& hm, const std::vector<std::uint8_t>& rgba) {
    AtomicFile file(ctx.output_path(ctx.text("path")));
    write_rgba_png(file.stream(), hm.width(), hm.height(), rgba);
    file.commit();
}

}  // namespace

OROGEN_PLUGIN("export-maps", "0.1.0", registry) {
    registry.add({
        .kind = "export",
        .name = "splatmap",
        .summary = "write the material weights (R sand, G grass, B rock, A snow) as an RGBA PNG for engine layers",
        .description =
            "One texel per vertex. The weights come from the same height bands and slope rule as orogen's other "
            "colours (thesis section 3.7.1: four height quarters blended, grass and snow turning to rock on slopes "
            "steeper than n_y 0.75, all rock at 0.5), and each texel's four bytes sum to exactly 255, as Unreal's "
            "and Unity's terrain layer weights expect. Note for viewers: a PNG with alpha is shown "
            "pre-multiplied by most image viewers; read the channels, not the picture.",
        .inputs = {{"terrain", ValueType::heightmap, Need::required, "the heightmap"}},
        .output = ValueType::none,
        .params = {Param::path("path", PathRole::output, {".png"}).help("output file: .png")},
        .run = [](NodeContext& ctx) -> NodeOutputs {
            const Heightmap& hm = *ctx.input(0).heightmap();
            write_png(ctx, hm, maps::splat_map(hm.view()));
            return {};
        },
    });
    registry.add({
        .kind = "export",
        .name = "normalmap",
        .summary = "write the surface's tangent-space normals as an RGB PNG (OpenGL or DirectX green)",
        .description =
            "One texel per vertex: the normal of the surface height · scale (central differences, metres per "
            "metre), +X east in red, +Y in green — north for OpenGL (Unity, Godot, Blender), south for DirectX "
            "(Unreal) — and +Z up in blue, each component c stored as round(127.5 · c + 127.5). A flat terrain "
            "is (128, 128, 255).",
        .inputs = {{"terrain", ValueType::heightmap, Need::required, "the heightmap"}},
        .output = ValueType::none,
        .params =
            {
                Param::path("path", PathRole::output, {".png"}).help("output file: .png"),
                Param::choice("green", {"opengl", "directx"}, "opengl")
                    .help("what the green channel points at: opengl = north (Y up the image), directx = south"),
                Param::real("scale", 1.0).min(0.0, true).max(1000.0).help("vertical exaggeration of the surface"),
            },
        .run = [](NodeContext& ctx) -> NodeOutputs {
            const Heightmap& hm = *ctx.input(0).heightmap();
            const auto green = ctx.text("green") == "directx" ? maps::Green::directx : maps::Green::opengl;
            write_png(ctx, hm, maps::normal_map(hm.view(), ctx.real("scale"), green));
            return {};
        },
    });
}
