// bench-links: orogen_kernel
// Loading every plugin and checking the spec: target ≤ 50 ms. This is
// what `orogen check` does before anything runs (process start-up aside).
#include "run/loader.hpp"
#include "spec/plan.hpp"
#include "spec/spec.hpp"

#include <benchmark/benchmark.h>

namespace {
const char* spec_text =
    "orogen 1\nseed 7\ngrid 513 cell=30\n\n"
    "base = generate:diamond-square(roughness=0.6, amplitude=800)\n"
    "cut  = generate:fault(base, iterations=200, displacement=4)\n"
    "export:png(cut, path=\"cut.png\", bits=16)\n"
    "export:png(base, path=\"base.png\")\n";
}

static void BM_LoadPluginsAndCheckSpec(benchmark::State& state) {
    for (auto _ : state) {
        orogen::PluginSet plugins;
        plugins.load_all(OROGEN_CLI);  // the plugin folder beside the real binary
        auto source = std::make_shared<orogen::spec::Source>("issue.orogen", spec_text);
        orogen::spec::Diagnostics diags;
        const auto parsed = orogen::spec::parse(source, diags);
        const auto plan = orogen::check(parsed, plugins.registry(), "issue.orogen", {}, diags);
        if (diags.has_errors() || plan.nodes.size() != 4) state.SkipWithError("the spec did not check");
        state.counters["plugins"] = double(plugins.plugins().size());
    }
}
BENCHMARK(BM_LoadPluginsAndCheckSpec)->Unit(benchmark::kMillisecond)->UseRealTime();
