// processes.hpp — the built-in processes of erode:evolve's loop (plugins/process/*), as plain C++: each
// one's parameters in the spec's units (a struct, its members' initialisers the defaults), their
// declaration bound to those members (ProcessParams, orogen/process.hpp), and the conversion to the
// model's own structs (radians, tangents). The process plugins register them; erode:evolve also lowers
// a body of them, in erode:stream-power's order, to that node's model (Settings), which runs tiled under
// mpirun (tiled.hpp) and gives the same bits as the loop.
#pragma once

#include "glaciers.hpp"
#include "stream_power.hpp"
#include "uplift.hpp"

#include <orogen/climate/orographic_rain.hpp>
#include <orogen/process.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace orogen::landscape {

/// uplift(...)'s parameters, in the spec's units.
struct UpliftSpec {
    double rate = 1.0;  // mm/yr
    std::string layer;
    double layer_years = 1e6;  // yr
    double smoothing = 0.0;  // m
    double edge_taper = 0.0;  // m
    double history_years = 0.0;  // yr (0: the run's)
};
ProcessParams<UpliftSpec> uplift_params();

/// rain(...)'s parameters, in the spec's units.
struct RainSpec {
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
ProcessParams<RainSpec> rain_params();

/// flow(...)'s parameters, in the spec's units.
struct FlowSpec {
    std::string routing = "d8";
    double mfd_exponent = 1.1;
    std::string depressions = "fill";
};
ProcessParams<FlowSpec> flow_params();

/// creep(...)'s parameters, in the spec's units.
struct CreepSpec {
    double diffusivity = 0.01;  // m²/yr
};
ProcessParams<CreepSpec> creep_params();

/// rock(...)'s parameters, in the spec's units.
struct RockSpec {
    double angle = 0.0;  // °
    double block_spread = 0.0;
    double thickness = 0.0;  // m
    double dip = 0.0;  // °
    double dip_toward = 0.0;  // °, clockwise from north
    double angle_spread = 0.0;  // °
    double erodibility_contrast = 1.0;
    double fold_amplitude = 0.0;  // m
    double fold_wavelength = 5000.0;  // m
    double thickness_spread = 0.0;
    double fault_spacing = 0.0;  // m
    double fault_throw = 0.0;  // m
    double facies_length = 0.0;  // m
    double facies_share = 0.5;
};
ProcessParams<RockSpec> rock_params();

/// stream-power(...)'s parameters, in the spec's units.
struct StreamPowerSpec {
    double erodibility = 2e-5;  // m^(1-2m)/yr
    double m = 0.45;
    double n = 1.0;
    double channel_area = 0.0;  // m²
    double deposition = 0.0;
};
ProcessParams<StreamPowerSpec> stream_power_params();

/// banks(...)'s parameters, in the spec's units.
struct BanksSpec {
    double erosion = 4.0;
    double area = 1e6;  // m²
    double floor_slope = 1.0;  // °
    double wide_area = 0.0;  // m²
    double wider_area = 0.0;  // m²
    int widest_floor = 0;  // cells
};
ProcessParams<BanksSpec> banks_params();

/// floodplains(...)'s parameters, in the spec's units.
struct FloodplainsSpec {
    double area = 2e6;  // m²
    double width = 30.0;  // m
    double exponent = 0.5;
    double slope = 2.0;  // °
    double max_slope = 0.0;  // °
};
ProcessParams<FloodplainsSpec> floodplains_params();

/// landslides(...)'s parameters, in the spec's units.
struct LandslidesSpec {
    double angle = 35.0;  // °
};
ProcessParams<LandslidesSpec> landslides_params();

/// glaciers(...)'s parameters, in the spec's units.
struct GlaciersSpec {
    double ela = 2500.0;  // m
    double balance_gradient = 0.007;  // 1/yr
    double max_balance = 2.0;  // m/yr
    double erodibility = 2e-6;
    double flux_exponent = 0.5;
    double min_flux = 2e5;  // m³/yr
};
ProcessParams<GlaciersSpec> glaciers_params();

/// troughs(...)'s parameters, in the spec's units.
struct TroughsSpec {
    double half_width = 400.0;  // m
    double wall_angle = 40.0;  // °
    double min_flux = 2e5;  // m³/yr
};
ProcessParams<TroughsSpec> troughs_params();

/// chi(...)'s parameters.
struct ChiSpec {
    double concavity = 0.45;  // m/n
    double reference_area = 1.0;  // m²
};
ProcessParams<ChiSpec> chi_params();

UpliftSources to_sources(const UpliftSpec& s);
/// The glaciers of both processes (glaciers makes the ice, troughs carves with it).
Glaciers to_glaciers(const GlaciersSpec& g, const TroughsSpec& t);
climate::OrographicRain to_rain(const RainSpec& s);
Depressions to_depressions(const FlowSpec& s);
/// The multiple-flow-direction exponent, 0 for D8.
double to_mfd_exponent(const FlowSpec& s);
Beds to_beds(const RockSpec& s, std::uint64_t seed);
Banks to_banks(const BanksSpec& s);
Floodplain to_floodplain(const FloodplainsSpec& s);
/// tan of the landslides' own angle, by the rock's expression for its mean angle (so the same bits).
double to_landslide_slope(const LandslidesSpec& s);

/// The rock's cross-parameter checks, for rock(...) and for erode:stream-power, whose names differ
/// (bed_dip for dip, landslide_angle for angle): `name(p)` is the caller's name for rock's parameter p.
/// A shaping parameter without its process is an error only where the process's switch is not given at
/// all (forgotten); a switch given as off turns the process off on purpose. `Context` is a node's
/// CheckContext or a process's ProcessCheckContext.
template <class Context, class Name>
void check_rock(Context& ctx, Name name) {
    const auto real = [&](const char* p) { return ctx.real(name(p)); };
    const auto given = [&](const char* p) { return ctx.given(name(p)); };
    const auto error = [&](const char* p, const std::string& message) { ctx.error(name(p), message); };
    if (!(real("thickness") > 0.0) && !given("thickness"))
        for (const char* p :
             {"dip", "dip_toward", "angle_spread", "erodibility_contrast", "fold_amplitude", "fold_wavelength",
              "thickness_spread", "fault_spacing", "fault_throw", "facies_length", "facies_share"})
            if (given(p)) error(p, name(p) + " describes the rock's beds; give " + name("thickness") + " (m) as well");
    if ((real("fault_spacing") > 0.0) != (real("fault_throw") > 0.0) &&
        !given(real("fault_spacing") > 0.0 ? "fault_throw" : "fault_spacing"))
        error(real("fault_spacing") > 0.0 ? "fault_spacing" : "fault_throw",
              "faults need both a spacing and a throw; give " + name("fault_spacing") + " (m) and " +
                  name("fault_throw") + " (m)");
    if (const double spacing = real("fault_spacing"); spacing > 0.0 && spacing < 100.0)
        error("fault_spacing",
              "faults closer than 100 m apart would shatter the rock cell by cell; give " + name("fault_spacing") +
                  " >= 100 (m), or 0 for no faults");
    if (const double length = real("facies_length"); length > 0.0 && length < 100.0)
        error("facies_length",
              "facies changing within less than 100 m would speckle the beds cell by cell; give " +
                  name("facies_length") + " >= 100 (m), or 0 for beds of one strength each");
    if (given("facies_share") && !(real("facies_length") > 0.0) && !given("facies_length"))
        error("facies_share",
              name("facies_share") + " sets how much the facies change a bed's strength; give " +
                  name("facies_length") + " (m) as well");
    if (real("block_spread") > 0.0 && !(real("angle") > 0.0) && !given("angle"))
        error("block_spread",
              name("block_spread") + " roughens the landslide slopes; give " + name("angle") + " as well");
    if (given("angle_spread") && !(real("angle") > 0.0) && !given("angle"))
        error("angle_spread",
              name("angle_spread") + " spreads the landslide angle; give " + name("angle") + " as well");
    if (const double a = real("angle"), spread = real("angle_spread");
        a > 0.0 && (a - spread < 5.0 || a + spread > 80.0))
        error("angle_spread",
              "the beds' landslide angles run " + name("angle") + " ± " + name("angle_spread") +
                  ", which must stay within 5-80°; give a smaller spread");
}

/// The banks' floors' cross-parameter checks, for banks(...) and erode:stream-power (bank_wide_area for
/// wide_area): `name` as check_rock's.
template <class Context, class Name>
void check_banks(Context& ctx, Name name) {
    const auto real = [&](const char* p) { return ctx.real(name(p)); };
    if (real("wider_area") > 0.0) {
        if (!(real("wide_area") > 0.0))
            ctx.error(name("wider_area"),
                      name("wider_area") + " widens the floors " + name("wide_area") + " makes; give " +
                          name("wide_area") + " as well");
        else if (real("wider_area") < real("wide_area"))
            ctx.error(name("wider_area"),
                      name("wider_area") + " is smaller than " + name("wide_area") +
                          ": the seven-cell floors start where the five-cell ones do at the earliest; give " +
                          name("wider_area") + " >= " + name("wide_area"));
    }
    if (const auto widest = ctx.integer(name("widest_floor")); widest > 0) {
        if (widest % 2 == 0 || widest < 7)
            ctx.error(name("widest_floor"),
                      name("widest_floor") + " is " + std::to_string(widest) +
                          ": floors are an odd number of cells wide, the river in the middle, "
                          "and seven or more (" +
                          name("wider_area") + " makes seven); give 7, 9, 11, …");
        else if (!(real("wider_area") > real("wide_area") && real("wide_area") > 0.0))
            ctx.error(name("widest_floor"),
                      name("widest_floor") +
                          " widens the floors past seven cells each time the drainage area "
                          "grows by " +
                          name("wider_area") + " / " + name("wide_area") + "; give " + name("wider_area") + " > " +
                          name("wide_area") + " > 0");
    }
}

/// erode:stream-power's model for a body of the built-in processes: its settings, the uplift's
/// sources, and why not ("" when it is one). A body is one when its processes are built-in ones, each
/// at most once, in the model's order (uplift, rain, flow, creep, rock, glaciers, stream-power, banks,
/// floodplains, troughs, landslides, chi), with flow and stream-power, glaciers and troughs together
/// with one min_flux, and the rock's and the landslides' angles agree (the model slides at the rock's
/// angle exactly when it has one).
struct LoweredBody {
    Settings settings;
    UpliftSources uplift;
    bool chi = false;  ///< a chi process (the model's chi layer, at its m/n)
    std::string why_not;  ///< "" when the body is the model
};
LoweredBody lower_to_model(const std::vector<ProcessCall>& body, std::uint64_t seed);

}  // namespace orogen::landscape
