// generate:fault — registers the Fault core as a node.
#include "fault.hpp"

#include <orogen/plugin.hpp>

using namespace orogen;

OROGEN_PLUGIN("fault", "0.1.0", registry) {
    registry.add({
        .kind = "generate",
        .name = "fault",
        .summary = "Fault algorithm (Krten; thesis 3.2): random lines raise one side, lower the other",
        .description =
            "Each iteration draws a random line; vertices on one side rise by `displacement`, the\n"
            "others sink by it. Many lines give cliffs and plateaus; smooth the result with\n"
            "erode:thermal. With no input, starts from the spec's grid, flat at 0 m.",
        .inputs = {{"base", ValueType::heightmap, Need::optional, "terrain to cut (default: the spec's grid, flat at 0 m)"}},
        .output = ValueType::heightmap,
        .params =
            {
                Param::integer("iterations", 200).min(1).max(1'000'000).help("number of fault lines"),
                Param::real("displacement", 1.0).min(0).max(1e5).unit("m").help("raise and lower per line"),
            },
        .run = [](NodeContext& ctx) -> NodeOutputs {
            auto hm = ctx.has_input(0) ? ctx.take_heightmap(0)
                                       : std::make_shared<Heightmap>(ctx.grid().width, ctx.grid().height, ctx.grid().cell);
            fault::apply(hm->view(), int(ctx.integer("iterations")), ctx.real("displacement"), ctx.seed());
            ctx.progress(1.0);
            return hm;
        },
    });
}
