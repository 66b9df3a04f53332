// Runs a checked plan: nodes in spec order, values handed from one to the
// next, each node timed, every error stopped at the node boundary.
#pragma once

#include "cache/cache.hpp"
#include "spec/plan.hpp"
#include "progress.hpp"

#include <atomic>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace orogen {

class TiledRun;  // tiles.hpp

struct PluginRecord {
    std::string name, version, file;
    /// The loaded library's binary identity (cache::binary_identity: "build-id:<hex>" or "sha256:<hex>"), part
    /// of every cache key of its nodes, so a rebuilt plugin whose code changed never finds the old results
    /// even if its version string did not change. "": unknown, and its nodes are not cached.
    std::string identity;
};

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

struct NodeTiming {
    std::string label, node;
    int line = 0;
    double seconds = 0.0;
    bool cached = false;  ///< it did not run: its result came from the cache (or nothing that ran needed it)
    bool read = false;  ///< cached, and its values were read from the cache for a node that ran
};

struct RunResult {
    int exit_code = 0;  ///< 0 ok, 1 failed run, 2 bad input, 130 cancelled
    std::string error;  ///< formatted diagnostic when exit_code != 0 ("" on a rank that only saw another fail)
    std::vector<NodeTiming> timings;
    std::vector<std::filesystem::path> outputs;  ///< files written (staged ones sorted), the manifest last
    std::vector<std::string> notes;  ///< debris of killed runs removed before this one, one line each
    double total_seconds = 0.0;
    /// "cache: 9 of 14 nodes reused from DIR (312 MiB of 2 GiB)"; empty without the cache.
    std::string cache_summary;
    /// After a successful run, the values still held: those whose Plan::last_use lies past the last node.
    /// The CLI wants none; a caller that wants a value back (the Python module) sets its last_use to
    /// plan.nodes.size() before the run, so it is kept (and never modified in place by a later node).
    std::map<std::string, Value, std::less<>> values;
};

/// The seed a node gets: a hash of the spec's seed and the node's label.
std::uint64_t node_seed(std::uint64_t spec_seed, const std::string& label);

/// Values the caller hands to a run by name, made outside any spec (the Python module's node() inputs: a
/// numpy array copied into a heightmap, a value from an earlier run). The spec reads `name` as if an
/// earlier line had made it; the checker learns what each is from CheckOptions::bound (describe_bound()).
/// No file, no importer: the value itself reaches the node. With the cache, a bound value is keyed by its
/// content (cache::bound_key over cache::value_hash), as a file an importer reads is.
using BoundValues = std::map<std::string, Value, std::less<>>;

/// What the checker knows of a bound value: its type, and a heightmap's size, cell and layers.
ValueInfo describe_bound(const Value& value);

/// True if a node of `plan` declares an output path (it may write files): such a plan needs an out_dir.
bool writes_files(const Plan& plan);

/// Runs `plan`. `bound` is taken over: a value whose only holder was the caller's map is the node's to
/// change in place when no later node reads it (NodeContext::take_heightmap: no copy).
RunResult run(const Plan& plan, const RunOptions& options, BoundValues bound = {});

/// The timing table printed after a run.
std::string format_timings(const RunResult& result);

}  // namespace orogen
