// export:vtk, export:vtk-particles, export:vtk-plates — VTK XML files for
// ParaView (vtk_writer.hpp). Three nodes because each input has one value
// type: a particle export asked of a heightmap is then a check-time type error.
#include <orogen/vtk/vtk_writer.hpp>

#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/plugin.hpp>

#include <algorithm>
#include <filesystem>

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

/// export:vtk-tiles: a .pvti over one .vti piece per tile (per rank under
/// mpirun; one piece for a single process). Each rank writes its own piece:
/// its tile plus the first column east and the first row south of it (from the
/// neighbours, by a one-vertex halo exchange), so neighbouring pieces share
/// those points bit for bit, as ParaView's parallel reader expects. Rank 0
/// writes the .pvti. The files are staged with the run's others.
NodeOutputs run_tiles(NodeContext& ctx) {
    const Heightmap& hm = *ctx.input(0).heightmap();
    Tiling* tiles = ctx.tiling();
    const int width = tiles ? tiles->grid_width() : hm.width(), height = tiles ? tiles->grid_height() : hm.height();
    const int rank = tiles ? tiles->rank() : 0, ranks = tiles ? tiles->ranks() : 1;
    auto tile_of = [&](int r) { return tiles ? tiles->tile(r) : TileRect{0, 0, width, height}; };
    // A piece: the tile and one more column and row where a neighbour has them.
    auto piece_of = [&](int r) {
        const TileRect t = tile_of(r);
        return TileRect{t.x0, t.y0, std::min(t.x1() + 1, width) - t.x0, std::min(t.y1() + 1, height) - t.y0};
    };
    const TileRect own = tile_of(rank), piece = piece_of(rank);
    const TileRect grown = tiles ? tiles->ghosted() : own;  // tile_halo 1
    // Each grid (heights, then the layers by name) ghosted, exchanged, cut to the piece.
    auto piece_grid = [&](const float* tile) {
        std::vector<float> held = tiles ? tiles->ghosted_copy(tile) : std::vector<float>(tile, tile + hm.size());
        if (tiles) tiles->exchange({held.data(), grown.width, grown.height, hm.cell()});
        std::vector<float> out(std::size_t(piece.width) * std::size_t(piece.height));
        for (int y = 0; y < piece.height; ++y) {
            const float* src = held.data() + std::size_t(piece.y0 - grown.y0 + y) * std::size_t(grown.width) +
                std::size_t(piece.x0 - grown.x0);
            std::copy(src, src + piece.width, out.begin() + std::ptrdiff_t(std::size_t(y) * std::size_t(piece.width)));
        }
        return out;
    };
    const std::vector<std::string> names = hm.layer_names();
    std::vector<std::vector<float>> grids;
    grids.push_back(piece_grid(hm.heights().data()));
    for (const auto& n : names) grids.push_back(piece_grid(hm.layer(n).data));
    std::vector<vtk::NamedGrid> layers;
    for (std::size_t i = 0; i < names.size(); ++i)
        layers.push_back({names[i], {grids[i + 1].data(), piece.width, piece.height, hm.cell()}});
    vtk::Options o;
    o.compress = ctx.flag("compress");
    o.up = vtk::up_from_name(ctx.text("up"));

    const std::filesystem::path pvti = ctx.text("path");
    auto piece_file = [&](int r) { return pvti.stem().string() + "_" + std::to_string(r) + ".vti"; };
    vtk::write_heightmap_piece({grids[0].data(), piece.width, piece.height, hm.cell()}, layers, piece.x0, piece.y0,
                               height, ctx.output_path((pvti.parent_path() / piece_file(rank)).string()), o);
    if (rank == 0) {
        std::vector<vtk::PvtiPiece> pieces;
        for (int r = 0; r < ranks; ++r) {
            const TileRect p = piece_of(r);
            pieces.push_back({piece_file(r), p.x0, p.x1() - 1, p.y0, p.y1() - 1});
        }
        const std::string text = vtk::pvti_text(width, height, hm.cell(), names, pieces, o.up);
        write_file_atomically(ctx.output_path(pvti.string()),
                              {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
    }
    ctx.info("wrote " + pvti.string() + " over " + std::to_string(ranks) + " piece(s)");
    return {};
}

Param up_param() {
    return Param::choice("up", {"z", "y"}, "z")
        .help(
            "which axis points up: z (X east, Y north, Z up: ParaView's and GIS's convention, the terrain in the "
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
        .name = "vtk-tiles",
        .summary = "write the heightmap and its layers as a ParaView .pvti over one .vti piece per tile (MPI rank)",
        .description =
            "The same points and arrays as export:vtk's .vti, cut into pieces: under mpirun each rank writes its own "
            "tile as NAME_RANK.vti (with the first column and row of its east and south neighbours, so the pieces "
            "meet without a gap), rank 0 the .pvti that lists them; a single process writes one piece. Open the "
            ".pvti in ParaView (or read it with vtkXMLPImageDataReader).",
        .inputs = {{"terrain", ValueType::heightmap, Need::required, "the heightmap to write"}},
        .output = ValueType::none,
        .params =
            {
                Param::path("path", PathRole::output, {".pvti"})
                    .help("output .pvti; the pieces NAME_RANK.vti go beside it"),
                up_param(),
                compress_param(),
            },
        .tile_halo = 1,
        .run = run_tiles,
    });
    registry.add({
        .kind = "export",
        .name = "vtk-particles",
        .summary = "write particle frames for ParaView: one .vtp per frame with every attribute, and a .pvd",
        .description =
            "Positions in metres (up=z: X east, Y north, Z up; up=y: X east, Y up, Z south), vectors "
            "(velocity) turned the same way; every other attribute (velocity, density, "
            "sediment...) as a point array. A .pvd lists the frames with their times so ParaView plays them.",
        .inputs = {{"particles", ValueType::particles, Need::required,
                    "particle frames (e.g. an SPH eroder's .particles)"}},
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
