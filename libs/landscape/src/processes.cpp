// processes.cpp — the built-in processes' parameters and conversions (see processes.hpp).
#include <orogen/landscape/processes.hpp>

#include <cmath>
#include <numbers>

namespace orogen::landscape {

ProcessParams<UpliftSpec> uplift_params() {
    ProcessParams<UpliftSpec> p;
    p.real(&UpliftSpec::rate, "rate")
        .min(0.0)
        .max(landscape::kMaxUpliftMmYr)
        .unit("mm/yr")
        .help("uniform rock uplift rate (0.1-10 mm/yr in active ranges)");
    p.text(&UpliftSpec::layer, "layer")
        .help("a layer of the terrain read as uplift (m) gained over layer_years, added to `rate`; \"\" = none");
    p.real(&UpliftSpec::layer_years, "layer_years")
        .min(1.0)
        .max(1e9)
        .unit("yr")
        .help("years over which the layer's metres were gained (1e6: metres per Myr = mm/yr)");
    p.real(&UpliftSpec::smoothing, "smoothing")
        .min(0.0)
        .max(1e6)
        .unit("m")
        .help("spread the layer's or history's uplift over about this distance (flexure of the crust; 0 = as is)");
    p.real(&UpliftSpec::edge_taper, "edge_taper")
        .min(0.0)
        .max(1e6)
        .unit("m")
        .help(
            "all of the uplift falls smoothly to zero over this distance towards the open sides, as a range's "
            "falls to its foreland (0 = the same right up to the sides)");
    p.real(&UpliftSpec::history_years, "history_years")
        .min(0.0)
        .max(1e9)
        .unit("yr")
        .help("the years the history's frames span, its first frame year 0 of the run (0 = the run's years)");
    return p;
}

ProcessParams<RainSpec> rain_params() {
    ProcessParams<RainSpec> p;
    p.real(&RainSpec::background, "background")
        .min(0.0, true)
        .max(20.0)
        .unit("m/yr")
        .help("the mean annual rain on flat ground (0.3-3 m/yr)");
    p.real(&RainSpec::wind_from, "wind_from")
        .min(0.0)
        .max(360.0)
        .unit("°")
        .help("azimuth the moist wind blows from, clockwise from north (270: westerly)");
    p.real(&RainSpec::wind_speed, "wind_speed")
        .min(0.0)
        .max(60.0)
        .unit("m/s")
        .help("the moist wind's speed (5-20 m/s)");
    p.real(&RainSpec::wind_share, "wind_share")
        .min(0.0, true)
        .max(1.0)
        .help(
            "share of the year the moist wind blows; the rest of the year other "
            "weather rains rain_background evenly, so the lee keeps (1 - wind_share) of it");
    p.real(&RainSpec::condensation_time, "condensation_time")
        .min(0.0)
        .max(1e5)
        .unit("s")
        .help(
            "tau_c, cloud water to rain and snow (200-2000 s); longer carries the "
            "rain further downwind");
    p.real(&RainSpec::fallout_time, "fallout_time")
        .min(0.0)
        .max(1e5)
        .unit("s")
        .help("tau_f, the time rain and snow take to fall (200-2000 s)");
    p.real(&RainSpec::moist_stability, "moist_stability")
        .min(0.0)
        .max(0.05)
        .unit("1/s")
        .help("N_m, the moist buoyancy frequency (0-0.01; 0 = neutral air)");
    p.real(&RainSpec::vapour_scale_height, "vapour_scale_height")
        .min(0.0)
        .max(2e4)
        .unit("m")
        .help("H_w, the water vapour's scale height (1-4 km)");
    p.real(&RainSpec::uplift_sensitivity, "uplift_sensitivity")
        .min(0.0)
        .max(0.1)
        .unit("kg/m³")
        .help("C_w, water condensed per metre of lift (0.004-0.01; warm air more)");
    p.real(&RainSpec::resolution, "resolution")
        .min(1.0)
        .max(1e5)
        .unit("m")
        .help(
            "the grid the rain is computed on (whole cells; the theory smooths "
            "below a few km)");
    return p;
}

ProcessParams<FlowSpec> flow_params() {
    ProcessParams<FlowSpec> p;
    p.choice(&FlowSpec::routing, "routing", {"d8", "mfd"})
        .help(
            "d8: all the water to the steepest of the 8 neighbours; mfd: the drainage area split among the lower "
            "neighbours by slope^mfd_exponent (Freeman 1991: wider, smoother hillslope areas); the graph's "
            "receivers are the steepest either way");
    p.real(&FlowSpec::mfd_exponent, "mfd_exponent")
        .min(0.0, true)
        .max(100.0)
        .help("routing=mfd: weight of a lower neighbour = slope^p (1.1: Freeman 1991; larger concentrates)");
    p.choice(&FlowSpec::depressions, "depressions", {"fill", "route"})
        .help("fill: each lake is filled to its spill level; route: water crosses it, the heights stay");
    return p;
}

ProcessParams<CreepSpec> creep_params() {
    ProcessParams<CreepSpec> p;
    p.real(&CreepSpec::diffusivity, "diffusivity")
        .min(0.0)
        .max(10.0)
        .unit("m²/yr")
        .help(
            "hillslope diffusivity D (1e-3 to 1e-1 m²/yr measured; ~1 stands in for faster slope processes "
            "at 30 m cells, docs/landscape.md; 0 = none)");
    return p;
}

ProcessParams<RockSpec> rock_params() {
    ProcessParams<RockSpec> p;
    p.real(&RockSpec::angle, "angle")
        .min(0.0)
        .max(80.0)
        .unit("°")
        .help(
            "the rock's mean threshold hillslope angle, its landslide angle (25-40° in ranges that erode fast, "
            "Montgomery & Brandon 2002), which angle_spread and block_spread vary by bed and joint block "
            "into the threshold_slope field that landslides() reads; 0 = none (landslides then use their own)");
    p.real(&RockSpec::block_spread, "block_spread")
        .min(0.0)
        .max(2.0)
        .help(
            "joint blocks: each cell's rock, a cell deep, stands up to this share steeper (tan) than "
            "its bed's landslide slope, from the seed, so threshold hillslopes break into spurs and "
            "chutes instead of planes (0.3-1; 0 = planar)");
    p.real(&RockSpec::thickness, "thickness")
        .min(0.0)
        .max(1e5)
        .unit("m")
        .help(
            "rock in tilted beds of this thickness, each of its own strength (from the seed): strong "
            "beds stand steeper and erode slower. 0 = one rock");
    p.real(&RockSpec::dip, "dip").min(0.0).max(89.0).unit("°").help("the beds' dip (0 = flat-lying)");
    p.real(&RockSpec::dip_toward, "dip_toward")
        .min(0.0)
        .max(360.0)
        .unit("°")
        .help("azimuth the beds dip towards, clockwise from north");
    p.real(&RockSpec::angle_spread, "angle_spread")
        .min(0.0)
        .max(40.0)
        .unit("°")
        .help("landslide angles run angle ± this from the weakest bed to the strongest");
    p.real(&RockSpec::erodibility_contrast, "erodibility_contrast")
        .min(1.0)
        .max(1000.0)
        .help(
            "erodibility of the weakest bed over the strongest's (1 = the same; shale against "
            "sandstone ~10, Sklar & Dietrich 2001)");
    p.real(&RockSpec::fold_amplitude, "fold_amplitude")
        .min(0.0)
        .max(1e5)
        .unit("m")
        .help(
            "folded beds: their surfaces rise and fall by up to this in folds whose axes run along "
            "the strike, so the outcrops bend and end instead of running straight across the map "
            "(a few bed thicknesses; 0 = planar beds)");
    p.real(&RockSpec::fold_wavelength, "fold_wavelength")
        .min(100.0)
        .max(1e6)
        .unit("m")
        .help(
            "the folds' wavelength across their axes (3 times as long along them): 1-10 km in "
            "fold-and-thrust belts");
    p.real(&RockSpec::thickness_spread, "thickness_spread")
        .min(0.0)
        .max(0.95)
        .help(
            "beds of uneven thickness: from (1 - this) to (1 + this) times thickness, so the "
            "outcrops are spaced unevenly (0 = all alike)");
    p.real(&RockSpec::fault_spacing, "fault_spacing")
        .min(0.0)
        .max(1e6)
        .unit("m")
        .help(
            "faulted beds: one fault of random strike, 1-3 times this long, per this square on "
            "average; the outcrops step across each fault (0 = no faults; give fault_throw)");
    p.real(&RockSpec::fault_throw, "fault_throw")
        .min(0.0)
        .max(1e5)
        .unit("m")
        .help(
            "the faults' largest vertical offset of the beds, at a fault's middle (1/4 to all of "
            "it, from the seed; a bed thickness or more to show)");
    p.real(&RockSpec::facies_length, "facies_length")
        .min(0.0)
        .max(1e6)
        .unit("m")
        .help(
            "beds whose facies change along them: each bed's strength drifts over about this "
            "distance, so cliff bands fade into benches along their outcrop and weak beds stiffen "
            "(300 m in make demo: cliff bands break into knobs and gaps; a few km: they fade "
            "along their outcrop; 0 = each bed one strength across the map)");
    p.real(&RockSpec::facies_share, "facies_share")
        .min(0.0)
        .max(1.0)
        .help(
            "how much of a bed's strength its facies set (0 = none, 1 = all: the bed's own strength "
            "is forgotten)");
    return p;
}

ProcessParams<StreamPowerSpec> stream_power_params() {
    ProcessParams<StreamPowerSpec> p;
    p.real(&StreamPowerSpec::erodibility, "erodibility")
        .min(0.0, true)
        .max(1e-2)
        .unit("m^(1-2m)/yr")
        .help(
            "K: 1e-7 (hard rock, dry) to 1e-4 (soft rock, wet) for m ~ 0.5, n = 1 (Stock & Montgomery 1999); "
            "times the erodibility_factor of a rock process before it");
    p.real(&StreamPowerSpec::m, "m")
        .min(0.1)
        .max(1.5)
        .help("area exponent (0.3-0.6 with n = 1; m/n is the concavity, 0.35-0.6 in real rivers)");
    p.real(&StreamPowerSpec::n, "n")
        .min(0.5)
        .max(4.0)
        .help("slope exponent (2/3-2 measured, Whipple & Tucker 1999; up to 4, Lague 2014)");
    p.real(&StreamPowerSpec::channel_area, "channel_area")
        .min(0.0)
        .max(1e10)
        .unit("m²")
        .help(
            "drainage area where rivers take over from hillslopes: incision is scaled by 1 - exp(-A/channel_area), "
            "so smaller catchments are shaped by creep (channel heads at 1e3-1e5 m², Montgomery & Dietrich "
            "1988); 0 = every cell is a river");
    p.real(&StreamPowerSpec::deposition, "deposition")
        .min(0.0)
        .max(10.0)
        .help(
            "G of Yuan et al. (2019), dimensionless: the sediment flux deposits G·Qs/A on its way down (0 = "
            "detachment-limited; ~1 = half the eroded rock settles in the valleys at steady state)");
    return p;
}

ProcessParams<BanksSpec> banks_params() {
    ProcessParams<BanksSpec> p;
    p.real(&BanksSpec::erosion, "erosion")
        .min(0.0)
        .max(10.0)
        .help(
            "each incision lowers the two cells across a river by this many times the river's own lowering, "
            "shared between them (straight on, half each; at a bend the outer bank takes more), never below the "
            "river; 4 = a floor three cells wide; 0 = banks stand");
    p.real(&BanksSpec::area, "area")
        .min(1.0)
        .max(1e12)
        .unit("m²")
        .help(
            "drainage area over which a river is wide and deep enough to undercut its banks: bank erosion is "
            "scaled by 1 - exp(-A/area)");
    p.real(&BanksSpec::floor_slope, "floor_slope")
        .min(0.0)
        .max(30.0)
        .unit("°")
        .help(
            "a bank the river has cut down still rises from the river at this angle, as the aprons along a "
            "valley's foot do (0 = dead flat floors, which hold pits)");
    p.real(&BanksSpec::wide_area, "wide_area")
        .min(0.0)
        .max(1e12)
        .unit("m²")
        .help(
            "rivers draining more keep floors five cells wide rather than three: a bank cut down to its floor "
            "passes the river's push on to the cell beyond it; 0 = three cells everywhere");
    p.real(&BanksSpec::wider_area, "wider_area")
        .min(0.0)
        .max(1e12)
        .unit("m²")
        .help("rivers draining more (and wide_area) keep floors seven cells wide; 0 = five cells at most");
    p.integer(&BanksSpec::widest_floor, "widest_floor")
        .min(0)
        .max(35)
        .unit("cells")
        .help(
            "floors keep widening past seven cells, two cells more each time the drainage area grows by "
            "wider_area / wide_area, up to this many; each two cells cost a pass; 0 = seven at most");
    return p;
}

ProcessParams<FloodplainsSpec> floodplains_params() {
    ProcessParams<FloodplainsSpec> p;
    p.real(&FloodplainsSpec::area, "area")
        .min(0.0)
        .max(1e12)
        .unit("m²")
        .help("rivers draining more than this have floodplains (3e6 = from 3 km²); 0 = none");
    p.real(&FloodplainsSpec::width, "width")
        .min(0.0, true)
        .max(1e5)
        .unit("m")
        .help("the floodplain's half-width for a river draining `area`");
    p.real(&FloodplainsSpec::exponent, "exponent")
        .min(0.0)
        .max(1.0)
        .help(
            "how fast floodplains widen downstream: half-width ∝ A^exponent (real 30 m valleys widen as "
            "A^0.2-0.3 10 m above their rivers)");
    p.real(&FloodplainsSpec::slope, "slope")
        .min(0.0)
        .max(30.0)
        .unit("°")
        .help("a floodplain rises from its river at this angle (0 = dead flat, which holds pits)");
    p.real(&FloodplainsSpec::max_slope, "max_slope")
        .min(0.0)
        .max(60.0)
        .unit("°")
        .help(
            "only rivers no steeper than this (to their receiver) plane a floodplain, as real ones lie along "
            "gentle reaches and none in gorges (2.3 = a 4 % gradient); 0 = every river");
    return p;
}

ProcessParams<LandslidesSpec> landslides_params() {
    ProcessParams<LandslidesSpec> p;
    p.real(&LandslidesSpec::angle, "angle")
        .min(5.0)
        .max(80.0)
        .unit("°")
        .help(
            "threshold hillslope angle where no rock process before it makes a threshold_slope field (25-40° in "
            "ranges that erode fast, Montgomery & Brandon 2002)");
    return p;
}

ProcessParams<GlaciersSpec> glaciers_params() {
    ProcessParams<GlaciersSpec> p;
    p.real(&GlaciersSpec::ela, "ela")
        .min(-1000.0)
        .max(9000.0)
        .unit("m")
        .help(
            "the equilibrium-line altitude, above which snow outlasts the summer (Alps today ~2900 m, in the last "
            "glacial maximum ~1500 m lower)");
    p.real(&GlaciersSpec::balance_gradient, "balance_gradient")
        .min(0.0, true)
        .max(0.1)
        .unit("1/yr")
        .help("metres of ice a year gained per metre above the ELA (0.005-0.01 in the Alps)");
    p.real(&GlaciersSpec::max_balance, "max_balance")
        .min(0.0, true)
        .max(20.0)
        .unit("m/yr")
        .help("the most ice a year any height gains");
    p.real(&GlaciersSpec::erodibility, "erodibility")
        .min(0.0)
        .max(1.0)
        .help("K_g of E = K_g*Q^m_g*S^n, Q the ice flux in m³/yr (n: stream-power's)");
    p.real(&GlaciersSpec::flux_exponent, "flux_exponent").min(0.1).max(1.5).help("m_g of the glacial erosion law");
    p.real(&GlaciersSpec::min_flux, "min_flux")
        .min(0.0)
        .max(1e12)
        .unit("m³/yr")
        .help(
            "the ice flux from which ice slides and erodes; thinner ice (snow on the slopes and peaks) erodes "
            "nothing, so horns and aretes stand above");
    return p;
}

ProcessParams<TroughsSpec> troughs_params() {
    ProcessParams<TroughsSpec> p;
    p.real(&TroughsSpec::half_width, "half_width")
        .min(0.0)
        .max(1e4)
        .unit("m")
        .help(
            "half the width of a glacier carrying 1e6 m³/yr (width grows as Q^0.4, Bahr 1997); its trough is "
            "carved that far on each side");
    p.real(&TroughsSpec::wall_angle, "wall_angle")
        .min(1.0)
        .max(80.0)
        .unit("°")
        .help("the slope of a trough's walls at the glacier's margin");
    p.real(&TroughsSpec::min_flux, "min_flux")
        .min(0.0)
        .max(1e12)
        .unit("m³/yr")
        .help("the ice flux from which a glacier carves a trough (erode:stream-power uses glaciers' min_flux)");
    return p;
}

ProcessParams<ChiSpec> chi_params() {
    ProcessParams<ChiSpec> p;
    p.real(&ChiSpec::concavity, "concavity")
        .min(0.0, true)
        .max(3.0)
        .help("m/n of the rivers' stream-power law (stream-power's m over its n)");
    p.real(&ChiSpec::reference_area, "reference_area")
        .min(0.0, true)
        .max(1e12)
        .unit("m²")
        .help("A_0 of chi = integral of (A_0/A)^(m/n) dx from the outlet upstream");
    return p;
}

namespace {
constexpr double kRad = std::numbers::pi / 180.0;
}  // namespace

Glaciers to_glaciers(const GlaciersSpec& g, const TroughsSpec& t) {
    Glaciers out;
    out.ela = g.ela;
    out.balance_gradient = g.balance_gradient;
    out.max_balance = g.max_balance;
    out.erodibility = g.erodibility;
    out.flux_exponent = g.flux_exponent;
    out.glacier_flux = g.min_flux;
    out.half_width = t.half_width;
    out.wall_slope = std::tan(t.wall_angle * kRad);
    return out;
}

UpliftSources to_sources(const UpliftSpec& s) {
    return UpliftSources{s.rate, s.layer, s.layer_years, s.smoothing, s.edge_taper, s.history_years, ""};
}

climate::OrographicRain to_rain(const RainSpec& s) {
    climate::OrographicRain r;
    r.background = s.background;
    r.wind_from = s.wind_from;
    r.wind_speed = s.wind_speed;
    r.wind_share = s.wind_share;
    r.condensation_time = s.condensation_time;
    r.fallout_time = s.fallout_time;
    r.moist_stability = s.moist_stability;
    r.vapour_scale_height = s.vapour_scale_height;
    r.uplift_sensitivity = s.uplift_sensitivity;
    return r;
}

Depressions to_depressions(const FlowSpec& s) {
    return s.depressions == "route" ? Depressions::route : Depressions::fill;
}

double to_mfd_exponent(const FlowSpec& s) { return s.routing == "mfd" ? s.mfd_exponent : 0.0; }

Beds to_beds(const RockSpec& r, std::uint64_t seed) {
    Beds b;
    b.angle = r.angle * kRad;
    b.thickness = r.thickness;
    b.dip_slope = std::tan(r.dip * kRad);
    // Azimuth clockwise from north; grid x runs east and y south.
    b.dip_east = std::sin(r.dip_toward * kRad);
    b.dip_south = -std::cos(r.dip_toward * kRad);
    b.angle_spread = r.angle_spread * kRad;
    b.erodibility_contrast = r.erodibility_contrast;
    b.fold_amplitude = r.fold_amplitude;
    b.fold_wavelength = r.fold_wavelength;
    b.thickness_spread = r.thickness_spread;
    b.fault_spacing = r.fault_spacing;
    b.fault_throw = r.fault_throw;
    b.block_spread = r.block_spread;
    b.facies_length = r.facies_length;
    b.facies_share = r.facies_share;
    b.seed = seed;
    return b;
}

Banks to_banks(const BanksSpec& s) {
    Banks b;
    b.erosion = s.erosion;
    b.area = s.area;
    b.floor_slope = std::tan(s.floor_slope * kRad);
    b.wide_area = s.wide_area;
    b.wider_area = s.wider_area;
    b.widest_floor = s.widest_floor;
    return b;
}

Floodplain to_floodplain(const FloodplainsSpec& s) {
    Floodplain fp;
    fp.area = s.area;
    fp.width = s.width;
    fp.exponent = s.exponent;
    fp.slope = std::tan(s.slope * kRad);
    fp.max_slope = std::tan(s.max_slope * kRad);
    return fp;
}

double to_landslide_slope(const LandslidesSpec& s) {
    Beds one_rock;
    one_rock.angle = s.angle * kRad;
    return one_rock.landslide_slope(0.5);
}

LoweredBody lower_to_model(const std::vector<ProcessCall>& body, std::uint64_t seed) {
    static const char* order[] = {"uplift",       "rain",  "flow",        "creep",   "rock",       "glaciers",
                                  "stream-power", "banks", "floodplains", "troughs", "landslides", "chi"};
    LoweredBody out;
    Settings& s = out.settings;
    s.diffusivity = 0.0;  // no creep unless the body has it
    out.uplift = to_sources(UpliftSpec{});
    out.uplift.uniform = 0.0;  // no uplift unless the body has it
    std::size_t next = 0;
    bool flow = false, incision = false;
    std::optional<double> rock_angle, slide_angle;
    std::optional<GlaciersSpec> glaciers;
    std::optional<TroughsSpec> troughs;
    std::optional<ChiSpec> chi;
    for (const ProcessCall& call : body) {
        const std::string& name = call.process->name;
        std::size_t k = next;
        while (k < std::size(order) && name != order[k]) ++k;
        if (k == std::size(order)) {
            out.why_not = "process " + call.label +
                " is not one of the built-in processes in erode:stream-power's "
                "order (uplift, rain, flow, creep, rock, stream-power, banks, floodplains, landslides)";
            return out;
        }
        next = k + 1;
        if (name == "uplift") out.uplift = to_sources(uplift_params().bind(call.params));
        else if (name == "rain") {
            const RainSpec r = rain_params().bind(call.params);
            s.orographic_rain = true;
            s.rain = to_rain(r);
            s.rain_resolution = r.resolution;
        } else if (name == "flow") {
            const FlowSpec f = flow_params().bind(call.params);
            s.depressions = to_depressions(f);
            s.mfd_exponent = to_mfd_exponent(f);
            flow = true;
        } else if (name == "creep") s.diffusivity = creep_params().bind(call.params).diffusivity;
        else if (name == "rock") {
            s.rock = to_beds(rock_params().bind(call.params), seed);
            if (s.rock.angle > 0.0) rock_angle = s.rock.angle;
        } else if (name == "stream-power") {
            const StreamPowerSpec sp = stream_power_params().bind(call.params);
            s.erodibility = sp.erodibility;
            s.area_exponent = sp.m;
            s.slope_exponent = sp.n;
            s.channel_area = sp.channel_area;
            s.deposition = sp.deposition;
            incision = true;
        } else if (name == "banks") s.banks = to_banks(banks_params().bind(call.params));
        else if (name == "floodplains") s.floodplain = to_floodplain(floodplains_params().bind(call.params));
        else if (name == "landslides") slide_angle = landslides_params().bind(call.params).angle * kRad;
        else if (name == "glaciers") glaciers = glaciers_params().bind(call.params);
        else if (name == "troughs") troughs = troughs_params().bind(call.params);
        else if (name == "chi") {
            chi = chi_params().bind(call.params);
            out.chi = true;
        }
    }
    if (!flow || !incision) {
        out.why_not = "the body has no " + std::string(!flow ? "flow" : "stream-power") + " process";
        return out;
    }
    // The model's glaciers make the ice and carve with one threshold; its chi is at its own m/n, A_0 = 1 m².
    if (glaciers.has_value() != troughs.has_value()) {
        out.why_not = "the model's glaciers both erode and carve troughs: give glaciers and troughs together";
        return out;
    }
    if (glaciers) {
        if (glaciers->min_flux != troughs->min_flux) {
            out.why_not = "glaciers' and troughs' min_flux differ";
            return out;
        }
        s.glaciers = to_glaciers(*glaciers, *troughs);
    }
    if (chi && (chi->reference_area != 1.0 || chi->concavity != s.area_exponent / s.slope_exponent)) {
        out.why_not = "chi's concavity is not stream-power's m/n, or its reference area not 1 m²";
        return out;
    }
    // The model slides at its rock's angle exactly when it has one.
    if (rock_angle && !slide_angle) out.why_not = "rock has an angle but no landslides process follows it";
    else if (rock_angle && *rock_angle != *slide_angle) out.why_not = "the rock's angle and the landslides' differ";
    else if (slide_angle && !rock_angle) s.rock.angle = *slide_angle;
    return out;
}

}  // namespace orogen::landscape
