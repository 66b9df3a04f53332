// process landslides — threshold hillslopes: after the incision whatever stands steeper than its rock's
// landslide angle slides away, the rivers carrying the debris off (Burbank et al. 1996, Montgomery &
// Brandon 2002), so hillslopes end planar at the threshold and the divides between them sharp. The
// angle is the threshold_slope field a rock process makes, else this process's own.
// libs/solvers/threshold_slopes.hpp.
#include <orogen/landscape/rock.hpp>
#include <orogen/solvers/threshold_slopes.hpp>

#include <orogen/landscape/processes.hpp>
#include <orogen/plugin.hpp>

#include <numbers>
#include <sstream>

namespace {

using namespace orogen;

class LandslidesProcess final : public Process {
public:
    explicit LandslidesProcess(const landscape::LandslidesSpec& s) : uniform_(landscape::to_landslide_slope(s)) {}

    void step(ProcessState& state, double dt) override {
        (void)dt;
        const std::vector<double>& slopes = state.field("threshold_slope");
        const auto r = solvers::threshold::limit_slopes(
            state.field(kElevation).data(), state.width(), state.height(), state.cell(),
            {uniform_, slopes.empty() ? nullptr : slopes.data()}, state.outlets().data(), nullptr, &scratch_);
        removed_ += r.removed;
        cell2_ = state.cell() * state.cell();
    }

    std::string summary() const override {
        std::ostringstream s;
        s << removed_ * cell2_ * 1e-9 << " km³ slid";
        return s.str();
    }

private:
    double uniform_ = 0.0;  // tan of the angle
    solvers::threshold::Scratch scratch_;  // the limit's working grids, kept between steps
    double removed_ = 0.0;  // m, summed over the cells
    double cell2_ = 0.0;  // m²
};

}  // namespace

OROGEN_PLUGIN("process-landslides", "0.1.0", registry) {
    const ProcessParams<landscape::LandslidesSpec> p = landscape::landslides_params();
    registry.add(ProcessDescriptor{
        .name = "landslides",
        .summary = "threshold hillslopes: whatever stands steeper than the rock's landslide angle slides away",
        .description = "Each sub-step lowers the heights to the greatest surface below them whose slope to a neighbour "
                       "nowhere exceeds the threshold: the threshold_slope field of a rock process before it (each bed "
                       "and joint block its own), else tan(angle). The debris leaves with the rivers. Outlets stay.",
        .params = p.params(),
        .fields = {{kElevation, FieldAccess::updates, "m", "lowered to the threshold"},
                   {"threshold_slope", FieldAccess::reads_if_present, "m/m", "the rock's threshold, cell by cell"}},
        .tile_halo = 1,  // tiled under mpirun within erode:stream-power's model (landscape/processes.hpp)
        .make = [p](const ProcessCall& call) -> std::unique_ptr<Process> {
            return std::make_unique<LandslidesProcess>(p.bind(call.params));
        },
    });
}
