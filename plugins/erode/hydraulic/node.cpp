// erode:hydraulic — registers Olsen's hydraulic automaton (hydraulic.hpp) with the kernel.
#include "hydraulic.hpp"

#include <orogen/error.hpp>
#include <orogen/plugin.hpp>
#include <orogen/timelapse.hpp>

#include <string>
#include <utility>
#include <vector>

namespace {

using namespace orogen;

NodeOutputs run(NodeContext& ctx) {
    auto hm = ctx.take_heightmap(0);
    hydraulic::Settings s;
    s.rain = ctx.real("rain");
    s.solubility = ctx.real("solubility");
    s.evaporation = ctx.real("evaporation");
    s.capacity = ctx.real("capacity");
    const std::string& hardness = ctx.text("hardness");
    const float* layer = nullptr;
    if (hardness == "steepness") {
        s.hardness = hydraulic::Hardness::steepness;
    } else if (hardness == "constant") {
        s.hardness = hydraulic::Hardness::constant;
    } else {
        s.hardness = hydraulic::Hardness::layer;
        if (!hm->has_layer(hardness)) throw BadInput("hardness: the input has no layer '" + hardness + "'");
    }
    // An input that already carries water and sediment continues from them.
    GridView water = hm->layer("water", 0.0f);
    GridView sediment = hm->layer("sediment", 0.0f);
    GridView eroded = hm->layer("eroded", 0.0f);
    if (s.hardness == hydraulic::Hardness::layer) layer = std::as_const(*hm).layer(hardness).data;

    const std::vector<float> before = hm->heights();
    const std::int64_t iterations = ctx.integer("iterations");
    Timelapse lapse(ctx.integer("timelapse_every"), 1.0);  // time = step count
    lapse.record(0, *hm);
    hydraulic::erode({hm->view(), water, sediment}, iterations, s, layer,
                     [&](std::int64_t i, const hydraulic::ConstState& st) {
                         ctx.check_cancelled();
                         lapse.record(i, st.height, st.water.data);
                         if (i % 64 == 0 || i == iterations) {
                             ctx.check_finite(st.height.span(), "height", i);
                             ctx.check_finite(st.water.span(), "water", i);
                             ctx.check_finite(st.sediment.span(), "sediment", i);
                             ctx.progress(double(i) / double(iterations));
                         }
                     });
    const std::vector<float>& after = hm->heights();
    for (std::size_t i = 0; i < after.size(); ++i) eroded.data[i] += after[i] - before[i];
    // Where the water runs: what each cell would send downhill next step. This
    // automaton moved the water itself, so a pipe model's flux state from an
    // earlier node no longer describes it (and erode:pipe reads `flow` as its
    // speed only together with its fluxes): drop them.
    for (const char* l : {"flux_west", "flux_east", "flux_north", "flux_south"}) hm->remove_layer(l);
    GridView flow = hm->layer("flow", 0.0f);
    hydraulic::outflow({hm->view(), water, sediment}, s, layer, flow);
    if (s.hardness == hydraulic::Hardness::steepness) hydraulic::steepness_hardness(hm->view(), hm->layer("hardness", 0.0f));
    lapse.finish(iterations, *hm);
    NodeOutputs out(hm);
    if (lapse.enabled()) out.side["timelapse"] = Value(lapse.series());
    return out;
}

void check(CheckContext& ctx) {
    const std::string& hardness = ctx.text("hardness");
    if (hardness != "steepness" && hardness != "constant") {
        ctx.require_layer(0, "hardness", hardness, "use steepness, constant or the name of an existing layer");
    }
    for (const char* l : {"water", "sediment", "eroded", "flow"}) ctx.output().layers.insert(l);
    if (hardness == "steepness") ctx.output().layers.insert("hardness");
    check_timelapse(ctx, ctx.integer("iterations"));
}

}  // namespace

OROGEN_PLUGIN("erode-hydraulic", "0.1.0", registry) {
    registry.add({
        .kind = "erode",
        .name = "hydraulic",
        .summary = "Olsen's hydraulic erosion automaton: rain dissolves terrain, water carries it downhill",
        .description =
            "Olsen's four-step cellular automaton (thesis section 3.5.1, fig. 3.18). Each step: rain on every "
            "cell; water dissolves solubility * water * softness of terrain (softness = (1 - |n_y|)^3, the "
            "thesis's steepness hardness, by default); water and its sediment flow to lower 4-neighbours by "
            "Olsen's two cases (level out, or drain completely); a fraction of the water evaporates and sediment "
            "above capacity * water is deposited. Water and sediment persist between steps and between nodes: "
            "an input carrying water and sediment layers continues from them. Terrain + sediment is conserved. "
            "Adds the layers water (m), sediment (m), eroded (net terrain change, m), flow (water each cell "
            "sends downhill per step at the end, m) and, with hardness=steepness, hardness (1 on flat ground, "
            "falling toward 0 on cliffs).",
        .inputs = {{"terrain", ValueType::heightmap, Need::required, "heightmap to erode"}},
        .output = ValueType::heightmap,
        .side_outputs = {timelapse_output()},
        .params =
            {
                Param::integer("iterations", 100).min(0).max(10'000'000).help("number of steps"),
                Param::real("rain", 0.01).min(0.0).unit("m").help("water added to every cell per step (Kr)"),
                Param::real("solubility", 0.01)
                    .min(0.0)
                    .max(1.0)
                    .help("terrain dissolved per metre of water per step, before hardness (Ks)"),
                Param::real("evaporation", 0.5)
                    .min(0.0)
                    .max(1.0)
                    .help("fraction of the water that evaporates per step (Ke)"),
                Param::real("capacity", 0.05)
                    .min(0.0)
                    .help("sediment a metre of water can hold, in metres (Kc); the rest is deposited"),
                Param::string("hardness", "steepness")
                    .help("steepness (the thesis's (1 - |n_y|)^3: flat ground resists), constant, or the name of a "
                          "layer holding hardness 0..1"),
                timelapse_param(),
            },
        .adds_layers = {"water", "sediment", "eroded", "flow"},
        .check = check,
        .run = run,
    });
}
