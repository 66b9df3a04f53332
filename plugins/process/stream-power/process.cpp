// process stream-power — fluvial incision by stream power, E = K·A^m·S^n (detachment-limited), or with
// deposition of a share of the sediment flux on its way down (Yuan et al. 2019), solved implicitly along
// the flow graph in stack order (Braun & Willett 2013: stable at any dt). libs/landscape/stream_power.hpp.
#include <orogen/landscape/stream_power.hpp>

#include <orogen/parallel.hpp>
#include <orogen/plugin.hpp>

#include <algorithm>
#include <sstream>

namespace {

using namespace orogen;

struct StreamPower {
    double erodibility = 2e-5;  // m^(1-2m)/yr
    double m = 0.45;
    double n = 1.0;
    double channel_area = 0.0;  // m²
    double deposition = 0.0;
};

class StreamPowerProcess final : public Process {
public:
    explicit StreamPowerProcess(const StreamPower& s) : s_(s) {}

    void start(ProcessState& state) override {
        inv_ac_ = s_.channel_area > 0.0 ? 1.0 / s_.channel_area : 0.0;
        table_ = landscape::area_power_table(state.cell(), s_.m, inv_ac_);
        keep_incision_ = state.wanted("incision");
    }

    void step(ProcessState& state, double dt) override {
        std::vector<double>& h = state.field(kElevation);
        const FlowGraph& flow = state.flow();
        if (keep_incision_) before_.assign(h.begin(), h.end());
        const std::vector<double>& k = state.field("erodibility_factor");
        landscape::Incision in;
        in.width = state.width();
        in.cell = state.cell();
        in.erodibility = s_.erodibility;
        in.area_exponent = s_.m;
        in.slope_exponent = s_.n;
        in.inv_channel_area = inv_ac_;
        in.pow_table = table_.data();
        in.area = flow.area.data();
        in.receivers = flow.receivers.data();
        in.stack = flow.stack.data();
        in.chunks = flow.chunks;
        in.rock_k = k.empty() ? nullptr : k.data();
        if (s_.deposition > 0.0) {
            const landscape::Deposited d =
                landscape::incise_with_deposition(in, s_.deposition, !flow.multiple, dt, h.data(), h.size(), scratch_);
            sediment_out_ += d.sediment_out;
        } else {
            landscape::incise(in, dt, h.data());
        }
        if (keep_incision_) {
            // The lowering by this incision, for the banks (m, ≥ 0).
            std::vector<double>& lowered = state.field("incision");
            lowered.resize(h.size());
            parallel_for(0, std::int64_t(h.size()), 1 << 15, [&](std::int64_t b, std::int64_t e) {
                for (auto i = std::size_t(b); i < std::size_t(e); ++i) lowered[i] = std::max(0.0, before_[i] - h[i]);
            });
        }
    }

    std::string summary() const override {
        if (!(s_.deposition > 0.0)) return {};
        std::ostringstream s;
        s << sediment_out_ * 1e-9 << " km³ of sediment left by the outlets";
        return s.str();
    }

private:
    StreamPower s_;
    double inv_ac_ = 0.0;
    std::vector<double> table_;  // A^m·(1 − e^(−A/A_c)) for whole numbers of cells
    bool keep_incision_ = false;
    std::vector<double> before_;
    landscape::DepositionScratch scratch_;
    double sediment_out_ = 0.0;  // m³
};

}  // namespace

OROGEN_PLUGIN("process-stream-power", "0.1.0", registry) {
    ProcessParams<StreamPower> p;
    p.real(&StreamPower::erodibility, "erodibility")
        .min(0.0, true)
        .max(1e-2)
        .unit("m^(1-2m)/yr")
        .help(
            "K: 1e-7 (hard rock, dry) to 1e-4 (soft rock, wet) for m ~ 0.5, n = 1 (Stock & Montgomery 1999); "
            "times the erodibility_factor of a rock process before it");
    p.real(&StreamPower::m, "m")
        .min(0.1)
        .max(1.5)
        .help("area exponent (0.3-0.6 with n = 1; m/n is the concavity, 0.35-0.6 in real rivers)");
    p.real(&StreamPower::n, "n")
        .min(0.5)
        .max(4.0)
        .help("slope exponent (2/3-2 measured, Whipple & Tucker 1999; up to 4, Lague 2014)");
    p.real(&StreamPower::channel_area, "channel_area")
        .min(0.0)
        .max(1e10)
        .unit("m²")
        .help(
            "drainage area where rivers take over from hillslopes: incision is scaled by 1 - exp(-A/channel_area), "
            "so smaller catchments are shaped by creep (channel heads at 1e3-1e5 m², Montgomery & Dietrich "
            "1988); 0 = every cell is a river");
    p.real(&StreamPower::deposition, "deposition")
        .min(0.0)
        .max(10.0)
        .help(
            "G of Yuan et al. (2019), dimensionless: the sediment flux deposits G·Qs/A on its way down (0 = "
            "detachment-limited; ~1 = half the eroded rock settles in the valleys at steady state)");
    registry.add(ProcessDescriptor{
        .name = "stream-power",
        .summary = "river incision by stream power K A^m S^n, implicit along the flow graph; optional deposition",
        .description =
            "Lowers each cell towards its receiver by K·A^m·S^n (times the erodibility_factor a rock process "
            "made, if any), solved implicitly in stack order so that any dt is stable and a cell never drops "
            "below its receiver (Braun & Willett 2013; Newton's method for n != 1). deposition=G > 0 lets G·Qs/A "
            "of the sediment flux settle on its way down, solved exactly on the receiver tree (Yuan et al. "
            "2019). A cell at or below its receiver (a lake) is not eroded. Writes the incision field (the "
            "lowering, m) when a later process reads it (banks).",
        .params = p.params(),
        .fields = {{kElevation, FieldAccess::updates, "m", "incised"},
                   {kFlowGraph, FieldAccess::reads, "", "receivers, stack, drainage area"},
                   {"erodibility_factor", FieldAccess::reads_if_present, "1", "the rock's K over K"},
                   {"incision", FieldAccess::writes, "m", "what this sub-step's incision lowered each cell by"}},
        .make = [p](const ProcessCall& call) -> std::unique_ptr<Process> {
            return std::make_unique<StreamPowerProcess>(p.bind(call.params));
        },
    });
}
