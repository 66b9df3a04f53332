// export:vtk, export:vtk-particles, export:vtk-plates — VTK XML files for
// ParaView (vtk_writer.hpp). Three nodes because each input has one value
// type: a particle export asked of a heightmap is then a check-time type error.
#include "vtk_writer.hpp"

#include <orogen/error.hpp>
#include <orogen/plugin.hpp>

namespace {

using namespace orogen;

/// The options every VTK node has: up and compress.
vtk::Options options(const NodeContext& ctx) {
    vtk::Options o;
    o.up = vtk::up_from_name(ctx.text("up"));
    o.compress = ctx.flag("compress");
    return o;
}

bool ends_with(const std::string& s, const std::string& tail) {
    return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

NodeOutputs run_heightmap(NodeContext& ctx) {
    const Heightmap& hm = *ctx.input(0).heightmap();
    std::vector<vtk::NamedGrid> layers;
    for (const auto& name : hm.layer_names()) layers.push_back({name, hm.layer(name)});
    vtk::Options o = options(ctx);
    o.vertical_scale = ctx.real("scale");
    o.decimate = int(ctx.integer("decimate"));
    vtk::write_heightmap(hm.view(), layers, ctx.output_path(ctx.text("path")), o);
    ctx.info("wrote " + ctx.text("path") + " with height and " + std::to_string(layers.size()) + " layer(s)");
    return {};
}

void check_heightmap(CheckContext& ctx) {
    const std::string& path = ctx.text("path");
    if (ends_with(path, ".vti")) {
        if (ctx.given("decimate"))
            ctx.error("decimate", "decimate applies to .vtp meshes only; .vti keeps every sample");
        if (ctx.given("scale"))
            ctx.error("scale", "scale applies to .vtp meshes only; in ParaView, Warp By Scalar scales a .vti");
    }
}

NodeOutputs run_particles(NodeContext& ctx) {
    vtk::Options o = options(ctx);
    const auto files = vtk::write_particles(*ctx.input(0).particles(), ctx.output_path(ctx.text("path")), o);
    ctx.info("wrote " + ctx.text("path") + " (" + std::to_string(files) + " file(s))");
    return {};
}

NodeOutputs run_plates(NodeContext& ctx) {
    vtk::Options o = options(ctx);
    const auto files = vtk::write_plates(*ctx.input(0).plates(), ctx.output_path(ctx.text("path")), o);
    ctx.info("wrote " + ctx.text("path") + " (" + std::to_string(files) + " files)");
    return {};
}

Param up_param() {
    return Param::choice("up", {"z", "y"}, "z")
        .help("which axis points up: z (X east, Y north, Z up: ParaView's and GIS's convention, the terrain in the "
              "XY plane) or y (X east, Y up, Z south: glTF's)");
}

Param compress_param() {
    return Param::boolean("compress", false).help("zlib-compress the arrays: smaller files, slower to write and read");
}

}  // namespace

OROGEN_PLUGIN("export-vtk", "0.1.0", registry) {
    registry.add({
        .kind = "export",
        .name = "vtk",
        .summary = "write the heightmap and all its layers as VTK XML for ParaView (.vti image or .vtp mesh)",
        .description =
            "Metres, origin at sample (0, 0) (the north-west corner). up=z (default): X east, Y north, Z up; a .vti is "
            "width x height x 1 points in the XY plane, which ParaView's default camera looks down on and Warp By "
            "Scalar (height) raises along Z. up=y: X east, Y up, Z south (glTF's frame); a .vti is width x 1 x height "
            "points in the XZ plane. Point arrays 'height' and every layer. .vtp: the triangle mesh with Normals and "
            "the same arrays. Particles and plates have their own nodes (export:vtk-particles, export:vtk-plates); "
            "export:paraview-state writes a script that opens it all in ParaView.",
        .inputs = {{"terrain", ValueType::heightmap, Need::required, "the heightmap to write"}},
        .output = ValueType::none,
        .params =
            {
                Param::path("path", PathRole::output, {".vti", ".vtp"})
                    .help("output file: .vti (image data) or .vtp (surface mesh)"),
                Param::real("scale", 1.0).min(0, true).max(1000).help(".vtp only: vertical exaggeration"),
                Param::integer("decimate", 1).min(1).max(4096).help(".vtp only: keep every k-th vertex"),
                up_param(),
                compress_param(),
            },
        .check = check_heightmap,
        .run = run_heightmap,
    });
    registry.add({
        .kind = "export",
        .name = "vtk-particles",
        .summary = "write particle frames for ParaView: one .vtp per frame with every attribute, and a .pvd",
        .description = "Positions in metres (up=z: X east, Y north, Z up; up=y: X east, Y up, Z south), vectors "
                       "(velocity) turned the same way; every other attribute (velocity, density, "
                       "sediment...) as a point array. A .pvd lists the frames with their times so ParaView plays them.",
        .inputs = {{"particles", ValueType::particles, Need::required, "particle frames (e.g. an SPH eroder's .particles)"}},
        .output = ValueType::none,
        .params =
            {
                Param::path("path", PathRole::output, {".pvd", ".vtp"})
                    .help("output: .pvd (time series; frames as <stem>_NNNNNN.vtp beside it) or .vtp (a single frame)"),
                up_param(),
                compress_param(),
            },
        .run = run_particles,
    });
    registry.add({
        .kind = "export",
        .name = "vtk-plates",
        .summary = "write plate polygons and collision events per snapshot for ParaView (.pvd + .vtp)",
        .description = "Per snapshot: <stem>_plates_NNNNNN.vtp (a polygon per plate; cell arrays plate, velocity, "
                       "density) and <stem>_collisions_NNNNNN.vtp (a line per contact since the previous snapshot; "
                       "plate_a, plate_b, kind 1 convergent / 2 divergent / 3 transform, impulse, step), as parts 0 "
                       "and 1 of one .pvd.",
        .inputs = {{"plates", ValueType::plates, Need::required, "a plate simulation's history"}},
        .output = ValueType::none,
        .params =
            {
                Param::path("path", PathRole::output, {".pvd"}).help("output .pvd; the .vtp files go beside it"),
                up_param(),
                compress_param(),
            },
        .run = run_plates,
    });
}
