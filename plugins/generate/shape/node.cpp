// generate:shape — analytic test surfaces as a node.
#include "shape.hpp"

#include <orogen/plugin.hpp>

using namespace orogen;

OROGEN_PLUGIN("generate-shape", "0.1.0", registry) {
    registry.add({
        .kind = "generate",
        .name = "shape",
        .summary = "Analytic test surfaces: crooked, pyramid, hemisphere (thesis 4.1), flat, plane, cone",
        .description = "Sized by the spec's grid. pyramid, hemisphere and cone stand on the centre with the\n"
                       "largest footprint that fits (hemisphere and cone: radius half the shorter side), 0 m\n"
                       "around; crooked is a surface falling south with twisted ridges, 0..height; flat is\n"
                       "`height` everywhere; plane is `height` at its lowest corner and rises at `slope`\n"
                       "degrees toward `direction` (0 = east, 90 = south).",
        .output = ValueType::heightmap,
        .params =
            {
                Param::choice("kind", {"crooked", "pyramid", "hemisphere", "flat", "plane", "cone"}, "pyramid")
                    .help("which surface"),
                Param::real("height", 100.0)
                    .min(-1e5)
                    .max(1e5)
                    .unit("m")
                    .help("top of the shape (flat: its level; plane: its lowest corner)"),
                Param::real("slope", 10.0).min(0).max(89).unit("°").help("plane only: its steepness"),
                Param::real("direction", 0.0)
                    .min(-360)
                    .max(360)
                    .unit("°")
                    .help("plane only: the way it rises, 0 = east, 90 = south"),
            },
        .check =
            [](CheckContext& ctx) {
                if (ctx.text("kind") != "plane")
                    for (const char* p : {"slope", "direction"})
                        if (ctx.given(p))
                            ctx.error(
                                p,
                                std::string(p) + " applies to kind=plane only; this shape is kind=" + ctx.text("kind"));
            },
        .run = [](NodeContext& ctx) -> NodeOutputs {
            auto hm = std::make_shared<Heightmap>(ctx.grid().width, ctx.grid().height, ctx.grid().cell);
            shape::ShapeParams p;
            p.kind = shape::kind_from_name(ctx.text("kind"));
            p.height = ctx.real("height");
            p.slope = ctx.real("slope");
            p.direction = ctx.real("direction");
            shape::make_shape(hm->view(), p);
            ctx.progress(1.0);
            return hm;
        },
    });
}
