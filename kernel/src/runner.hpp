// Runs a checked plan: nodes in spec order, values handed from one to the
// next, each node timed, every error stopped at the node boundary.
#pragma once

#include "plan.hpp"
#include "progress.hpp"

#include <atomic>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace orogen {

class TiledRun;  // tiles.hpp

struct PluginRecord {
    std::string name, version, file;
};

struct RunOptions {
    std::filesystem::path out_dir = "out";
    int threads = 0;  ///< 0: all cores
    ProgressDisplay* progress = nullptr;
    std::vector<PluginRecord> plugins;  ///< for the manifest
    const std::atomic<bool>* cancel = nullptr;
    /// The signal that set `cancel` (SIGINT or SIGTERM), for the message; the caller picks the exit code.
    const std::atomic<int>* cancel_signal = nullptr;
    /// Told at once of each piece of debris of killed runs removed before this run (else kept in RunResult::notes).
    std::function<void(const std::string&)> on_note;
    /// A tiled run under MPI (tiles.hpp): this rank's side of it; nullptr for a single process.
    TiledRun* tiled = nullptr;
};

struct NodeTiming {
    std::string label, node;
    int line = 0;
    double seconds = 0.0;
};

struct RunResult {
    int exit_code = 0;        ///< 0 ok, 1 failed run, 2 bad input, 130 cancelled
    std::string error;        ///< formatted diagnostic when exit_code != 0 ("" on a rank that only saw another fail)
    std::vector<NodeTiming> timings;
    std::vector<std::filesystem::path> outputs;  ///< files written (staged ones sorted), the manifest last
    std::vector<std::string> notes;              ///< debris of killed runs removed before this one, one line each
    double total_seconds = 0.0;
};

/// The seed a node gets: a hash of the spec's seed and the node's label.
std::uint64_t node_seed(std::uint64_t spec_seed, const std::string& label);

RunResult run(const Plan& plan, const RunOptions& options);

/// The timing table printed after a run.
std::string format_timings(const RunResult& result);

}  // namespace orogen
