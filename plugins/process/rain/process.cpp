// process rain — rain that follows the relief (Smith & Barstad 2004): once a step, the rain a steady
// moist wind leaves on the current heights, on a coarse grid, as each cell's rain over the background
// (the rain_factor field) that weighs the drainage area of a flow process after it. The wet windward
// flank's rivers then cut faster than the dry lee's. libs/climate/orographic_rain.hpp.
#include <orogen/climate/orographic_rain.hpp>
#include <orogen/landscape/stream_power.hpp>

#include <orogen/plugin.hpp>

namespace {

using namespace orogen;

struct Rain {
    double background = 1.0;  // m/yr
    double wind_from = 270.0;  // °
    double wind_speed = 10.0;  // m/s
    double wind_share = 0.1;
    double condensation_time = 1000.0;  // s
    double fallout_time = 1000.0;  // s
    double moist_stability = 0.005;  // 1/s
    double vapour_scale_height = 2500.0;  // m
    double uplift_sensitivity = 0.0083;  // kg/m³
    double resolution = 250.0;  // m
};

class RainProcess final : public Process {
public:
    explicit RainProcess(const Rain& s) : resolution_(s.resolution) {
        rain_.background = s.background;
        rain_.wind_from = s.wind_from;
        rain_.wind_speed = s.wind_speed;
        rain_.wind_share = s.wind_share;
        rain_.condensation_time = s.condensation_time;
        rain_.fallout_time = s.fallout_time;
        rain_.moist_stability = s.moist_stability;
        rain_.vapour_scale_height = s.vapour_scale_height;
        rain_.uplift_sensitivity = s.uplift_sensitivity;
    }

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
    ProcessParams<Rain> p;
    p.real(&Rain::background, "background")
        .min(0.0, true)
        .max(20.0)
        .unit("m/yr")
        .help("the mean annual rain on flat ground (0.3-3 m/yr)");
    p.real(&Rain::wind_from, "wind_from")
        .min(0.0)
        .max(360.0)
        .unit("°")
        .help("azimuth the moist wind blows from, clockwise from north (270: westerly)");
    p.real(&Rain::wind_speed, "wind_speed").min(0.0).max(60.0).unit("m/s").help("the moist wind's speed (5-20 m/s)");
    p.real(&Rain::wind_share, "wind_share")
        .min(0.0, true)
        .max(1.0)
        .help(
            "share of the year the moist wind blows; the rest of the year other "
            "weather rains rain_background evenly, so the lee keeps (1 - wind_share) of it");
    p.real(&Rain::condensation_time, "condensation_time")
        .min(0.0)
        .max(1e5)
        .unit("s")
        .help(
            "tau_c, cloud water to rain and snow (200-2000 s); longer carries the "
            "rain further downwind");
    p.real(&Rain::fallout_time, "fallout_time")
        .min(0.0)
        .max(1e5)
        .unit("s")
        .help("tau_f, the time rain and snow take to fall (200-2000 s)");
    p.real(&Rain::moist_stability, "moist_stability")
        .min(0.0)
        .max(0.05)
        .unit("1/s")
        .help("N_m, the moist buoyancy frequency (0-0.01; 0 = neutral air)");
    p.real(&Rain::vapour_scale_height, "vapour_scale_height")
        .min(0.0)
        .max(2e4)
        .unit("m")
        .help("H_w, the water vapour's scale height (1-4 km)");
    p.real(&Rain::uplift_sensitivity, "uplift_sensitivity")
        .min(0.0)
        .max(0.1)
        .unit("kg/m³")
        .help("C_w, water condensed per metre of lift (0.004-0.01; warm air more)");
    p.real(&Rain::resolution, "resolution")
        .min(1.0)
        .max(1e5)
        .unit("m")
        .help(
            "the grid the rain is computed on (whole cells; the theory smooths "
            "below a few km)");
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
        .make = [p](const ProcessCall& call) -> std::unique_ptr<Process> {
            return std::make_unique<RainProcess>(p.bind(call.params));
        },
    });
}
