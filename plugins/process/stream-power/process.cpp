// process stream-power — fluvial incision by stream power, E = K·A^m·S^n (detachment-limited), or with
// deposition of a share of the sediment flux on its way down (Yuan et al. 2019), solved implicitly along
// the flow graph in stack order (Braun & Willett 2013: stable at any dt). libs/landscape/stream_power.hpp.
#include <orogen/landscape/stream_power.hpp>

#include <orogen/parallel.hpp>
#include <orogen/landscape/processes.hpp>
#include <orogen/plugin.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace {

using namespace orogen;

class StreamPowerProcess final : public Process {
public:
    explicit StreamPowerProcess(const landscape::StreamPowerSpec& s) : s_(s) {}

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
        // Glaciers before it: their K_g·dt·Q^m_g over L^n joins the rivers' factor in the same sweep.
        if (const std::vector<double>& ice = state.field("glacial_factor"); !ice.empty()) {
            ice_f_.resize(ice.size());
            parallel_for(0, std::int64_t(ice.size()), 1 << 14, [&](std::int64_t b, std::int64_t e) {
                for (std::int64_t i = b; i < e; ++i)
                    ice_f_[std::size_t(i)] =
                        ice[std::size_t(i)] != 0.0 ? ice[std::size_t(i)] / std::pow(flow.distance(i), s_.n) : 0.0;
            });
            in.ice_f = ice_f_.data();
        }
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
    landscape::StreamPowerSpec s_;
    double inv_ac_ = 0.0;
    std::vector<double> table_;  // A^m·(1 − e^(−A/A_c)) for whole numbers of cells
    bool keep_incision_ = false;
    std::vector<double> before_;
    landscape::DepositionScratch scratch_;
    std::vector<double> ice_f_;  // glaciers: K_g·dt·Q^m_g/L^n
    double sediment_out_ = 0.0;  // m³
};

}  // namespace

OROGEN_PLUGIN("process-stream-power", "0.1.0", registry) {
    const ProcessParams<landscape::StreamPowerSpec> p = landscape::stream_power_params();
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
                   {"glacial_factor", FieldAccess::reads_if_present, "m^(1-3m_g)·yr^m_g", "glaciers' K_g·dt·Q^m_g"},
                   {"incision", FieldAccess::writes, "m", "what this sub-step's incision lowered each cell by"}},
        .tile_halo = 1,  // tiled under mpirun within erode:stream-power's model (landscape/processes.hpp)
        .make = [p](const ProcessCall& call) -> std::unique_ptr<Process> {
            return std::make_unique<StreamPowerProcess>(p.bind(call.params));
        },
    });
}
