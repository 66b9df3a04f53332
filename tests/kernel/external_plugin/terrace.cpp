// terrace.cpp — generate:terrace, cuts a terrain into flat steps
#include <orogen/plugin.hpp>
#include <cmath>

using namespace orogen;

OROGEN_PLUGIN("generate-terrace", "1.0.0", registry) {
    registry.add({
        .kind = "generate",
        .name = "terrace",
        .summary = "cut a terrain into flat steps",
        .inputs = {{"terrain", ValueType::heightmap, Need::required, "the terrain to terrace"}},
        .output = ValueType::heightmap,
        .params = {Param::real("step", 10.0).min(0, true).unit("m").help("height of one terrace")},
        .run = [](NodeContext& ctx) -> NodeOutputs {
            auto hm = ctx.take_heightmap(0);  // the input itself if no later node reads it
            const float step = float(ctx.real("step"));
            for (float& h : hm->heights()) h = step * std::floor(h / step);
            return hm;
        },
    });
}
