// generate:fault — registers the Fault core as a node.
#include "fault.hpp"

#include <orogen/plugin.hpp>

using namespace orogen;

OROGEN_PLUGIN("generate-fault", "0.1.0", registry) {
    registry.add({
        .kind = "generate",
        .name = "fault",
        .summary = "Fault algorithm (Krten; thesis 3.2): random lines raise one side, lower the other",
        .description = "Each iteration draws a random line; vertices on one side rise by `displacement`, the\n"
                       "others sink by it. Many lines give cliffs and plateaus; smooth the result with\n"
                       "erode:thermal. With no input, starts from the spec's grid, flat at 0 m.",
        .inputs = {{"base", ValueType::heightmap, Need::optional,
                    "terrain to cut (default: the spec's grid, flat at 0 m)"}},
        .output = ValueType::heightmap,
        .params =
            {
                Param::integer("iterations", 200).min(1).max(1'000'000).help("number of fault lines"),
                Param::real("displacement", 1.0).min(0).max(1e5).unit("m").help("raise and lower per line"),
            },
        .tile_halo = 0,  // each vertex is a pure function of the seed and its global position
        .run = [](NodeContext& ctx) -> NodeOutputs {
            // Under MPI (ctx.tiling()), the heightmaps are this rank's tile.
            const Tiling* tiles = ctx.tiling();
            const TileRect area = tiles ? tiles->owned() : TileRect{0, 0, ctx.grid().width, ctx.grid().height};
            auto hm = ctx.has_input(0) ? ctx.take_heightmap(0)
                                       : std::make_shared<Heightmap>(area.width, area.height, ctx.grid().cell);
            // With an input, its size is the grid (apply() cuts it as the whole grid's lines).
            const int grid_w = tiles ? tiles->grid_width() : hm->width(),
                      grid_h = tiles ? tiles->grid_height() : hm->height();
            fault::apply_tile(hm->view(), grid_w, grid_h, area.x0, area.y0, int(ctx.integer("iterations")),
                              ctx.real("displacement"), ctx.seed());
            ctx.progress(1.0);
            return hm;
        },
    });
}
