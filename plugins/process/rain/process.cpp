// process rain — rain that follows the relief (Smith & Barstad 2004): once a step, the rain a steady
// moist wind leaves on the current heights, on a coarse grid, as each cell's rain over the background
// (the rain_factor field) that weighs the drainage area of a flow process after it. The wet windward
// flank's rivers then cut faster than the dry lee's. libs/climate/orographic_rain.hpp.
#include <orogen/climate/orographic_rain.hpp>
#include <orogen/landscape/stream_power.hpp>

#include <orogen/landscape/processes.hpp>
#include <orogen/plugin.hpp>

namespace {

using namespace orogen;

class RainProcess final : public Process {
public:
    explicit RainProcess(const landscape::RainSpec& s) : rain_(landscape::to_rain(s)), resolution_(s.resolution) {}

    void step(ProcessState& state, double dt) override {
        (void)dt;
        std::vector<double>& weights = state.field("rain_factor");
        climate::orographic_rain_coarse(state.field(kElevation).data(), state.width(), state.height(), state.cell(),
                                        rain_, resolution_, weights, &transfer_);
        landscape::rain_to_weights(weights, rain_.background);
    }

    /// The last step's rain (m/yr) as the layer rain.
    void finish(ProcessState& state, Heightmap& out) override {
        const std::vector<double> rain = landscape::weights_to_rain(state.field("rain_factor"), rain_.background);
        GridView r = out.layer("rain", 0.0f);
        for (std::size_t i = 0; i < rain.size() && i < out.size(); ++i) r.data[i] = float(rain[i]);
    }

private:
    climate::OrographicRain rain_;
    double resolution_;
    climate::RainTransfer transfer_;  // the same every step
};

}  // namespace

OROGEN_PLUGIN("process-rain", "0.1.0", registry) {
    const ProcessParams<landscape::RainSpec> p = landscape::rain_params();
    registry.add(ProcessDescriptor{
        .name = "rain",
        .summary = "orographic rain once a step (Smith & Barstad 2004): weighs the drainage area",
        .description =
            "Once a step, before the flow process, the rain a steady moist wind leaves on the current heights "
            "(Smith & Barstad 2004's linear theory, on a grid of about `resolution` metres): each cell's rain "
            "over the background weighs its share of the drainage area, so stream power's K is the "
            "erodibility under the background rain. After the run: the layer rain (m/yr).",
        .params = p.params(),
        .fields = {{kElevation, FieldAccess::reads, "m", ""},
                   {"rain_factor", FieldAccess::writes, "1", "rain over the background rain, in whole 2^-20"}},
        .cadence = Cadence::once_per_step,
        .adds_layers = {"rain"},
        .tile_halo = 1,  // tiled under mpirun within erode:stream-power's model (landscape/processes.hpp)
        .make = [p](const ProcessCall& call) -> std::unique_ptr<Process> {
            return std::make_unique<RainProcess>(p.bind(call.params));
        },
    });
}
