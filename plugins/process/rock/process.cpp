// process rock — the rock the landscape is cut into: tilted beds of varying strength, folded and
// faulted, whose strength drifts along each bed (facies) and whose joint blocks stand steeper than their
// bed. Each sub-step it finds the rock each cell shows at its depth of exhumation and writes two fields:
// erodibility_factor (stream power's K multiplier) and threshold_slope (the landslides' angle, as tan).
// libs/landscape/rock.hpp has the geology.
#include <orogen/landscape/rock.hpp>

#include <orogen/landscape/processes.hpp>
#include <orogen/plugin.hpp>

namespace {

using namespace orogen;

class RockProcess final : public Process {
public:
    explicit RockProcess(const landscape::RockSpec& r) : rock_(r) {}

    void start(ProcessState& state) override { beds_ = landscape::to_beds(rock_, state.seed()); }

    void step(ProcessState& state, double dt) override {
        (void)dt;
        const std::size_t n = state.size();
        if (offsets_.empty()) landscape::bed_offsets(beds_, n, state.width(), 0, 0, state.cell(), offsets_);
        landscape::rock_at(beds_, state.field(kElevation).data(), state.field(kUplifted).data(), offsets_.data(), n,
                           state.width(), 0, 0, state.cell(), state.field("threshold_slope"),
                           state.field("erodibility_factor"), &memo_);
    }

private:
    landscape::RockSpec rock_;
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
    const ProcessParams<landscape::RockSpec> p = landscape::rock_params();
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
        .tile_halo = 1,  // tiled under mpirun within erode:stream-power's model (landscape/processes.hpp)
        .check = check,
        .make = [p](const ProcessCall& call) -> std::unique_ptr<Process> {
            return std::make_unique<RockProcess>(p.bind(call.params));
        },
    });
}
