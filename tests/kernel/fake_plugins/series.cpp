// Nodes that make, map and consume series, for the kernel's series tests:
//   generate:test-frames(frames=N)      a series of N grid-sized heightmaps, entry i filled with i
//   generate:test-add(terrain, amount)  one heightmap in, one out (the kernel maps it over a series)
//   generate:test-either(terrain)       takes a heightmap or a series of them; outputs how many entries it saw
//   export:test-series(s, path, sums) writes "time first-height [sum]" per entry and the most heightmaps alive at once
#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/plugin.hpp>

#include <algorithm>
#include <atomic>
#include <iomanip>
#include <sstream>

using namespace orogen;

namespace {

// Heightmaps made by this plugin and not yet freed: shows whether a consumer
// holds every entry of a series at once or one at a time.
std::atomic<int> alive{0};
std::atomic<int> most_alive{0};

std::shared_ptr<Heightmap> counted(int w, int h, double cell, float fill) {
    const int now = ++alive;
    int seen = most_alive.load();
    while (now > seen && !most_alive.compare_exchange_weak(seen, now)) {}
    return std::shared_ptr<Heightmap>(new Heightmap(w, h, cell, fill), [](Heightmap* p) {
        --alive;
        delete p;
    });
}

}  // namespace

OROGEN_PLUGIN("test-series", "0.0.1", registry) {
    registry.add({.kind = "generate",
                  .name = "test-frames",
                  .summary = "a series of heightmaps filled with 0, 1, 2, ...",
                  .output = ValueType::heightmap,
                  .output_series = true,
                  .params = {Param::integer("frames", 3).min(0).max(1000)},
                  .run = [](NodeContext& ctx) -> NodeOutputs {
                      auto s = std::make_shared<Series>();
                      s->element = ValueType::heightmap;
                      for (std::int64_t i = 0; i < ctx.integer("frames"); ++i) s->times.push_back(0.5 * double(i));
                      const GridSpec g = ctx.grid();
                      s->make = [g](std::size_t i) -> Value { return counted(g.width, g.height, g.cell, float(i)); };
                      return s;
                  }});
    registry.add({.kind = "generate",
                  .name = "test-add",
                  .summary = "adds `amount` to every height",
                  .inputs = {{"terrain", ValueType::heightmap, Need::required, ""}},
                  .output = ValueType::heightmap,
                  .params = {Param::real("amount", 1.0)},
                  .run = [](NodeContext& ctx) -> NodeOutputs {
                      const auto& in = *ctx.input(0).heightmap();
                      if (in.heights()[0] >= 99.0f) throw BadInput("height 99 is not allowed here");
                      auto out = counted(in.width(), in.height(), in.cell(), 0.0f);
                      for (std::size_t i = 0; i < in.size(); ++i)
                          out->heights()[i] = in.heights()[i] + float(ctx.real("amount"));
                      return out;
                  }});
    registry.add({.kind = "generate",
                  .name = "test-either",
                  .summary = "a heightmap or a series; outputs the entry count",
                  .inputs = {{"terrain", ValueType::heightmap, Need::required, "", Many::either}},
                  .output = ValueType::heightmap,
                  .run = [](NodeContext& ctx) -> NodeOutputs {
                      const Value& v = ctx.input(0);
                      const float n = v.type() == ValueType::series ? float(v.series()->size()) : -1.0f;
                      return std::make_shared<Heightmap>(2, 2, 1.0, n);
                  }});
    registry.add({.kind = "export",
                  .name = "test-series",
                  .summary = "writes each entry's time and first height",
                  .inputs = {{"series", ValueType::heightmap, Need::required, "", Many::series}},
                  .params = {Param::path("path", PathRole::output, {".txt"}),
                             Param::boolean("sums", false).help("also write each entry's sum of heights")},
                  .run = [](NodeContext& ctx) -> NodeOutputs {
                      const auto& s = *ctx.input(0).series();
                      most_alive = alive.load();
                      std::ostringstream text;
                      for (std::size_t i = 0; i < s.size(); ++i) {
                          const Value v = s.at(i);
                          const auto& h = v.heightmap()->heights();
                          double sum = 0.0;
                          for (float x : h) sum += x;
                          text << s.times[i] << ' ' << std::setprecision(9) << h[0] << std::setprecision(6);
                          if (ctx.flag("sums")) text << ' ' << std::setprecision(17) << sum << std::setprecision(6);
                          text << '\n';
                      }
                      text << "most alive " << most_alive.load() << '\n';
                      const std::string t = text.str();
                      write_file_atomically(ctx.output_path(ctx.text("path")),
                                            {reinterpret_cast<const std::uint8_t*>(t.data()), t.size()});
                      return {};
                  }});
}
