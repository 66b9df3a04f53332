// generate:diamond-square — registers the Diamond-Square core as a node.
#include "diamond_square.hpp"

#include <orogen/plugin.hpp>
#include <orogen/tiles.hpp>

using namespace orogen;

OROGEN_PLUGIN("generate-diamond-square", "0.1.0", registry) {
    registry.add({
        .kind = "generate",
        .name = "diamond-square",
        .summary = "Diamond-Square fractal terrain (Fournier et al.; thesis 3.1), any grid size",
        .description = "Corners get random heights, then diamond and square steps alternate, the random offset\n"
                       "multiplied by `roughness` each level (0.5 halves it, as the thesis does). With an input,\n"
                       "the fractal is added to it.",
        .inputs = {{"base", ValueType::heightmap, Need::optional,
                    "terrain to add the fractal to (default: the spec's grid, flat at 0 m)"}},
        .output = ValueType::heightmap,
        .params =
            {
                Param::real("roughness", 0.5)
                    .min(0, true)
                    .max(1)
                    .help("offset scale kept per level: higher is rougher"),
                Param::real("amplitude", 100.0)
                    .min(0)
                    .max(1e6)
                    .unit("m")
                    .help("random range of the corners and the first level: ±amplitude"),
            },
        // Tiled: each rank makes its own tile (diamond_square::generate_tile),
        // computing each coarser level only near it; no halo.
        .tile_halo = 0,
        .run = [](NodeContext& ctx) -> NodeOutputs {
            std::shared_ptr<Heightmap> hm;
            const diamond_square::Params params{ctx.real("amplitude"), ctx.real("roughness")};
            if (Tiling* tiles = ctx.tiling()) {
                const TileRect own = tiles->owned();
                Heightmap fractal(own.width, own.height, ctx.grid().cell);
                diamond_square::generate_tile(fractal.view(), own.x0, own.y0, tiles->grid_width(), tiles->grid_height(),
                                              params, ctx.seed());
                if (ctx.has_input(0)) {
                    hm = ctx.take_heightmap(0);  // the base's tile
                    auto& h = hm->heights();
                    const auto& f = fractal.heights();
                    for (std::size_t i = 0; i < h.size(); ++i) h[i] += f[i];
                } else {
                    hm = std::make_shared<Heightmap>(std::move(fractal));
                }
                ctx.progress(1.0);
                return hm;
            }
            if (ctx.has_input(0)) {
                hm = ctx.take_heightmap(0);
                Heightmap fractal(hm->width(), hm->height(), hm->cell());
                diamond_square::generate(fractal.view(), {ctx.real("amplitude"), ctx.real("roughness")}, ctx.seed());
                auto& h = hm->heights();
                const auto& f = fractal.heights();
                for (std::size_t i = 0; i < h.size(); ++i) h[i] += f[i];
            } else {
                hm = std::make_shared<Heightmap>(ctx.grid().width, ctx.grid().height, ctx.grid().cell);
                diamond_square::generate(hm->view(), {ctx.real("amplitude"), ctx.real("roughness")}, ctx.seed());
            }
            ctx.progress(1.0);
            return hm;
        },
    });
}
