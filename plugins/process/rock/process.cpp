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
        const landscape::CellBlock grid{n, state.width(), 0, 0, state.cell()};
        if (offsets_.empty()) landscape::bed_offsets(beds_, grid, offsets_);
        landscape::rock_at(beds_, grid,
                           {state.field(kElevation).data(), state.field(kUplifted).data(), offsets_.data()},
                           state.field("threshold_slope"), state.field("erodibility_factor"), &memo_);
    }

private:
    landscape::RockSpec rock_;
    landscape::Beds beds_;
    std::vector<double> offsets_;  // each cell's offset of the beds (the dip's and the folds' part), once
    landscape::RockMemo memo_;  // the bed and slice each cell showed
};

void check(ProcessCheckContext& ctx) {
    landscape::check_rock(ctx, [](std::string_view p) { return std::string(p); });
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
