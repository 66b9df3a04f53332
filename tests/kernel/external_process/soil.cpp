// soil.cpp — process soil: rock weathers into soil at P0·exp(-H/h0) (Heimsath et al. 1997), and the soil
// creeps downhill at D·(1 - exp(-H/h*))·slope, so bare rock holds (Roering 2008's depth dependence).
#include <orogen/plugin.hpp>
#include <algorithm>
#include <cmath>

using namespace orogen;

struct Soil {
    double production = 2e-4;  // P0, m/yr: bare rock's weathering rate
    double depth = 0.5;  // h0, m: production falls e-fold per this much soil
    double diffusivity = 0.01;  // D, m²/yr
};

class SoilProcess final : public Process {
public:
    explicit SoilProcess(const Soil& s) : s_(s) {}
    void step(ProcessState& state, double dt) override {
        std::vector<double>& z = state.field("elevation");
        std::vector<double>& H = state.field("soil");
        H.resize(z.size(), 0.0);
        for (double& h : H) h += s_.production * std::exp(-h / s_.depth) * dt;  // the surface stays; rock turns
        const int W = state.width(), N = state.height();
        const double k = s_.diffusivity * dt / (state.cell() * state.cell());
        std::vector<double> flux(z.size(), 0.0);  // m of soil gained this step
        for (int y = 0; y < N; ++y)
            for (int x = 0; x < W; ++x)
                for (const auto [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}}) {
                    if (x + dx >= W || y + dy >= N) continue;
                    const std::size_t a = std::size_t(y) * W + x, b = std::size_t(y + dy) * W + x + dx;
                    const std::size_t from = z[a] > z[b] ? a : b, to = from == a ? b : a;
                    // what the slope carries, limited to the soil the upper cell has
                    const double q =
                        std::min(k * (1.0 - std::exp(-H[from] / s_.depth)) * (z[from] - z[to]), 0.25 * H[from]);
                    flux[from] -= q, flux[to] += q;
                }
        for (std::size_t i = 0; i < z.size(); ++i)
            if (!state.outlets()[i]) H[i] += flux[i], z[i] += flux[i];
    }
    void finish(ProcessState& state, Heightmap& out) override {
        GridView layer = out.layer("soil", 0.0f);
        const std::vector<double>& H = state.field("soil");
        for (std::size_t i = 0; i < H.size(); ++i) layer.data[i] = float(H[i]);
    }

private:
    Soil s_;
};

OROGEN_PLUGIN("process-soil", "1.0.0", registry) {
    ProcessParams<Soil> p;
    p.real(&Soil::production, "production").min(0).unit("m/yr").help("bare rock's soil production P0");
    p.real(&Soil::depth, "depth").min(0, true).unit("m").help("production falls e-fold per this much soil");
    p.real(&Soil::diffusivity, "diffusivity").min(0).unit("m²/yr").help("soil creep D where soil is deep");
    registry.add(ProcessDescriptor{
        .name = "soil",
        .summary = "soil produced from rock, creeping downhill where it is deep",
        .params = p.params(),
        .fields = {{"elevation", FieldAccess::updates, "m", "soil moved"},
                   {"soil", FieldAccess::adds, "m", "soil thickness"}},
        .adds_layers = {"soil"},
        // explicit creep: stable while D·dt/cell² ≤ 1/4
        .max_dt = [](const ProcessCall& call, double cell) { return 0.25 * cell * cell / call.real("diffusivity"); },
        .make = [p](const ProcessCall& call) -> std::unique_ptr<Process> {
            return std::make_unique<SoilProcess>(p.bind(call.params));
        },
    });
}
