// process creep — soil creep down hillslopes, linear: ∂h/∂t = D·∇²h, one implicit alternating-direction
// step a sub-step (libs/solvers/diffusion.hpp: stable at any dt), the open sides held, closed sides closed.
#include <orogen/landscape/stream_power.hpp>

#include <orogen/landscape/processes.hpp>
#include <orogen/plugin.hpp>

namespace {

using namespace orogen;

class CreepProcess final : public Process {
public:
    explicit CreepProcess(const landscape::CreepSpec& s) : s_(s) {}

    void start(ProcessState& state) override {
        if (!(s_.diffusivity > 0.0)) return;
        landscape::Settings settings;
        settings.diffusivity = s_.diffusivity;
        settings.open = state.open();
        solver_.emplace(state.width(), state.height(), state.cell(), landscape::hillslope_settings(settings));
    }

    void step(ProcessState& state, double dt) override {
        if (!solver_) return;
        std::vector<double>& h = state.field(kElevation);
        // With every side closed the sink stays at base level (the diffusion's sides are closed there).
        std::vector<std::pair<std::size_t, double>> sink;
        if (!state.open().any()) {
            const auto& outlets = state.outlets();
            for (std::size_t i = 0; i < outlets.size(); ++i)
                if (outlets[i]) sink.emplace_back(i, h[i]);
        }
        solver_->step(h.data(), dt);
        for (const auto& [i, v] : sink) h[i] = v;
    }

private:
    landscape::CreepSpec s_;
    std::optional<solvers::diffusion::Solver> solver_;
};

}  // namespace

OROGEN_PLUGIN("process-creep", "0.1.0", registry) {
    const ProcessParams<landscape::CreepSpec> p = landscape::creep_params();
    registry.add(ProcessDescriptor{
        .name = "creep",
        .summary = "soil creep: linear hillslope diffusion D lap(h), implicit (stable at any step)",
        .description =
            "Each sub-step one implicit alternating-direction diffusion step of the heights (stable at any dt; "
            "Culling 1960's linear creep law), the open sides held at base level, the closed sides closed. In "
            "erode:stream-power's order it runs after the routing and before the incision, so that the incision "
            "leaves every eroded cell above its receiver (docs/landscape.md).",
        .params = p.params(),
        .fields = {{kElevation, FieldAccess::updates, "m", "diffused"}},
        .tile_halo = 1,  // tiled under mpirun within erode:stream-power's model (landscape/processes.hpp)
        .make = [p](const ProcessCall& call) -> std::unique_ptr<Process> {
            return std::make_unique<CreepProcess>(p.bind(call.params));
        },
    });
}
