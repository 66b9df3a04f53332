// export:vdb, export:vdb-particles — OpenVDB files (vdb_writer.hpp).
#include "vdb_writer.hpp"

#include <orogen/error.hpp>
#include <orogen/plugin.hpp>

namespace {

using namespace orogen;

NodeOutputs run_terrain(NodeContext& ctx) {
    const Heightmap& hm = *ctx.input(0).heightmap();
    vdb::TerrainOptions o;
    o.voxel_size = ctx.real("voxel");
    o.half_width = ctx.real("half_width");
    o.water_min = ctx.real("water_min");
    o.half_float = ctx.flag("half");
    std::optional<ConstGridView> water;
    if (hm.has_layer("water")) water = hm.layer("water");
    const auto s = vdb::write_terrain(hm.view(), water ? &*water : nullptr, ctx.output_path(ctx.text("path")), o);
    ctx.info("wrote " + ctx.text("path") + ": surface level set of " + std::to_string(s.surface_voxels) + " voxels" +
             (water ? ", water level set of " + std::to_string(s.water_voxels) + " voxels" : std::string()) +
             ", voxel " + std::to_string(s.voxel_size) + " m");
    return {};
}

NodeOutputs run_particles(NodeContext& ctx) {
    const auto files =
        vdb::write_particles(*ctx.input(0).particles(), ctx.output_path(ctx.text("path")), ctx.real("voxel"));
    ctx.info("wrote " + std::to_string(files) + " .vdb file(s)");
    return {};
}

}  // namespace

OROGEN_PLUGIN("export-vdb", "0.1.0", registry) {
    registry.add({
        .kind = "export",
        .name = "vdb",
        .summary = "write the terrain as an OpenVDB narrow-band level set, with a height grid and water",
        .description =
            "Grids: 'surface' (level set: signed distance to the terrain, negative below ground), 'height' (the "
            "heightmap in metres on the plane j = 0) and, when the heightmap has a water layer, 'water' (level set of "
            "the water body). X east, Y up, Z south, metres.",
        .inputs = {{"terrain", ValueType::heightmap, Need::required, "the heightmap to write"}},
        .output = ValueType::none,
        .params =
            {
                Param::path("path", PathRole::output, {".vdb"}).help("output .vdb file"),
                Param::real("voxel", 0.0).min(0).unit("m").help("voxel size; 0 = the heightmap's cell size"),
                Param::real("half_width", 3.0).min(1).max(64).help("narrow band half-width, in voxels"),
                Param::real("water_min", 1e-3).min(0).unit("m").help("water depth from which a column counts as wet"),
                Param::boolean("half", true)
                    .help("store the level sets as 16-bit floats: half the file, error under 1/1000 of a voxel; the "
                          "height "
                          "grid stays 32-bit"),
            },
        .run = run_terrain,
    });
    registry.add({
        .kind = "export",
        .name = "vdb-particles",
        .summary = "write particle frames as OpenVDB points grids with every attribute",
        .description = "One frame: the file itself; several: <stem>_NNNNNN.vdb beside it, one per frame (Houdini and "
                       "Blender load them as a sequence). Each holds a points grid 'particles' with every attribute "
                       "(3-component ones as vec3f) and metadata time and step.",
        .inputs = {{"particles", ValueType::particles, Need::required,
                    "particle frames (e.g. an SPH eroder's .particles)"}},
        .output = ValueType::none,
        .params =
            {
                Param::path("path", PathRole::output, {".vdb"}).help("output .vdb (frames numbered beside it)"),
                Param::real("voxel", 0.0).min(0).unit("m").help("points grid voxel size; 0 = about 8 points per voxel"),
            },
        .run = run_particles,
    });
}
