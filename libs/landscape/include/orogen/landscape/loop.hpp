// loop.hpp — a landscape-evolution loop over processes (orogen/process.hpp): the fields they share,
// the flow graph one of them publishes, the clock, and the order they run in.
//
// Each step of dt years runs in `substeps` sub-steps of dt/substeps; in each sub-step every process
// runs in the body's order, but a process of Cadence::once_per_step (routing, rain) only in the first.
// So the body `uplift flow creep stream-power landslides` with two sub-steps runs
//
//     uplift flow creep stream-power landslides | uplift creep stream-power landslides
//
// which is erode:stream-power's own order (stream_power.hpp), and gives its bits.
#pragma once

#include <orogen/process.hpp>
#include <orogen/values.hpp>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace orogen::landscape {

class ProcessLoop final : public ProcessState {
public:
    struct Options {
        OpenSides open;
        std::optional<double> base_level;  ///< m: the outlets' height (none: they keep theirs)
        int substeps = 1;
        double years = 0.0;  ///< the whole run's (run_years())
        std::uint64_t seed = 0;  ///< the node's
        std::function<void(std::string_view)> info, warn;
    };

    /// `terrain` the heights to evolve (its layers stay as given, for the processes to read);
    /// `inputs` the node's inputs (terrain first). Makes each process (its descriptor's make).
    ProcessLoop(const std::vector<ProcessCall>& calls, std::shared_ptr<Heightmap> terrain, std::vector<Value> inputs,
                Options options);

    /// Once before the first step: each process's start().
    void start();
    /// One step of `dt` years.
    void advance(double dt);
    /// Run `years` in steps of `dt` (the last one shorter, as erode:stream-power); on_step(step, steps) after each.
    void run(double years, double dt, const std::function<void(std::int64_t, std::int64_t)>& on_step = {});
    /// After the last step: the heights into the terrain, then each process's finish() (its layers).
    void finish();

    /// Index of the first non-finite height, or −1.
    std::int64_t first_non_finite() const;
    /// Each process's summary clause, in order ("" left out).
    std::vector<std::string> summaries() const;
    /// The heights (m), as the processes leave them.
    const std::vector<double>& heights() const { return elevation_; }
    std::vector<double>& heights() { return elevation_; }
    const std::vector<double>& uplifted_so_far() const { return uplifted_; }
    Heightmap& result() { return *terrain_; }
    /// For the host (Python): a field by name, whoever declared it (elevation and uplifted included); null
    /// if no process of the body declares it.
    std::vector<double>* find_field(std::string_view name);
    /// Every field the body's processes declare, and elevation and uplifted (sorted, without the flow graph).
    std::vector<std::string> field_names() const;

    // ProcessState
    int width() const override { return width_; }
    int height() const override { return height_; }
    double cell() const override { return cell_; }
    const OpenSides& open() const override { return options_.open; }
    const std::vector<std::uint8_t>& outlets() const override { return outlets_; }
    double time() const override { return time_; }
    double step_years() const override { return step_years_; }
    int substep() const override { return substep_; }
    int substeps() const override { return options_.substeps; }
    std::int64_t step() const override { return step_; }
    double run_years() const override { return options_.years; }
    std::vector<double>& field(std::string_view name) override;
    bool wanted(std::string_view name) const override;
    const FlowGraph& flow() const override { return flow_; }
    void set_flow(const FlowGraph& graph) override { flow_ = graph; }
    std::uint64_t seed() const override;
    const Heightmap& terrain() const override { return *terrain_; }
    const Value& node_input(std::size_t i) const override;
    void info(std::string_view message) override;
    void warn(std::string_view message) override;

private:
    struct Running {
        const ProcessCall* call;
        std::unique_ptr<Process> process;
    };
    void each(const std::function<void(Process&)>& run);  // every process in order, current_ set

    int width_, height_;
    double cell_;
    Options options_;
    std::shared_ptr<Heightmap> terrain_;
    std::vector<Value> inputs_;
    std::vector<Running> processes_;
    std::vector<double> elevation_, uplifted_;
    std::map<std::string, std::vector<double>, std::less<>> fields_;
    std::vector<std::uint8_t> outlets_;
    FlowGraph flow_;
    double time_ = 0.0, step_years_ = 0.0;
    int substep_ = 0;
    std::int64_t step_ = 0;
    std::size_t current_ = 0;  // the process running
};

/// The outlet mask of a width × height grid: the open sides' cells, or with every side closed the
/// lowest of `heights` (lowest index among equals), as FlowRouter's.
std::vector<std::uint8_t> outlet_mask(int width, int height, const OpenSides& open, const std::vector<double>& heights);

}  // namespace orogen::landscape
