// erode:stream-power — registers the implicit stream-power landscape model (stream_power.hpp) with the kernel.
#include <orogen/landscape/model_node.hpp>
#include <orogen/landscape/processes.hpp>
#include <orogen/landscape/stream_power.hpp>
#include <orogen/landscape/tiled.hpp>
#include <orogen/landscape/uplift.hpp>

#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/plugin.hpp>
#include <orogen/timelapse.hpp>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstring>
#include <functional>
#include <map>
#include <memory>
#include <numbers>
#include <cmath>
#include <optional>
#include <sstream>
#include <string>
#include <unistd.h>
#include <utility>
#include <vector>

namespace {

using namespace orogen;
using landscape::kMaxUpliftMmYr;
using landscape::parse_base_level;
using landscape::parse_sides;

/// The parameters of rain="orographic" (an error without it).
constexpr const char* kRainParams[] = {"rain_background",    "wind_from",      "wind_speed",      "wind_share",
                                       "condensation_time",  "fallout_time",   "moist_stability", "vapour_scale_height",
                                       "uplift_sensitivity", "rain_resolution"};

landscape::Settings settings_of(NodeContext& ctx) {
    landscape::Settings s;
    s.erodibility = ctx.real("erodibility");
    s.area_exponent = ctx.real("m");
    s.slope_exponent = ctx.real("n");
    s.diffusivity = ctx.real("diffusivity");
    s.channel_area = ctx.real("channel_area");
    s.substeps = int(ctx.integer("substeps"));
    s.banks.erosion = ctx.real("bank_erosion");
    s.banks.area = ctx.real("bank_area");
    constexpr double rad = std::numbers::pi / 180.0;
    s.banks.floor_slope = std::tan(ctx.real("bank_floor_slope") * rad);
    s.banks.wide_area = ctx.real("bank_wide_area");
    s.banks.wider_area = ctx.real("bank_wider_area");
    s.banks.widest_floor = int(ctx.integer("bank_widest_floor"));
    s.floodplain.area = ctx.real("floodplain_area");
    s.floodplain.width = ctx.real("floodplain_width");
    s.floodplain.exponent = ctx.real("floodplain_exponent");
    s.floodplain.slope = std::tan(ctx.real("floodplain_slope") * rad);
    s.floodplain.max_slope = std::tan(ctx.real("floodplain_max_slope") * rad);
    s.rock.angle = ctx.real("landslide_angle") * rad;
    s.rock.thickness = ctx.real("bed_thickness");
    s.rock.dip_slope = std::tan(ctx.real("bed_dip") * rad);
    // Azimuth clockwise from north; grid x runs east and y south.
    s.rock.dip_east = std::sin(ctx.real("bed_dip_toward") * rad);
    s.rock.dip_south = -std::cos(ctx.real("bed_dip_toward") * rad);
    s.rock.angle_spread = ctx.real("bed_angle_spread") * rad;
    s.rock.erodibility_contrast = ctx.real("bed_erodibility_contrast");
    s.rock.fold_amplitude = ctx.real("bed_fold_amplitude");
    s.rock.fold_wavelength = ctx.real("bed_fold_wavelength");
    s.rock.thickness_spread = ctx.real("bed_thickness_spread");
    s.rock.fault_spacing = ctx.real("bed_fault_spacing");
    s.rock.fault_throw = ctx.real("bed_fault_throw");
    s.rock.block_spread = ctx.real("landslide_block_spread");
    s.rock.facies_length = ctx.real("bed_facies_length");
    s.rock.facies_share = ctx.real("bed_facies_share");
    s.rock.seed = ctx.seed();
    if (ctx.flag("glaciers")) {
        s.glaciers.ela = ctx.real("ela");
        s.glaciers.balance_gradient = ctx.real("ice_balance_gradient");
        s.glaciers.max_balance = ctx.real("ice_max_balance");
        s.glaciers.erodibility = ctx.real("ice_erodibility");
        s.glaciers.flux_exponent = ctx.real("ice_flux_exponent");
        s.glaciers.half_width = ctx.real("glacier_half_width");
        s.glaciers.wall_slope = std::tan(ctx.real("trough_wall_angle") * rad);
        s.glaciers.glacier_flux = ctx.real("glacier_min_flux");
    }
    if (ctx.text("rain") == "orographic") {
        s.orographic_rain = true;
        s.rain.background = ctx.real("rain_background");
        s.rain.wind_from = ctx.real("wind_from");
        s.rain.wind_speed = ctx.real("wind_speed");
        s.rain.wind_share = ctx.real("wind_share");
        s.rain.condensation_time = ctx.real("condensation_time");
        s.rain.fallout_time = ctx.real("fallout_time");
        s.rain.moist_stability = ctx.real("moist_stability");
        s.rain.vapour_scale_height = ctx.real("vapour_scale_height");
        s.rain.uplift_sensitivity = ctx.real("uplift_sensitivity");
        s.rain_resolution = ctx.real("rain_resolution");
    }
    s.open = *parse_sides(ctx.text("open"));
    s.depressions = ctx.text("depressions") == "route" ? landscape::Depressions::route : landscape::Depressions::fill;
    if (ctx.text("routing") == "mfd") s.mfd_exponent = ctx.real("mfd_exponent");
    s.deposition = ctx.real("deposition");
    return s;
}

NodeOutputs run(NodeContext& ctx) {
    const landscape::ModelRun model{
        settings_of(ctx),
        landscape::UpliftSources{ctx.real("uplift"), ctx.text("uplift_layer"), ctx.real("uplift_layer_years"),
                                 ctx.real("uplift_smoothing"), ctx.real("uplift_edge_taper"),
                                 ctx.real("uplift_history_years")},
        ctx.flag("chi")};
    return landscape::run_model(ctx, model);
}

void check(CheckContext& ctx) {
    const auto sides = parse_sides(ctx.text("open"));
    if (!sides)
        ctx.error("open",
                  "'" + ctx.text("open") +
                      "' is not a set of sides; write the letters of the open sides (n, e, s, w), e.g. "
                      "\"nesw\", or all or none (every side closed: the lowest cell is the outlet)");
    else if (!sides->any() && ctx.real("uplift_edge_taper") > 0.0)
        ctx.error("uplift_edge_taper",
                  "uplift_edge_taper tapers the uplift towards the open sides, and open=" + ctx.text("open") +
                      " opens none; open some sides or give uplift_edge_taper=0");
    if (!parse_base_level(ctx.text("base_level")))
        ctx.error("base_level",
                  "'" + ctx.text("base_level") +
                      "' is not a height; give edge (outlets keep their heights) or metres, e.g. \"0\"");
    if (ctx.text("routing") == "mfd" && ctx.text("depressions") == "route")
        ctx.error("routing",
                  "multiple flow directions need filled lakes (water crossing an unfilled lake would "
                  "flow back into it); use depressions=fill or routing=d8");
    if (ctx.text("routing") != "mfd" && ctx.given("mfd_exponent") && !ctx.given("routing"))
        ctx.error("mfd_exponent", "mfd_exponent weights multiple flow directions; give routing=mfd as well");
    if (ctx.real("dt") > ctx.real("years"))
        ctx.error("dt", "the time step is longer than the run (years); give dt <= years");
    // The beds' parameters describe beds: without a thickness there are none, and a spread of landslide
    // angles needs landslides. A shaping parameter without its process is an error only where the process's
    // switch is not given at all (forgotten); a switch given as off (`--set range.floodplain_area=0` on a spec
    // that shapes floodplains) turns the process off on purpose, its shaping parameters then unused.
    landscape::check_rock(ctx, [](std::string_view p) {
        return p == "angle" || p == "block_spread" ? "landslide_" + std::string(p) : "bed_" + std::string(p);
    });
    for (const char* bank : {"bank_area", "bank_floor_slope", "bank_wide_area", "bank_wider_area", "bank_widest_floor"})
        if (ctx.given(bank) && !(ctx.real("bank_erosion") > 0.0) && !ctx.given("bank_erosion"))
            ctx.error(bank, std::string(bank) + " shapes the rivers' bank erosion; give bank_erosion > 0 as well");
    if (ctx.real("bank_erosion") > 0.0)
        landscape::check_banks(ctx, [](std::string_view p) { return "bank_" + std::string(p); });
    for (const char* fp : {"floodplain_width", "floodplain_exponent", "floodplain_slope", "floodplain_max_slope"})
        if (ctx.given(fp) && !(ctx.real("floodplain_area") > 0.0) && !ctx.given("floodplain_area"))
            ctx.error(fp, std::string(fp) + " shapes the rivers' floodplains; give floodplain_area (m²) as well");
    const std::string& layer = ctx.text("uplift_layer");
    const ValueInfo* hist = ctx.input(1);
    if (hist) {
        if (!layer.empty())
            ctx.error("uplift_layer",
                      "give uplift_layer or an uplift_history input, not both (the plates' 'uplift' "
                      "layer is the sum of their history's height changes: it would count twice)");
        if (hist->empty)
            ctx.error("",
                      "input 2 (uplift_history) records no frames: give its node timelapse_every=K (e.g. "
                      "tectonics:plates(..., timelapse_every=50)) so that it hands on its heights over time");
        else if (hist->count == 1)
            ctx.error("", "input 2 (uplift_history) has 1 frame; a rate needs at least two (the start and the end)");
        const ValueInfo* in = ctx.input(0);
        if (in && in->width > 0 && hist->width > 0 && (in->width != hist->width || in->height != hist->height))
            ctx.error("",
                      "input 2 (uplift_history) is " + std::to_string(hist->width) + " x " +
                          std::to_string(hist->height) + ", the terrain " + std::to_string(in->width) + " x " +
                          std::to_string(in->height) + "; record the history on the terrain's grid");
    } else if (ctx.given("uplift_history_years")) {
        ctx.error("uplift_history_years",
                  "uplift_history_years spreads an uplift history; give one as input 2, e.g. plates.timelapse");
    }
    if (!layer.empty())
        ctx.require_layer(0, "uplift_layer", layer, "tectonics:plates writes 'uplift'; or give \"\" for none");
    else if (ctx.given("uplift_layer_years"))
        ctx.error("uplift_layer_years", "uplift_layer_years scales an uplift layer; name one with uplift_layer");
    else if (ctx.given("uplift_smoothing") && !hist)
        ctx.error("uplift_smoothing",
                  "uplift_smoothing spreads an uplift layer or history; name a layer with "
                  "uplift_layer or give a history as input 2");
    // Memory: the model holds about kBytesPerCell bytes per cell beside the heightmap.
    const ValueInfo* in = ctx.input(0);
    const std::int64_t w = in && in->width > 0 ? in->width : ctx.grid().width;
    const std::int64_t hgt = in && in->height > 0 ? in->height : ctx.grid().height;
    // In a tiled run each rank holds its tile's model only (memory_share: this machine's share of the grid).
    const double need = ctx.memory_share() * double(w) * double(hgt) *
        double(landscape::kBytesPerCell + (ctx.real("deposition") > 0.0 ? landscape::kBytesPerCellDeposition : 0) +
               (ctx.text("rain") == "orographic" ? landscape::kBytesPerCellRain : 0));
    const double have = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE));
    if (have > 0 && need > 0.5 * have) {
        std::ostringstream msg;
        msg << "a " << w << " x " << hgt << " grid needs " << human_bytes(need) << " for the landscape model"
            << (ctx.memory_share() < 1.0 ? " (this machine's tiles)" : "") << ", more than half of this machine's "
            << human_bytes(have) << "; use a smaller grid" << (ctx.memory_share() < 1.0 ? " or more machines" : "");
        ctx.error("", msg.str());
    }
    check_timelapse(ctx, std::int64_t(std::ceil(ctx.real("years") / ctx.real("dt"))));
    for (const char* l : {"drainage", "flow_direction", "eroded", "uplifted"}) ctx.output().layers.insert(l);
    if (ctx.flag("chi")) ctx.output().layers.insert("chi");
    if (ctx.flag("glaciers")) ctx.output().layers.insert("ice_flux");
    if (ctx.flag("glaciers") && ctx.real("deposition") > 0.0)
        ctx.error("glaciers", "glaciers erode detachment-limited for now; give deposition=0 or glaciers=false");
    if (!ctx.flag("glaciers") && !ctx.given("glaciers"))
        for (const char* p : {"ela", "ice_balance_gradient", "ice_max_balance", "ice_erodibility", "ice_flux_exponent",
                              "glacier_half_width", "glacier_min_flux", "trough_wall_angle"})
            if (ctx.given(p)) ctx.error(p, std::string(p) + " describes glaciers; give glaciers=true as well");
    if (ctx.text("rain") == "orographic") ctx.output().layers.insert("rain");
    else if (!ctx.given("rain"))
        for (const char* p : kRainParams)
            if (ctx.given(p))
                ctx.error(p, std::string(p) + " describes orographic rain; give rain=\"orographic\" as well");
}

constexpr const char* kDescription =
    "dh/dt = U - K A^m S^n + D lap(h): rock uplift U against detachment-limited fluvial incision (drainage "
    "area A, slope S to the receiver) and hillslope diffusion D. Each step of dt years uplifts the land, "
    "routes water D8 (steepest of 8 neighbours; routing=mfd also splits the drainage area among all lower "
    "neighbours, Freeman 1991) with pits resolved over the basin graph (Cordonnier et al. 2019): each "
    "lake spills at its lowest pass (depressions=fill also fills it). It accumulates drainage area, "
    "diffuses implicitly and solves the incision implicitly in flow order (Braun & Willett 2013: stable at "
    "any dt; Newton's method for n != 1). Water leaves by the open sides, whose vertices are held at base "
    "level; with every side closed the lowest cell is the outlet. Uplift is `uplift` (mm/yr) plus, with "
    "uplift_layer, that layer's metres gained over uplift_layer_years (e.g. the plates' 'uplift'), spread over "
    "uplift_smoothing metres; with a second input (a heightmap series such as plates.timelapse), the height "
    "change between its frames over the years they map to (the first frame year 0, the last "
    "uplift_history_years, default the run's years), spread the same way. deposition=G > 0 lets G Qs/A of "
    "the sediment flux Qs settle on its way down (Yuan et al. 2019; solved exactly on the receiver tree). "
    "landslide_angle > 0 holds every slope below that threshold after each step (the debris leaves with the "
    "rivers); bed_* cut the rock into tilted beds of varying strength (landslide angle and erodibility); "
    "glaciers=true routes ice from above the ELA down the valleys, eroding K_g Q^m_g S^n and carving "
    "U-shaped troughs; rain=orographic weights the drainage area by the rain a moist wind leaves on the "
    "relief (Smith & Barstad 2004). The same "
    "result on any number of threads, and under mpirun on any number of tiles (routing=d8, deposition=0, no "
    "glaciers or floodplains, uniform rain; other settings run on rank 0). Adds the layers drainage (upstream "
    "area, m^2: draw "
    "rivers where it exceeds ~1 km^2), flow_direction (D8 code of the receiver: 0 east, 1 south-east, ... 7 "
    "north-east; -1 "
    "outlet), eroded (the surface's change by erosion and deposition, m: negative where rock was removed; "
    "added to "
    "an earlier eroder's), uplifted (the rock uplift it received, m; eroded + uplifted is the net change) and, "
    "with chi=true, chi (m).";

/// The parameters of time, the stream-power law, uplift, deposition, creep.
std::vector<Param> uplift_params() {
    return {
        Param::real("years", 1e6).min(0.0, true).max(1e9).unit("yr").help("simulated time"),
        Param::real("dt", 1e4).min(0.0, true).max(1e8).unit("yr").help(
            "time step (any size is stable and steady states are exact; a transient is not: each step lets the "
            "soil creep for the whole dt before the rivers incise, so a landscape tuned at one dt changes at "
            "another, most with strong creep: it converges once dt/substeps is below about cell^2/D, 750-1500 "
            "yr at 30 m with D of 0.6-1.2 m2/yr; docs/landscape.md)"),
        Param::real("erodibility", 2e-5)
            .min(0.0, true)
            .max(1e-2)
            .unit("m^(1-2m)/yr")
            .help("K: 1e-7 (hard rock, dry) to 1e-4 (soft rock, wet) for m ~ 0.5, n = 1 "
                  "(Stock & Montgomery 1999)"),
        Param::real("m", 0.45).min(0.1).max(1.5).help("area exponent (0.3-0.6 with n = 1; m/n is the concavity, "
                                                      "0.35-0.6 in real rivers)"),
        Param::real("n", 1.0).min(0.5).max(4.0).help("slope exponent (2/3-2 measured, Whipple & Tucker 1999; "
                                                     "up to 4, Lague 2014)"),
        Param::real("uplift", 1.0)
            .min(0.0)
            .max(kMaxUpliftMmYr)
            .unit("mm/yr")
            .help("uniform rock uplift rate (0.1-10 mm/yr in active ranges)"),
        Param::real("uplift_edge_taper", 0.0)
            .min(0.0)
            .max(1e6)
            .unit("m")
            .help("the uplift (all of it) falls smoothly to zero over this distance towards the open sides, "
                  "as a range's uplift falls to its foreland (0 = the same right up to the sides, which "
                  "are held at base level)"),
        Param::string("uplift_layer", "")
            .help("a layer of the input read as uplift (m) gained over uplift_layer_years, added to "
                  "`uplift`; \"\" = none"),
        Param::real("uplift_layer_years", 1e6)
            .min(1.0)
            .max(1e9)
            .unit("yr")
            .help("years over which the uplift layer's metres were gained (1e6: metres per Myr = mm/yr)"),
        Param::real("uplift_smoothing", 0.0)
            .min(0.0)
            .max(1e6)
            .unit("m")
            .help("spread the uplift layer over about this distance (flexure of the crust; 0 = as is)"),
        Param::real("uplift_history_years", 0.0)
            .min(0.0)
            .max(1e9)
            .unit("yr")
            .help("with an uplift_history input: the years its frames span, from the start of the run "
                  "(the first frame is year 0, the last this; 0 = the run's years); no history uplift after"),
        Param::real("deposition", 0.0)
            .min(0.0)
            .max(10.0)
            .help("G of Yuan et al. (2019), dimensionless: the sediment flux deposits G·Qs/A on its way "
                  "down (0 = detachment-limited; ~1 = half the eroded rock settles in the valleys at "
                  "steady state; Yuan et al. use 0-3)"),
        Param::real("diffusivity", 0.01)
            .min(0.0)
            .max(10.0)
            .unit("m²/yr")
            .help("D of hillslope diffusion applied each step (1e-3 to 1e-1; 0 = none)"),
        Param::real("channel_area", 0.0)
            .min(0.0)
            .max(1e10)
            .unit("m²")
            .help("drainage area where rivers take over from hillslopes: incision is scaled by "
                  "1 - exp(-A/channel_area), so smaller catchments are shaped by creep (channel heads "
                  "at 1e3-1e5 m², Montgomery & Dietrich 1988); 0 = every cell is a river"),
    };
}

/// The parameters of river banks and floodplains.
std::vector<Param> bank_params() {
    return {
        Param::real("bank_erosion", 0.0)
            .min(0.0)
            .max(10.0)
            .help("rivers widen their valleys (lateral erosion, after Langston & Tucker 2018): each "
                  "incision lowers the two cells across a river by this many times the river's own "
                  "lowering, shared between them (straight on, half each; at a bend the outer bank takes "
                  "more), never below the river; 0 = banks stand, 4 = a floor three cells wide"),
        Param::real("bank_area", 1e6)
            .min(1.0)
            .max(1e12)
            .unit("m²")
            .help("drainage area over which a river is wide and deep enough to undercut its banks: "
                  "bank erosion is scaled by 1 - exp(-A/bank_area)"),
        Param::real("bank_floor_slope", 1.0)
            .min(0.0)
            .max(30.0)
            .unit("°")
            .help("a bank the river has cut down still rises from the river at this angle: the valley "
                  "floor slopes gently to its river, as the aprons along a mountain valley's foot do "
                  "(0 = dead flat floors, which hold pits)"),
        Param::real("bank_wide_area", 0.0)
            .min(0.0)
            .max(1e12)
            .unit("m²")
            .help("rivers draining more than this keep floors five cells wide rather than three: a bank cut "
                  "down to its floor passes the river's push on to the cell beyond it, as real valley floors "
                  "widen downstream (3e5 = from a third of a km²); 0 = three cells everywhere"),
        Param::real("bank_wider_area", 0.0)
            .min(0.0)
            .max(1e12)
            .unit("m²")
            .help("rivers draining more than this (and bank_wide_area) keep floors seven cells wide: the "
                  "cell beyond the bank, once down to its floor, passes the push on once more (1e6 = from "
                  "a km²); 0 = five cells at most"),
        Param::integer("bank_widest_floor", 0)
            .min(0)
            .max(35)
            .unit("cells")
            .help("floors keep widening past seven cells, two cells more each time the drainage area grows "
                  "by bank_wider_area / bank_wide_area (9 from 3.3 km², 11 from 11 km² with 3e5 and 1e6), "
                  "up to this many, as real floors widen all the way downstream; each two cells cost a "
                  "pass; 0 = seven at most"),
        Param::real("floodplain_area", 0.0)
            .min(0.0)
            .max(1e12)
            .unit("m²")
            .help("rivers draining more than this have floodplains: each step every cell within the "
                  "half-width floodplain_width·(A/floodplain_area)^floodplain_exponent of such a river is "
                  "lowered to its nearest one plus floodplain_slope over the distance (never raised), as "
                  "large rivers plane their valley floors (3e6 = from 3 km²); "
                  "0 = none"),
        Param::real("floodplain_width", 30.0)
            .min(0.0, true)
            .max(1e5)
            .unit("m")
            .help("the floodplain's half-width for a river draining floodplain_area"),
        Param::real("floodplain_exponent", 0.5)
            .min(0.0)
            .max(1.0)
            .help("how fast floodplains widen downstream: half-width ∝ A^floodplain_exponent (real 30 m "
                  "valleys widen as A^0.2-0.3 10 m above their rivers)"),
        Param::real("floodplain_slope", 2.0)
            .min(0.0)
            .max(30.0)
            .unit("°")
            .help("a floodplain rises from its river at this angle (0 = dead flat, which holds pits)"),
        Param::real("floodplain_max_slope", 0.0)
            .min(0.0)
            .max(60.0)
            .unit("°")
            .help("only rivers no steeper than this (to their receiver) plane a floodplain, as real ones "
                  "lie along gentle reaches and none in gorges (2.3 = a 4 % gradient); 0 = every river"),
    };
}

/// The parameters of sub-steps, landslides and the beds of rock.
std::vector<Param> slope_params() {
    return {
        Param::integer("substeps", 1)
            .min(1)
            .max(1000)
            .help("sub-steps per step: each step's routing serves this many sub-steps of uplift, creep, "
                  "incision and landslides of dt/substeps each, so the creep and the incision no longer run "
                  "a whole dt apart (the part of a step that sets its accuracy; the routing is most of the "
                  "cost). 6 at dt=6e4 gives nearly the terrain of dt=1e4 in 60% of its time; the split "
                  "converges once dt/substeps is below about cell^2/D"),
        Param::real("landslide_angle", 0.0)
            .min(0.0)
            .max(80.0)
            .unit("°")
            .help("threshold hillslope angle: after each step whatever stands steeper slides away, the "
                  "rivers carrying the debris off (25-40° in ranges that erode fast, Montgomery & Brandon "
                  "2002); hillslopes end planar at it, divides sharp. 0 = no landslides"),
        Param::real("landslide_block_spread", 0.0)
            .min(0.0)
            .max(2.0)
            .help("joint blocks: each cell's rock, a cell deep, stands up to this share steeper (tan) than "
                  "its bed's landslide slope, from the seed, so threshold hillslopes break into spurs and "
                  "chutes instead of planes (0.3-1; 0 = planar)"),
        Param::real("bed_thickness", 0.0)
            .min(0.0)
            .max(1e5)
            .unit("m")
            .help("rock in tilted beds of this thickness, each of its own strength (from the seed): strong "
                  "beds stand steeper and erode slower. 0 = one rock"),
        Param::real("bed_dip", 0.0).min(0.0).max(89.0).unit("°").help("the beds' dip (0 = flat-lying)"),
        Param::real("bed_dip_toward", 0.0)
            .min(0.0)
            .max(360.0)
            .unit("°")
            .help("azimuth the beds dip towards, clockwise from north"),
        Param::real("bed_angle_spread", 0.0)
            .min(0.0)
            .max(40.0)
            .unit("°")
            .help("landslide angles run landslide_angle ± this from the weakest bed to the strongest"),
        Param::real("bed_erodibility_contrast", 1.0)
            .min(1.0)
            .max(1000.0)
            .help("erodibility of the weakest bed over the strongest's (1 = the same; shale against "
                  "sandstone ~10, Sklar & Dietrich 2001)"),
        Param::real("bed_fold_amplitude", 0.0)
            .min(0.0)
            .max(1e5)
            .unit("m")
            .help("folded beds: their surfaces rise and fall by up to this in folds whose axes run along "
                  "the strike, so the outcrops bend and end instead of running straight across the map "
                  "(a few bed thicknesses; 0 = planar beds)"),
        Param::real("bed_fold_wavelength", 5000.0)
            .min(100.0)
            .max(1e6)
            .unit("m")
            .help("the folds' wavelength across their axes (3 times as long along them): 1-10 km in "
                  "fold-and-thrust belts"),
        Param::real("bed_thickness_spread", 0.0)
            .min(0.0)
            .max(0.95)
            .help("beds of uneven thickness: from (1 - this) to (1 + this) times bed_thickness, so the "
                  "outcrops are spaced unevenly (0 = all alike)"),
        Param::real("bed_fault_spacing", 0.0)
            .min(0.0)
            .max(1e6)
            .unit("m")
            .help("faulted beds: one fault of random strike, 1-3 times this long, per this square on "
                  "average; the outcrops step across each fault (0 = no faults; give bed_fault_throw)"),
        Param::real("bed_fault_throw", 0.0)
            .min(0.0)
            .max(1e5)
            .unit("m")
            .help("the faults' largest vertical offset of the beds, at a fault's middle (1/4 to all of "
                  "it, from the seed; a bed thickness or more to show)"),
        Param::real("bed_facies_length", 0.0)
            .min(0.0)
            .max(1e6)
            .unit("m")
            .help("beds whose facies change along them: each bed's strength drifts over about this "
                  "distance, so cliff bands fade into benches along their outcrop and weak beds stiffen "
                  "(300 m in make demo: cliff bands break into knobs and gaps; a few km: they fade "
                  "along their outcrop; 0 = each bed one strength across the map)"),
        Param::real("bed_facies_share", 0.5)
            .min(0.0)
            .max(1.0)
            .help("how much of a bed's strength its facies set (0 = none, 1 = all: the bed's own strength "
                  "is forgotten)"),
    };
}

/// The parameters of valley glaciers.
std::vector<Param> glacier_params() {
    return {
        Param::boolean("glaciers", false)
            .help("valley glaciers: ice gathers above the ELA, flows down the valleys, erodes "
                  "ice_erodibility*Q^ice_flux_exponent*S^n and carves U-shaped troughs (docs/landscape.md); "
                  "adds the layer ice_flux"),
        Param::real("ela", 2500.0)
            .min(-1000.0)
            .max(9000.0)
            .unit("m")
            .help("glaciers: the equilibrium-line altitude, above which snow outlasts the summer (Alps "
                  "today ~2900 m, in the last glacial maximum ~1500 m lower)"),
        Param::real("ice_balance_gradient", 0.007)
            .min(0.0, true)
            .max(0.1)
            .unit("1/yr")
            .help("glaciers: metres of ice a year gained per metre above the ELA (0.005-0.01 in the Alps)"),
        Param::real("ice_max_balance", 2.0)
            .min(0.0, true)
            .max(20.0)
            .unit("m/yr")
            .help("glaciers: the most ice a year any height gains"),
        Param::real("ice_erodibility", 2e-6)
            .min(0.0)
            .max(1.0)
            .help("glaciers: K_g of E = K_g*Q^m_g*S^n, Q the ice flux in m³/yr"),
        Param::real("ice_flux_exponent", 0.5).min(0.1).max(1.5).help("glaciers: m_g of the glacial erosion law"),
        Param::real("glacier_half_width", 400.0)
            .min(0.0)
            .max(1e4)
            .unit("m")
            .help("glaciers: half the width of a glacier carrying 1e6 m³/yr (width grows as Q^0.4, Bahr "
                  "1997); its trough is carved that far on each side"),
        Param::real("glacier_min_flux", 2e5)
            .min(0.0)
            .max(1e12)
            .unit("m³/yr")
            .help("glaciers: the ice flux from which ice slides, erodes and carves a trough; thinner ice "
                  "(snow on the slopes and peaks) erodes nothing, so horns and aretes stand above"),
        Param::real("trough_wall_angle", 40.0)
            .min(1.0)
            .max(80.0)
            .unit("°")
            .help("glaciers: the slope of a trough's walls at the glacier's margin"),
    };
}

/// The parameters of orographic rain.
std::vector<Param> rain_params() {
    return {
        Param::choice("rain", {"uniform", "orographic"}, "uniform")
            .help("where the rain falls: uniform, or orographic (Smith & Barstad 2004): a steady moist "
                  "wind rains on the windward slopes and leaves a dry lee, recomputed each step over the "
                  "growing relief; a cell counts rain/rain_background of its area, so `erodibility` is for "
                  "the background rain. Adds the layer rain (m/yr)"),
        Param::real("rain_background", 1.0)
            .min(0.0, true)
            .max(20.0)
            .unit("m/yr")
            .help("rain=orographic: the mean annual rain on flat ground (0.3-3 m/yr)"),
        Param::real("wind_from", 270.0)
            .min(0.0)
            .max(360.0)
            .unit("°")
            .help("rain=orographic: azimuth the moist wind blows from, clockwise from north (270: westerly)"),
        Param::real("wind_speed", 10.0)
            .min(0.0)
            .max(60.0)
            .unit("m/s")
            .help("rain=orographic: the moist wind's speed (5-20 m/s)"),
        Param::real("wind_share", 0.1)
            .min(0.0, true)
            .max(1.0)
            .help("rain=orographic: share of the year the moist wind blows; the rest of the year other "
                  "weather rains rain_background evenly, so the lee keeps (1 - wind_share) of it"),
        Param::real("condensation_time", 1000.0)
            .min(0.0)
            .max(1e5)
            .unit("s")
            .help("rain=orographic: tau_c, cloud water to rain and snow (200-2000 s); longer carries the "
                  "rain further downwind"),
        Param::real("fallout_time", 1000.0)
            .min(0.0)
            .max(1e5)
            .unit("s")
            .help("rain=orographic: tau_f, the time rain and snow take to fall (200-2000 s)"),
        Param::real("moist_stability", 0.005)
            .min(0.0)
            .max(0.05)
            .unit("1/s")
            .help("rain=orographic: N_m, the moist buoyancy frequency (0-0.01; 0 = neutral air)"),
        Param::real("vapour_scale_height", 2500.0)
            .min(0.0)
            .max(2e4)
            .unit("m")
            .help("rain=orographic: H_w, the water vapour's scale height (1-4 km)"),
        Param::real("uplift_sensitivity", 0.0083)
            .min(0.0)
            .max(0.1)
            .unit("kg/m³")
            .help("rain=orographic: C_w, water condensed per metre of lift (0.004-0.01; warm air more)"),
        Param::real("rain_resolution", 250.0)
            .min(1.0)
            .max(1e5)
            .unit("m")
            .help("rain=orographic: the grid the rain is computed on (whole cells; the theory smooths "
                  "below a few km)"),
    };
}

/// The parameters of outlets, pits, routing, chi and the time-lapse.
std::vector<Param> routing_params() {
    return {
        Param::string("open", "nesw")
            .help("sides water leaves by (letters n e s w, all or none); their vertices are held at base "
                  "level. none: the lowest cell is the one outlet"),
        Param::string("base_level", "edge")
            .help("height of the outlets: edge (they keep the input's heights) or metres, e.g. \"0\""),
        Param::choice("depressions", {"fill", "route"}, "fill")
            .help("pits: fill (lakes fill to their spill level: sediment) or route (water crosses them, "
                  "the heights stay)"),
        Param::choice("routing", {"d8", "mfd"}, "d8")
            .help("drainage area: d8 (all water to the steepest neighbour) or mfd (split among the lower "
                  "neighbours by slope^mfd_exponent, Freeman 1991: wider, smoother hillslope areas); the "
                  "incision follows the steepest neighbour either way"),
        Param::real("mfd_exponent", 1.1)
            .min(0.0, true)
            .max(100.0)
            .help("routing=mfd: weight of a lower neighbour = slope^p (1.1: Freeman 1991; larger "
                  "concentrates the flow, towards D8)"),
        Param::boolean("chi", false).help("also write the layer chi (m; reference area 1 m^2)"),
        timelapse_param(),
    };
}

/// Every parameter, in the order `orogen help` lists them.
std::vector<Param> params() {
    std::vector<Param> all;
    for (auto group : {uplift_params, bank_params, slope_params, glacier_params, rain_params, routing_params})
        for (Param& q : group()) all.push_back(std::move(q));
    return all;
}

}  // namespace

OROGEN_PLUGIN("erode-stream-power", "0.1.0", registry) {
    registry.add({
        .kind = "erode",
        .name = "stream-power",
        .summary = "landscape evolution over geological time: rivers incise (stream power) against rock uplift",
        .description = kDescription,
        .inputs = {{"terrain", ValueType::heightmap, Need::required, "heightmap to evolve"},
                   {"uplift_history", ValueType::heightmap, Need::optional,
                    "heights over time (e.g. plates.timelapse): the height change between two frames is rock uplift "
                    "over the years they map to (uplift_history_years), added to `uplift`",
                    Many::series}},
        .output = ValueType::heightmap,
        .side_outputs = {timelapse_output()},
        .params = params(),
        .adds_layers = {"drainage", "flow_direction", "eroded", "uplifted"},
        .tile_halo = 1,
        .check = check,
        .run = run,
        .tiled_timelapse = true,  // rank 0 gathers the frames (Timelapse with the tiling)
        .untiled_because =
            [](const std::map<std::string, ParamValue, std::less<>>& p, const std::vector<bool>&) {
                landscape::Settings s;
                if (std::get<std::string>(p.at("routing")) == "mfd") s.mfd_exponent = 1.0;
                s.deposition = std::get<double>(p.at("deposition"));
                if (std::get<bool>(p.at("glaciers"))) s.glaciers.balance_gradient = 1.0;
                s.orographic_rain = std::get<std::string>(p.at("rain")) == "orographic";
                s.floodplain.area = std::get<double>(p.at("floodplain_area"));
                return landscape::untiled_because(s);
            },
    });
}
