// The kernel's front door: load the plugins, parse and check a spec, bind
// values, run it with hooks, read its results and diagnostics. The `orogen`
// command, the Python module and the tests that run specs go through it;
// nothing outside kernel/src/ includes a header of the kernel's rooms
// (kernel/src/README.md), and a test holds that.
//
//     orogen::Session session(exe);                    // plugins found from the binary's path
//     orogen::Checked spec = session.check(orogen::SpecText::read("alps.orogen"));
//     if (!spec.ok()) { std::fputs(spec.report().text_with_count().c_str(), stderr); return 2; }
//     orogen::RunResult result = session.run(spec, {.out_dir = "out"});
//
// The shape of GDAL's GDALOpen or LLVM's PassBuilder: one small object in
// front of the machinery, which stays free to change behind it.
#pragma once

#include <orogen/plugin.hpp>
#include <orogen/process.hpp>
#include <orogen/tiles.hpp>
#include <orogen/values.hpp>

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace orogen {

// ----------------------------------------------------------------- plugins

/// A plugin library the session loaded.
struct PluginRecord {
    std::string name, version, file;
    /// The library's binary identity ("build-id:<hex>" or "sha256:<hex>"), part of every cache key of its nodes,
    /// so a rebuilt plugin whose code changed never finds the old results. "": unknown, its nodes are not cached.
    std::string identity;
};

// ------------------------------------------------------------ diagnostics

/// One message about a spec or a --set override: where, how bad, what.
struct Diagnostic {
    enum class Severity { error, warning, note };
    Severity severity = Severity::error;
    std::string file;  ///< the spec's name as given ("alps.orogen", "--set" for an override)
    int line = 0, column = 0;  ///< 1-based; 0 when the message is about the whole file
    std::string message;
    /// "file:3:7: error: message", the source line and a caret under the place (LLVM's SourceMgr format).
    std::string formatted;
};

/// Everything a check said, in the order of the spec (each --set after it).
struct CheckReport {
    std::string name;  ///< the spec's name, for the count line
    std::vector<Diagnostic> diagnostics;
    int errors = 0;
    int warnings = 0;

    /// Every diagnostic, formatted, in order ("" if there are none).
    std::string text() const;
    /// "3 errors in alps.orogen\n" ("" without errors).
    std::string count_line() const;
    /// text() then count_line(): what `orogen check` prints for a spec with errors.
    std::string text_with_count() const { return text() + count_line(); }
};

// ------------------------------------------------------------------ specs

/// A spec's text and where it came from.
struct SpecText {
    std::string name;  ///< for messages
    std::string text;
    std::filesystem::path path;  ///< its input paths are relative to this file's folder

    /// The file at `path`. Throws orogen::Error (bad input) naming the file when it is missing, a folder or
    /// unreadable.
    static SpecText read(const std::filesystem::path& path);
    /// Text made elsewhere (a Python string, a spec composed from a command line), named `name`; input paths
    /// are relative to `folder`.
    static SpecText of(std::string name, std::string text, const std::filesystem::path& folder);
};

/// A run split into tiles under mpirun (docs/mpi.md): this process's rank among `ranks`.
struct TiledSettings {
    int rank = 0, ranks = 1;
    /// rows × columns (--tiles RxC); nullopt: as square as the grid allows.
    std::optional<std::pair<int, int>> tiles;
    /// The ranks on this machine (they share its memory); 0: all of them.
    int ranks_on_this_machine = 0;
};

/// Values the caller hands to a run by name, made outside any spec (Python's node() inputs, a value from an
/// earlier run). The spec reads `name` as if an earlier line had made it.
using BoundValues = std::map<std::string, Value, std::less<>>;

struct CheckSettings {
    std::vector<std::string> overrides;  ///< "NAME.PARAM=VALUE", as --set gives them
    std::optional<std::uint64_t> seed;  ///< overrides the spec's
    /// Where outputs go: every output path must resolve inside it, unless allow_outside_out.
    std::filesystem::path out_dir = "out";
    bool allow_outside_out = false;
    /// The values run() will be given (their types, sizes and layers are what the checker needs).
    const BoundValues* bound = nullptr;
    /// A tiled run: its rules (one tile per rank, halos, whole-grid nodes that fit) are checked too.
    std::optional<TiledSettings> tiled;
};

/// A node of a checked spec, as a caller may look at it.
struct CheckedNode {
    std::string label;  ///< its value name, or kind:name for an unnamed call
    std::string value_name;  ///< "" if unnamed
    const NodeDescriptor* node = nullptr;
    int line = 0;
    const std::map<std::string, ParamValue, std::less<>>* params = nullptr;  ///< every parameter, defaults filled in
    const std::vector<ProcessCall>* processes = nullptr;  ///< a loop node's body
    std::uint64_t seed = 0;  ///< what NodeContext::seed() gives it
    /// "" if it runs on every rank's tile in a tiled run, else why it runs on rank 0 over the whole grid.
    std::string untiled_reason;
};

/// A spec after check(): the plan a run executes, and what the check said. Move-only.
class Checked {
public:
    Checked();
    ~Checked();
    Checked(Checked&&) noexcept;
    Checked& operator=(Checked&&) noexcept;

    /// No errors: it can run.
    bool ok() const;
    const CheckReport& report() const;

    std::uint64_t seed() const;
    GridSpec grid() const;
    bool grid_given() const;  ///< a `grid` line (else 513 x 513)
    bool cell_given() const;  ///< its cell= (else 1 m)
    std::vector<CheckedNode> nodes() const;
    /// A node declares an output path (it may write files): a run of it needs an out_dir.
    bool writes_files() const;
    /// The split of a tiled check (CheckSettings::tiled); a single tile otherwise.
    const TileSplit& tiles() const;

    /// Hand value `key` ("base", "sim.particles") back in RunResult::values after the run (else it is
    /// released after its last reader, and may be changed in place by it).
    void keep(const std::string& key);
    /// keep() every named value and its side values: what a caller that wants the results back asks for.
    void keep_named_values();
    /// Run only what `keys` need: every node that none of them reads, directly or through others, is dropped
    /// (an exporter with it, so no file is written that was not asked for), and the keys are kept. The
    /// nodes that stay get the same seeds and give the same bits. Throws orogen::BadInput naming a key the
    /// spec does not make, with the ones it does.
    void keep_only(const std::vector<std::string>& keys);
    /// The keys of the values this spec makes ("base", "sim.particles"), in spec order; no exporter's.
    std::vector<std::string> value_keys() const;

private:
    friend class Session;
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// ------------------------------------------------------------------ cache

/// The node cache's folder (docs/cache.md): what a run keeps, and `orogen cache info|clear`.
namespace cache {

struct Settings {
    std::filesystem::path folder;
    std::uint64_t max_bytes = std::uint64_t(2) << 30;  ///< 2 GiB
};

/// $XDG_CACHE_HOME/orogen, else $HOME/.cache/orogen; empty if neither variable is set.
std::filesystem::path default_folder();
/// "2G", "500M", "64MiB", "1e9", "123456" → bytes; nullopt if it is not a size.
std::optional<std::uint64_t> parse_size(std::string_view text);

/// What a cache folder holds (`orogen cache info`).
struct FolderFacts {
    bool exists = false;  ///< false: no such folder (nothing kept yet)
    std::uint64_t entries = 0;  ///< `<key>.orc` files
    std::uint64_t bytes = 0;  ///< their size
    std::int64_t oldest_ns = 0;  ///< least recently used entry's modification time (ns since 1970), if any
    std::int64_t newest_ns = 0;  ///< most recently used
    std::uint64_t temporaries = 0;  ///< half-written entries of runs in progress or killed
    std::uint64_t temporary_bytes = 0;
};
/// Throws orogen::BadInput if `folder` exists but is not a folder or cannot be listed.
FolderFacts folder_facts(const std::filesystem::path& folder);

struct Cleared {
    std::uint64_t entries = 0, bytes = 0;  ///< removed
    std::vector<std::string> failures;  ///< "file: why", one per entry that could not be removed
};
/// Remove every entry of `folder` and the temporaries of killed runs (older than an hour; a run in progress
/// keeps its own). Nothing else in the folder is touched, so pointing --cache at a wrong folder loses no
/// files of the user's. Throws orogen::BadInput as folder_facts does.
Cleared clear_folder(const std::filesystem::path& folder);

}  // namespace cache

// ------------------------------------------------------------------- runs

struct NodeTiming {
    std::string label, node;
    int line = 0;
    double seconds = 0.0;
    bool cached = false;  ///< it did not run: its result came from the cache (or nothing that ran needed it)
    bool read = false;  ///< cached, and its values were read from the cache for a node that ran
};

struct RunSettings {
    /// Where the outputs and manifest.json go. Empty: the run writes no files at all (no folder, no manifest),
    /// for a spec of which writes_files() is false; a node that asks for an output path then fails.
    std::filesystem::path out_dir = "out";
    int threads = 0;  ///< 0: all cores
    /// Where the progress line goes (nullptr: nowhere); a bar on a terminal, plain lines otherwise.
    std::FILE* progress = stderr;
    /// Drop what nodes say for information (a run that succeeds is then silent), never a warning.
    bool quiet = false;
    const std::atomic<bool>* cancel = nullptr;  ///< set: stop at the node's next check
    /// The signal that set `cancel` (SIGINT or SIGTERM), for the message.
    const std::atomic<int>* cancel_signal = nullptr;
    /// Told at once of each piece of debris of killed runs removed before this run.
    std::function<void(const std::string&)> on_note;
    /// One-line warnings that do not stop the run; default: the progress display.
    std::function<void(const std::string&)> on_warning;
    std::optional<cache::Settings> cache;  ///< nullopt: every node runs
    /// A tiled run under MPI: the settings the spec was checked with (the same split).
    std::optional<TiledSettings> tiled;
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
    /// The values Checked::keep() asked for (and any other still held after the last node).
    std::map<std::string, Value, std::less<>> values;
};

/// The timing table printed after a run.
std::string format_timings(const RunResult& result);

/// The seed a node gets: a hash of the spec's seed and the node's label.
std::uint64_t node_seed(std::uint64_t spec_seed, const std::string& label);

// ---------------------------------------------------------------- session

/// The plugins, loaded once, and what checks and runs specs against them. check() and run() may be called
/// from any thread, one run at a time per Checked.
class Session {
public:
    /// Load every plugin found from `exe` (the running binary's path: <exe>/../../lib/orogen/plugins, the
    /// install prefix's plugin folder, then OROGEN_PLUGIN_PATH). A library that cannot be loaded is a
    /// problem (plugin_problems()), never an exception.
    explicit Session(const std::filesystem::path& exe);
    ~Session();
    Session(const Session&) = delete;
    Session& operator=(const Session&) = delete;

    const Registry& registry() const;
    const std::vector<PluginRecord>& plugins() const;
    /// One line each, naming the file.
    std::vector<std::string> plugin_problems() const;
    /// The folders searched, in order.
    const std::vector<std::filesystem::path>& searched() const;

    /// Parse and check `spec`. Every mistake is reported at once: after a syntax error the statements that
    /// parsed are still checked (a value a broken line would have made is not reported again).
    Checked check(const SpecText& spec, const CheckSettings& settings = {}) const;

    /// Run a checked spec (ok() must be true). `bound` must hold the values the check was told of; it is
    /// taken over, so a value whose only holder was the caller is the node's to change in place.
    RunResult run(const Checked& spec, const RunSettings& settings, BoundValues bound = {}) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// -------------------------------------------------------------------- MPI

/// MPI for the life of the object, for a process that mpirun started (launched_size() > 0): MPI_Init in
/// the constructor, MPI_Finalize in the destructor. Throws orogen::Error if this orogen was built without MPI.
class MpiScope {
public:
    /// The number of processes mpirun started (OMPI_COMM_WORLD_SIZE, PMI_SIZE or PMIX_SIZE), 0 without mpirun.
    static int launched_size();
    MpiScope(int& argc, char**& argv);
    ~MpiScope();
    MpiScope(const MpiScope&) = delete;
    MpiScope& operator=(const MpiScope&) = delete;
    int rank() const { return rank_; }
    int size() const { return size_; }
    /// Collective: true on every rank if `failed` on any (stderr flushed first, so rank 0's message is out).
    bool failed_on_any(bool failed) const;
    /// The ranks on this machine (OMPI_COMM_WORLD_LOCAL_SIZE), between 1 and size().
    int ranks_on_this_machine() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    int rank_ = 0, size_ = 1;
};

/// "RxC" (rows x columns, e.g. "2x3") → {R, C}; nullopt if it is not that.
std::optional<std::pair<int, int>> parse_tiles(std::string_view text);

/// The closest candidate to `word` (Damerau–Levenshtein), or "" if none is close: for "did you mean".
std::string closest(std::string_view word, const std::vector<std::string>& candidates);

}  // namespace orogen
