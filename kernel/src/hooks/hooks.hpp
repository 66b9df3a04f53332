// The runner's instrumentation: what happens around each node that is not
// running it. The run loop (runner.cpp) walks the plan and calls every hook at
// fixed points, the way LLVM's PassInstrumentation calls its callbacks around
// each pass; the node cache (cache/), progress and timing (run/) and the
// agreement of a tiled run's ranks (tiles/) are hooks, each in its own room,
// so a change to one of them does not edit the runner.
//
// Around node j, in this order:
//   at_turn       its turn in spec order, before anything runs: a hook may
//                 answer that it need not run (its effects are put back now)
//                 or that it runs only if a later node reads it
//   supply        a node that runs needs a value of node j that is not at
//                 hand: a hook may supply it (a cache entry) instead of running j
//   before_node   j is about to run, its inputs made (may say "not here": a
//                 node that rank 0 alone runs)
//   settle        j stopped, well or not: a hook may turn the outcome
//                 (every rank learns of any rank's failure)
//   after_node    j finished well, before its outputs are checked
//   on_result     j's outputs are checked and kept
//   skipped       j did not run (at_turn answered for it)
// and once, bound, for each value the caller bound (run()'s `bound`) before
// the first node, and run_finished, after the last node (failed or not).
//
// The room sits below its users (cache/, tiles/, run/), as LLVM keeps
// PassInstrumentation.h below the pass managers: it includes the plan and the
// public headers, nothing of theirs.
#pragma once

#include "spec/plan.hpp"

#include <orogen/node.hpp>
#include <orogen/session.hpp>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace orogen {

class Staging;  // io/outputs.hpp
class ProgressDisplay;  // run/progress.hpp
class TiledRun;  // tiles/tiles.hpp

/// What a run is told: where files go, threads, progress, cancellation, the cache, the plugins, the tiles.
struct RunOptions {
    /// Where the outputs and manifest.json go. Empty: the run writes no files at all (no folder, no
    /// staging, no manifest), for a plan of which writes_files() is false (the Python module's node());
    /// a node that asks for an output path then fails.
    std::filesystem::path out_dir = "out";
    int threads = 0;  ///< 0: all cores
    ProgressDisplay* progress = nullptr;
    std::vector<PluginRecord> plugins;  ///< for the manifest
    const std::atomic<bool>* cancel = nullptr;
    /// The signal that set `cancel` (SIGINT or SIGTERM), for the message; the caller picks the exit code.
    const std::atomic<int>* cancel_signal = nullptr;
    /// Told at once of each piece of debris of killed runs removed before this run (else kept in RunResult::notes).
    std::function<void(const std::string&)> on_note;
    /// The node cache (docs/cache.md); nullopt: every node runs.
    std::optional<cache::Settings> cache;
    /// kind:name → the plugin that provides it (its name and version go into cache keys; a node not
    /// listed is never cached).
    std::map<std::string, PluginRecord, std::less<>> node_plugins;
    /// One-line warnings that do not stop the run (a damaged cache entry...); default: the progress display.
    std::function<void(const std::string&)> on_warning;
    /// A tiled run under MPI (tiles.hpp): this rank's side of it; nullptr for a single process.
    TiledRun* tiled = nullptr;
};

/// A node failed; the message is formatted (node_error). Thrown through the run loop to run().
struct NodeFailed {
    int exit_code;
    std::string message;
};

/// "file:line:col: error: node 'x' (kind:name) failed: <message>", with the source line.
std::string node_error(const PlannedNode& node, const std::string& message);

/// What every hook of one run shares: the plan, the options, where files go, the result being built.
struct RunShared {
    const Plan& plan;
    const RunOptions& options;
    /// This process's staging folder, or nullptr on a rank of a tiled run other than 0 (it writes into
    /// rank 0's, `staging_folder`).
    const Staging* staging;
    std::filesystem::path staging_folder;
    std::vector<std::filesystem::path>& outside;  ///< outputs written outside --out so far
    RunResult& result;
    /// Files of cached exports already in --out with the same bytes (relative to --out): listed, not moved.
    std::vector<std::filesystem::path> kept;

    /// A one-line warning that does not stop the run (RunOptions::on_warning, else the progress display).
    void warn(const std::string& line) const;
};

/// Node j as the hooks see it.
struct NodeTurn {
    std::size_t index;
    const PlannedNode& node;
    NodeTiming& timing;  ///< its row in the timing table
};

/// A node that need not run: why (for the progress line), what it said when it ran, its values (kept if read).
struct Reuse {
    std::string why;
    std::vector<std::string> said;
    std::vector<std::pair<std::string, Value>> values;  ///< "" for the main value, else the side output's name
};

/// A hook's answer at a node's turn.
struct TurnAnswer {
    enum class Kind { run, reused, deferred } kind = Kind::run;
    Reuse reuse;  ///< for reused
};

/// How a node stopped: exit code 0 if it finished, else 1, 2 or 130 and the formatted message.
struct Outcome {
    int exit_code = 0;
    std::string error;
    bool agreed = false;  ///< a tiled node learnt of another rank's failure: the ranks already agree
};

class NodeHooks {
public:
    virtual ~NodeHooks() = default;
    /// A value the caller bound by name (runner.hpp BoundValues), before the first node's turn.
    virtual void bound(const std::string& /*name*/, const Value&) {}
    virtual TurnAnswer at_turn(const NodeTurn&) { return {}; }
    /// The producer's values, if the hook has them without running it.
    virtual std::optional<Reuse> supply(const NodeTurn&) { return std::nullopt; }
    /// Returns false if this process does not run the node (it runs elsewhere). Throws like a node.
    virtual bool before_node(const NodeTurn&, std::vector<Value>& /*inputs*/) { return true; }
    virtual void settle(const NodeTurn&, Outcome&) {}
    virtual void after_node(const NodeTurn&) {}
    /// `said`: what the node said through info/warn.
    virtual void on_result(const NodeTurn&, const NodeOutputs&, const std::vector<std::string>& /*said*/) {}
    virtual void skipped(const NodeTurn&, const Reuse&) {}
    virtual void run_finished() {}
};

/// Progress line and timing table (run/progress_hooks.cpp).
std::unique_ptr<NodeHooks> progress_hooks(RunShared& shared);
/// The node cache (cache/cache_hooks.cpp); nullptr when the run has none or it cannot be used.
std::unique_ptr<NodeHooks> cache_hooks(RunShared& shared);
/// The agreement of a tiled run's ranks (tiles/tiled_hooks.cpp); nullptr for a single process.
std::unique_ptr<NodeHooks> tiled_hooks(RunShared& shared);

/// Collective in a tiled run: every rank learns the worst exit code; only the lowest failing rank keeps its
/// message (tiles/tiled_hooks.cpp).
void agree_across_ranks(TiledRun& tiled, int& exit_code, std::string& error);

}  // namespace orogen
