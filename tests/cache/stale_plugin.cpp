// A plugin built twice from this file (tests/cache/CMakeLists.txt), with STALE_ELEVATION 1 and 2, into two
// folders: the same plugin name, version and node, different code. The cache must tell the two builds apart
// (docs/cache.md, "Which binary ran"): a rebuilt plugin never finds the old build's results.
//   generate:test-stale()   a flat heightmap at STALE_ELEVATION metres
#include <orogen/plugin.hpp>

using namespace orogen;

OROGEN_PLUGIN("test-stale", "0.1.0", registry) {
    registry.add({.kind = "generate",
                  .name = "test-stale",
                  .summary = "a flat heightmap at the build's elevation",
                  .output = ValueType::heightmap,
                  .run = [](NodeContext& ctx) -> NodeOutputs {
                      const GridSpec g = ctx.grid();
                      return std::make_shared<Heightmap>(g.width, g.height, g.cell, float(STALE_ELEVATION));
                  }});
}
