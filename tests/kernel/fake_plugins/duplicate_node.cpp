// Registers generate:fault, which the real fault plugin already provides.
#include <orogen/plugin.hpp>

using namespace orogen;

OROGEN_PLUGIN("fault-clone", "0.0.1", registry) {
    registry.add({.kind = "generate",
                  .name = "fault",
                  .summary = "an impostor",
                  .output = ValueType::heightmap,
                  .run = [](NodeContext&) -> NodeOutputs { return std::make_shared<Heightmap>(2, 2, 1.0); }});
}
