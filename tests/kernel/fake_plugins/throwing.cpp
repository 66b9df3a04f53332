// Nodes that fail at run time, in each way a plugin can: an orogen::Error, a
// BadInput, a foreign exception, a wrong return type, a NaN (via check_finite).
#include <orogen/error.hpp>
#include <orogen/plugin.hpp>

#include <chrono>
#include <cmath>
#include <fstream>
#include <thread>
#include <stdexcept>

using namespace orogen;

OROGEN_PLUGIN("test-throwing", "0.0.1", registry) {
    registry.add({.kind = "generate",
                  .name = "fails",
                  .summary = "throws orogen::Error",
                  .inputs = {{"base", ValueType::heightmap, Need::optional, ""}},
                  .output = ValueType::heightmap,
                  .run = [](NodeContext&) -> NodeOutputs { throw Error("the simulation diverged"); }});
    registry.add({.kind = "generate",
                  .name = "bad-file",
                  .summary = "throws orogen::BadInput",
                  .output = ValueType::heightmap,
                  .run = [](NodeContext&) -> NodeOutputs { throw BadInput("input.dat is not a heightmap"); }});
    registry.add({.kind = "generate",
                  .name = "foreign",
                  .summary = "throws std::logic_error",
                  .output = ValueType::heightmap,
                  .run = [](NodeContext&) -> NodeOutputs { throw std::logic_error("vector::at out of range"); }});
    registry.add({.kind = "generate",
                  .name = "nan",
                  .summary = "produces a NaN",
                  .output = ValueType::heightmap,
                  .run = [](NodeContext& ctx) -> NodeOutputs {
                      auto hm = std::make_shared<Heightmap>(ctx.grid().width, ctx.grid().height, ctx.grid().cell);
                      hm->heights()[5] = std::nanf("");
                      ctx.check_finite(hm->heights(), "height", 17);
                      return hm;
                  }});
    registry.add({.kind = "generate",
                  .name = "wrong-type",
                  .summary = "returns nothing though it declares a heightmap",
                  .output = ValueType::heightmap,
                  .run = [](NodeContext&) -> NodeOutputs { return {}; }});
    registry.add({.kind = "generate",
                  .name = "slow",
                  .summary = "runs for up to 60 s, checking for cancellation",
                  .output = ValueType::heightmap,
                  .params = {Param::real("seconds", 60).min(0).max(60).unit("s")},
                  .run = [](NodeContext& ctx) -> NodeOutputs {
                      const int steps = int(ctx.real("seconds") * 100);
                      for (int i = 0; i < steps; ++i) {
                          std::this_thread::sleep_for(std::chrono::milliseconds(10));
                          ctx.check_cancelled();
                          ctx.progress(i / double(steps));
                      }
                      return std::make_shared<Heightmap>(2, 2, 1.0);
                  }});
    registry.add({.kind = "generate",
                  .name = "stubborn",
                  .summary = "creates stubborn.started in the current folder, then sleeps 30 s without looking at "
                             "cancellation",
                  .output = ValueType::heightmap,
                  .run = [](NodeContext&) -> NodeOutputs {
                      std::ofstream("stubborn.started") << "started\n";
                      std::this_thread::sleep_for(std::chrono::seconds(30));
                      return std::make_shared<Heightmap>(2, 2, 1.0);
                  }});
}
