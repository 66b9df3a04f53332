// libFuzzer target: `--set NAME.PARAM=VALUE` overrides (one per line of the input) applied to a spec that
// uses every parameter type (integer, real, boolean, choice, point, points, path).
#include "fuzz_support.hpp"

namespace {
const char* spec =
    "orogen 1\nseed 3\ngrid 33 cell=10\n"
    "crust = generate:diamond-square(roughness=0.6, amplitude=250)\n"
    "fault = generate:fault(crust, iterations=10)\n"
    "summit = generate:rmp(fault, peaks=[(0.62, 0.38), (0.2, 0.2)], iterations=6, cones=4)\n"
    "shape = generate:shape(kind=pyramid)\n"
    "plates = tectonics:plates(crust, plates=3, steps=10)\n"
    "scree = erode:thermal(summit, talus=38, iterations=4, rule=moore)\n"
    "rivers = erode:pipe(scree, steps=8, boundary=open)\n"
    "wet = erode:hydraulic(rivers, iterations=4)\n"
    "export:png(wet, path=\"t.png\", bits=16)\n"
    "export:raw(wet, path=\"t.r16\")\n"
    "export:gltf(wet, path=\"t.glb\")\n"
    "export:vtk(wet, path=\"t.vti\")\n";
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    std::vector<std::string> overrides;
    std::string line;
    for (std::size_t i = 0; i < size; ++i) {
        if (data[i] == '\n') {
            overrides.push_back(std::move(line));
            line.clear();
        } else {
            line += char(data[i]);
        }
    }
    if (!line.empty() || overrides.empty()) overrides.push_back(std::move(line));
    if (overrides.size() > 64) overrides.resize(64);
    orogen::fuzz::check_spec(spec, overrides);
    return 0;
}
