// process rock — the rock the landscape is cut into: tilted beds of varying strength, folded and
// faulted, whose strength drifts along each bed (facies) and whose joint blocks stand steeper than their
// bed. Each sub-step it finds the rock each cell shows at its depth of exhumation and writes two fields:
// erodibility_factor (stream power's K multiplier) and threshold_slope (the landslides' angle, as tan).
// libs/landscape/rock.hpp has the geology.
#include <orogen/landscape/rock.hpp>

#include <orogen/plugin.hpp>

#include <cmath>
#include <numbers>

namespace {

using namespace orogen;

struct Rock {
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

/// The beds in the geology's units (radians, tangents, a unit dip vector), as erode:stream-power makes them.
landscape::Beds beds_of(const Rock& r, std::uint64_t seed) {
    constexpr double rad = std::numbers::pi / 180.0;
    landscape::Beds b;
    b.angle = r.angle * rad;
    b.thickness = r.thickness;
    b.dip_slope = std::tan(r.dip * rad);
    // Azimuth clockwise from north; grid x runs east and y south.
    b.dip_east = std::sin(r.dip_toward * rad);
    b.dip_south = -std::cos(r.dip_toward * rad);
    b.angle_spread = r.angle_spread * rad;
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

class RockProcess final : public Process {
public:
    explicit RockProcess(const Rock& r) : rock_(r) {}

    void start(ProcessState& state) override { beds_ = beds_of(rock_, state.seed()); }

    void step(ProcessState& state, double dt) override {
        (void)dt;
        const std::size_t n = state.size();
        if (offsets_.empty()) landscape::bed_offsets(beds_, n, state.width(), 0, 0, state.cell(), offsets_);
        landscape::rock_at(beds_, state.field(kElevation).data(), state.field(kUplifted).data(), offsets_.data(), n,
                           state.width(), 0, 0, state.cell(), state.field("threshold_slope"),
                           state.field("erodibility_factor"), &memo_);
    }

private:
    Rock rock_;
    landscape::Beds beds_;
    std::vector<double> offsets_;  // each cell's offset of the beds (the dip's and the folds' part), once
    landscape::RockMemo memo_;  // the bed and slice each cell showed
};

void check(ProcessCheckContext& ctx) {
    // The beds' parameters describe beds: without a thickness there are none.
    if (!(ctx.real("thickness") > 0.0) && !ctx.given("thickness"))
        for (const char* p : {"dip", "dip_toward", "erodibility_contrast", "fold_amplitude", "fold_wavelength",
                              "thickness_spread", "fault_spacing", "fault_throw", "facies_length", "facies_share"})
            if (ctx.given(p)) ctx.error(p, std::string(p) + " describes the rock's beds; give thickness (m) as well");
    if ((ctx.real("fault_spacing") > 0.0) != (ctx.real("fault_throw") > 0.0) &&
        !ctx.given(ctx.real("fault_spacing") > 0.0 ? "fault_throw" : "fault_spacing"))
        ctx.error(ctx.real("fault_spacing") > 0.0 ? "fault_spacing" : "fault_throw",
                  "faults need both a spacing and a throw; give fault_spacing (m) and fault_throw (m)");
    if (const double spacing = ctx.real("fault_spacing"); spacing > 0.0 && spacing < 100.0)
        ctx.error("fault_spacing",
                  "faults closer than 100 m apart would shatter the rock cell by cell; give "
                  "fault_spacing >= 100 (m), or 0 for no faults");
    if (const double length = ctx.real("facies_length"); length > 0.0 && length < 100.0)
        ctx.error("facies_length",
                  "facies changing within less than 100 m would speckle the beds cell by cell; give "
                  "facies_length >= 100 (m), or 0 for beds of one strength each");
    if (ctx.given("facies_share") && !(ctx.real("facies_length") > 0.0) && !ctx.given("facies_length"))
        ctx.error("facies_share",
                  "facies_share sets how much the facies change a bed's strength; give facies_length (m) as well");
    for (const char* p : {"block_spread", "angle_spread"})
        if (ctx.given(p) && !(ctx.real("angle") > 0.0) && !ctx.given("angle"))
            ctx.error(p, std::string(p) + " varies the rock's threshold angle; give angle as well");
    if (const double a = ctx.real("angle"), spread = ctx.real("angle_spread");
        a > 0.0 && (a - spread < 5.0 || a + spread > 80.0))
        ctx.error("angle_spread",
                  "the beds' threshold angles run angle ± angle_spread, which must stay within 5-80°; "
                  "give a smaller spread");
}

}  // namespace

OROGEN_PLUGIN("process-rock", "0.1.0", registry) {
    ProcessParams<Rock> p;
    p.real(&Rock::angle, "angle")
        .min(0.0)
        .max(80.0)
        .unit("°")
        .help(
            "the rock's mean threshold hillslope angle, its landslide angle (25-40° in ranges that erode fast, "
            "Montgomery & Brandon 2002), which angle_spread and block_spread vary by bed and joint block "
            "into the threshold_slope field that landslides() reads; 0 = none (landslides then use their own)");
    p.real(&Rock::block_spread, "block_spread")
        .min(0.0)
        .max(2.0)
        .help(
            "joint blocks: each cell's rock, a cell deep, stands up to this share steeper (tan) than "
            "its bed's landslide slope, from the seed, so threshold hillslopes break into spurs and "
            "chutes instead of planes (0.3-1; 0 = planar)");
    p.real(&Rock::thickness, "thickness")
        .min(0.0)
        .max(1e5)
        .unit("m")
        .help(
            "rock in tilted beds of this thickness, each of its own strength (from the seed): strong "
            "beds stand steeper and erode slower. 0 = one rock");
    p.real(&Rock::dip, "dip").min(0.0).max(89.0).unit("°").help("the beds' dip (0 = flat-lying)");
    p.real(&Rock::dip_toward, "dip_toward")
        .min(0.0)
        .max(360.0)
        .unit("°")
        .help("azimuth the beds dip towards, clockwise from north");
    p.real(&Rock::angle_spread, "angle_spread")
        .min(0.0)
        .max(40.0)
        .unit("°")
        .help("landslide angles run angle ± this from the weakest bed to the strongest");
    p.real(&Rock::erodibility_contrast, "erodibility_contrast")
        .min(1.0)
        .max(1000.0)
        .help(
            "erodibility of the weakest bed over the strongest's (1 = the same; shale against "
            "sandstone ~10, Sklar & Dietrich 2001)");
    p.real(&Rock::fold_amplitude, "fold_amplitude")
        .min(0.0)
        .max(1e5)
        .unit("m")
        .help(
            "folded beds: their surfaces rise and fall by up to this in folds whose axes run along "
            "the strike, so the outcrops bend and end instead of running straight across the map "
            "(a few bed thicknesses; 0 = planar beds)");
    p.real(&Rock::fold_wavelength, "fold_wavelength")
        .min(100.0)
        .max(1e6)
        .unit("m")
        .help(
            "the folds' wavelength across their axes (3 times as long along them): 1-10 km in "
            "fold-and-thrust belts");
    p.real(&Rock::thickness_spread, "thickness_spread")
        .min(0.0)
        .max(0.95)
        .help(
            "beds of uneven thickness: from (1 - this) to (1 + this) times thickness, so the "
            "outcrops are spaced unevenly (0 = all alike)");
    p.real(&Rock::fault_spacing, "fault_spacing")
        .min(0.0)
        .max(1e6)
        .unit("m")
        .help(
            "faulted beds: one fault of random strike, 1-3 times this long, per this square on "
            "average; the outcrops step across each fault (0 = no faults; give fault_throw)");
    p.real(&Rock::fault_throw, "fault_throw")
        .min(0.0)
        .max(1e5)
        .unit("m")
        .help(
            "the faults' largest vertical offset of the beds, at a fault's middle (1/4 to all of "
            "it, from the seed; a bed thickness or more to show)");
    p.real(&Rock::facies_length, "facies_length")
        .min(0.0)
        .max(1e6)
        .unit("m")
        .help(
            "beds whose facies change along them: each bed's strength drifts over about this "
            "distance, so cliff bands fade into benches along their outcrop and weak beds stiffen "
            "(300 m in make demo: cliff bands break into knobs and gaps; a few km: they fade "
            "along their outcrop; 0 = each bed one strength across the map)");
    p.real(&Rock::facies_share, "facies_share")
        .min(0.0)
        .max(1.0)
        .help(
            "how much of a bed's strength its facies set (0 = none, 1 = all: the bed's own strength "
            "is forgotten)");
    registry.add(ProcessDescriptor{
        .name = "rock",
        .summary = "the rock: folded, faulted beds of varying strength -> erodibility and threshold-slope fields",
        .description =
            "Cuts the rock into beds `thickness` metres thick dipping `dip` towards `dip_toward`, folded and "
            "faulted, each of its own strength (from the seed; a strong bed erodes erodibility_contrast times "
            "slower than a weak one and stands angle_spread steeper), the strength drifting along a bed over "
            "facies_length. Each sub-step it finds the bed every cell shows at its depth of exhumation (its "
            "height less the uplift it received) and writes erodibility_factor and threshold_slope, which "
            "stream-power and landslides read when they come after it.",
        .params = p.params(),
        .fields = {{kElevation, FieldAccess::reads, "m", ""},
                   {kUplifted, FieldAccess::reads, "m", "the depth of exhumation is the height less this"},
                   {"erodibility_factor", FieldAccess::writes, "1", "K of the rock a cell shows over K (empty: 1)"},
                   {"threshold_slope", FieldAccess::writes, "m/m", "tan of the rock's landslide angle (empty: none)"}},
        .check = check,
        .make = [p](const ProcessCall& call) -> std::unique_ptr<Process> {
            return std::make_unique<RockProcess>(p.bind(call.params));
        },
    });
}
