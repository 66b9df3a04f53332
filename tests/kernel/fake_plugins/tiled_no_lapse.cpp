// A tiled node (tile_halo 0) with a time-lapse parameter that does not gather
// its frames under mpirun (no tiled_timelapse), as a third-party plugin may
// be: the kernel must refuse timelapse_every > 0 in a tiled run at check time.
//   erode:test-tiled-no-lapse(terrain, timelapse_every)  returns its input
#include <orogen/plugin.hpp>
#include <orogen/timelapse.hpp>

using namespace orogen;

OROGEN_PLUGIN("test-tiled-no-lapse", "0.0.1", registry) {
    registry.add({.kind = "erode",
                  .name = "test-tiled-no-lapse",
                  .summary = "returns its input; tiled, but records no time-lapse under mpirun",
                  .inputs = {{"terrain", ValueType::heightmap, Need::required, ""}},
                  .output = ValueType::heightmap,
                  .side_outputs = {timelapse_output()},
                  .params = {timelapse_param()},
                  .tile_halo = 0,
                  .run = [](NodeContext& ctx) -> NodeOutputs { return NodeOutputs(ctx.take_heightmap(0)); }});
}
