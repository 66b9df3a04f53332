// The `orogen` command: run | check | list | help | version | cache | analyze.
// Exit codes: 0 success, 1 the run failed, 2 bad input (spec, file, value,
// usage), 130 interrupted (SIGINT), 143 terminated (SIGTERM).
// Everything it does goes through the kernel's front door, orogen/session.hpp.
#include "analyze.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/session.hpp>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <iostream>
#include <map>
#include <sstream>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace orogen;

namespace {

constexpr int exit_ok = 0, exit_failed = 1, exit_bad_input = 2;

std::atomic<bool> g_cancel{false};
std::atomic<int> g_signal{0};
// The first SIGINT or SIGTERM asks the run to stop at the node's next check (its staged outputs are then
// removed); a second one ends the process at once (a later run removes what it staged).
extern "C" void on_interrupt(int sig) {
    if (g_cancel.exchange(true)) {
        std::signal(sig, SIG_DFL);
        std::raise(sig);
        return;
    }
    g_signal.store(sig);
}

const char* usage_text =
    "usage:\n"
    "  orogen run SPEC [--out DIR] [--seed N] [--threads N] [--set NAME.PARAM=VALUE]... [--quiet]\n"
    "                  [--allow-outside-out] [--cache DIR | --no-cache] [--cache-size SIZE] [--tiles RxC]\n"
    "  orogen check SPEC [--out DIR] [--set NAME.PARAM=VALUE]...   parse and check only; prints every diagnostic\n"
    "  orogen analyze FILE... [--against DEM...] [--out DIR] [--cell M] [--heights LOW:HIGH] [--no-render]\n"
    "                 [--fit-filled-flats] [--threads N] [--quiet]\n"
    "                                                  measure terrains (slopes, hypsometry, spectrum, rivers...)\n"
    "                                                  against real DEMs: a table, DIR/analysis.json, charts,\n"
    "                                                  renderings and DIR/README.md (default DIR: analysis/;\n"
    "                                                  docs/analysis.md)\n"
    "  orogen analyze --discriminate TERRAIN... --against DEM... [--window-m M] [--out DIR]\n"
    "                                                  can a classifier tell the terrains from the DEMs, window\n"
    "                                                  by window? DIR/discriminate.json, .txt, .png\n"
    "  orogen list [KIND]                              the nodes (and processes) the loaded plugins provide\n"
    "  orogen help NODE                                a node's inputs and parameters\n"
    "  orogen version                                  kernel, plugin API and plugin versions\n"
    "  orogen cache info [--cache DIR] [--cache-size SIZE]   what the cache folder holds: entries, size, limit,\n"
    "                                                  least and most recently used\n"
    "  orogen cache clear [--cache DIR]                remove every cache entry (nothing else in the folder)\n"
    "\n"
    "Output paths in a spec are relative to --out (default: out/) and must stay inside it unless\n"
    "--allow-outside-out is given. A run's outputs appear together, the manifest last, or not at all.\n"
    "Each node's result is kept in a cache folder (default: $XDG_CACHE_HOME/orogen or ~/.cache/orogen;\n"
    "--cache DIR picks another, --no-cache or OROGEN_NO_CACHE=1 turns it off) of at most --cache-size\n"
    "(default 2G; K, M, G, T suffixes), least recently used entries evicted: a re-run recomputes only\n"
    "what changed.\n"
    "Under mpirun (`mpirun -n N orogen run SPEC`), the grid is cut into one tile per rank, R rows by\n"
    "C columns (--tiles RxC, default: as square as N allows); see docs/mpi.md.\n"
    "Plugins are loaded from\n"
    "<prefix>/lib/orogen/plugins and from OROGEN_PLUGIN_PATH (folders or .so files, ':'-separated).\n";

int usage_error(const std::string& message) {
    std::fprintf(stderr, "orogen: error: %s\n%s", message.c_str(), usage_text);
    return exit_bad_input;
}

fs::path self_path(const char* argv0) {
    std::error_code ec;
    fs::path p = fs::read_symlink("/proc/self/exe", ec);
    return ec ? fs::absolute(argv0) : p;
}

void print_problems(const Session& plugins) {
    for (const auto& p : plugins.plugin_problems()) std::fprintf(stderr, "orogen: warning: plugin %s\n", p.c_str());
}

struct Args {
    std::string command;
    std::vector<std::string> positional;
    std::string out = "out";
    std::optional<std::uint64_t> seed;
    int threads = 0;
    bool quiet = false;
    bool allow_outside_out = false;
    std::vector<std::string> overrides;
    std::optional<std::string> cache_dir;  ///< --cache DIR
    bool no_cache = false;  ///< --no-cache
    std::uint64_t cache_size = cache::Settings{}.max_bytes;
    std::optional<std::pair<int, int>> tiles;  ///< --tiles RxC
    std::string tiles_text;
};

/// The MPI side of this process: set when mpirun started it.
const MpiScope* g_mpi = nullptr;  // MPI for the life of main (main's mpi_scope)

std::optional<std::uint64_t> parse_u64(const std::string& s) {
    if (s.empty() || s.find_first_not_of("0123456789") != std::string::npos || s.size() > 20) return std::nullopt;
    errno = 0;
    char* end = nullptr;
    const unsigned long long v = std::strtoull(s.c_str(), &end, 10);
    if (errno == ERANGE) return std::nullopt;
    return std::uint64_t(v);
}

/// Parse options; returns an exit code on error.
std::optional<int> parse_args(int argc, char** argv, Args& a) {
    for (int i = 2; i < argc; ++i) {
        std::string arg = argv[i];
        auto value = [&](const std::string& name) -> std::optional<std::string> {
            const auto eq = arg.find('=');
            if (eq != std::string::npos && arg.substr(0, eq) == name) return arg.substr(eq + 1);
            if (arg == name) {
                if (i + 1 >= argc) return std::nullopt;
                return std::string(argv[++i]);
            }
            return std::nullopt;
        };
        auto is = [&](const std::string& name) { return arg == name || arg.rfind(name + "=", 0) == 0; };
        if (is("--out")) {
            auto v = value("--out");
            if (!v || v->empty()) return usage_error("--out needs a folder");
            a.out = *v;
        } else if (is("--seed")) {
            auto v = value("--seed");
            auto n = v ? parse_u64(*v) : std::nullopt;
            if (!n)
                return usage_error("--seed needs a whole number from 0 to 2^64-1" +
                                   (v ? ", got '" + *v + "'" : std::string()));
            a.seed = n;
        } else if (is("--threads")) {
            auto v = value("--threads");
            auto n = v ? parse_u64(*v) : std::nullopt;
            if (!n || *n < 1 || *n > 1024)
                return usage_error("--threads needs a number from 1 to 1024" +
                                   (v ? ", got '" + *v + "'" : std::string()));
            a.threads = int(*n);
        } else if (is("--set")) {
            auto v = value("--set");
            if (!v) return usage_error("--set needs NAME.PARAM=VALUE");
            a.overrides.push_back(*v);
        } else if (is("--cache-size")) {
            auto v = value("--cache-size");
            auto n = v ? cache::parse_size(*v) : std::nullopt;
            if (!n)
                return usage_error("--cache-size needs a size such as 2G, 500M or 1073741824" +
                                   (v ? ", got '" + *v + "'" : std::string()));
            a.cache_size = *n;
        } else if (is("--cache")) {
            auto v = value("--cache");
            if (!v || v->empty()) return usage_error("--cache needs a folder");
            a.cache_dir = *v;
        } else if (arg == "--no-cache") {
            a.no_cache = true;
        } else if (is("--tiles")) {
            auto v = value("--tiles");
            a.tiles = v ? parse_tiles(*v) : std::nullopt;
            if (!a.tiles)
                return usage_error("--tiles needs ROWSxCOLUMNS, e.g. 2x3" + (v ? ", got '" + *v + "'" : std::string()));
            a.tiles_text = *v;
        } else if (arg == "--allow-outside-out") {
            a.allow_outside_out = true;
        } else if (arg == "--quiet" || arg == "-q") {
            a.quiet = true;
        } else if (arg.size() > 1 && arg[0] == '-') {
            static const std::vector<std::string> options = {
                "--out",      "--seed",  "--threads",           "--set",  "--cache-size", "--cache",
                "--no-cache", "--tiles", "--allow-outside-out", "--quiet"};
            const std::string guess = closest(arg.substr(0, arg.find('=')), options);
            return usage_error("unknown option '" + arg + "'" +
                               (guess.empty() ? "" : "; did you mean '" + guess + "'?"));
        } else {
            a.positional.push_back(arg);
        }
    }
    if (a.no_cache && a.cache_dir) return usage_error("--cache and --no-cache contradict each other; give one");
    return std::nullopt;
}

/// The cache a run uses (nullopt: none), from --cache, --no-cache, OROGEN_NO_CACHE and the user's cache folder.
std::optional<cache::Settings> cache_settings(const Args& args) {
    if (args.no_cache) return std::nullopt;
    cache::Settings s;
    s.max_bytes = args.cache_size;
    if (args.cache_dir) {  // the command line wins over the environment
        s.folder = *args.cache_dir;
        return s;
    }
    if (const char* off = std::getenv("OROGEN_NO_CACHE"); off && *off && std::string(off) != "0") return std::nullopt;
    s.folder = cache::default_folder();
    if (s.folder.empty()) {
        std::fprintf(stderr,
                     "orogen: warning: neither XDG_CACHE_HOME nor HOME is set, so there is no cache folder; "
                     "running without the cache (give one with --cache DIR)\n");
        return std::nullopt;
    }
    return s;
}

std::string utc_time(std::int64_t ns) {
    const std::time_t t = std::time_t(ns / 1'000'000'000);
    std::tm tm{};
    ::gmtime_r(&t, &tm);
    char buf[64];
    std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S UTC", &tm);
    return buf;
}

/// `orogen cache info|clear`: the folder a run would use (--cache DIR, else the user's cache folder; not
/// turned off by OROGEN_NO_CACHE, which is about runs).
int cmd_cache(const Args& args) {
    if (args.positional.size() != 1 || (args.positional[0] != "info" && args.positional[0] != "clear"))
        return usage_error(args.positional.empty() ? "cache needs 'info' or 'clear'"
                                                   : "cache takes 'info' or 'clear', got '" + args.positional[0] + "'");
    if (args.no_cache) return usage_error("--no-cache means no cache folder; give the folder with --cache DIR");
    const fs::path folder = args.cache_dir ? fs::path(*args.cache_dir) : cache::default_folder();
    if (folder.empty()) {
        std::fprintf(stderr,
                     "orogen: error: neither XDG_CACHE_HOME nor HOME is set, so there is no default cache "
                     "folder; give one with --cache DIR\n");
        return exit_bad_input;
    }
    if (args.positional[0] == "clear") {
        const cache::Cleared c = cache::clear_folder(folder);
        for (const auto& f : c.failures) std::fprintf(stderr, "orogen: error: cannot remove %s\n", f.c_str());
        std::printf("removed %llu cache entr%s (%s) from %s\n", static_cast<unsigned long long>(c.entries),
                    c.entries == 1 ? "y" : "ies", human_bytes(double(c.bytes)).c_str(), folder.c_str());
        return c.failures.empty() ? exit_ok : exit_failed;
    }
    const cache::FolderFacts f = cache::folder_facts(folder);
    std::printf("cache folder: %s%s\n", folder.c_str(), f.exists ? "" : " (does not exist yet: nothing kept)");
    std::printf("entries:      %llu (%s)\n", static_cast<unsigned long long>(f.entries),
                human_bytes(double(f.bytes)).c_str());
    std::printf("limit:        %s%s\n", human_bytes(double(args.cache_size)).c_str(),
                args.cache_size == cache::Settings{}.max_bytes ? " (the default; a run's --cache-size sets its own)"
                                                               : " (--cache-size)");
    if (f.entries > 0) {
        std::printf("oldest:       %s (least recently used)\n", utc_time(f.oldest_ns).c_str());
        std::printf("newest:       %s (most recently used)\n", utc_time(f.newest_ns).c_str());
    }
    if (f.temporaries > 0)
        std::printf("temporaries:  %llu (%s) being written by a run, or left by a killed one (removed after an hour)\n",
                    static_cast<unsigned long long>(f.temporaries), human_bytes(double(f.temporary_bytes)).c_str());
    if (f.bytes > args.cache_size)
        std::printf("over the limit: the next run that keeps a result evicts the least recently used entries\n");
    return exit_ok;
}

/// The files a run wrote, one line each, except that files differing only in their numbers (tiles
/// alps_x0_y0.png ... alps_x3_y3.png, the steps of a .pvd) make one line with their count: a tiled export's
/// hundred files read as one. In the order written, each group where its first file was.
std::vector<std::string> summarise_outputs(const std::vector<fs::path>& outputs) {
    std::vector<std::string> order;
    std::map<std::string, std::vector<std::string>> groups;
    for (const auto& f : outputs) {
        const std::string name = f.string();
        std::string pattern = f.parent_path().string() + "/";  // the name with each run of digits as one '#'
        bool in_number = false;
        for (char c : f.filename().string()) {
            const bool digit = std::isdigit(static_cast<unsigned char>(c)) != 0;
            if (!digit) pattern += c;
            else if (!in_number) pattern += '#';
            in_number = digit;
        }
        auto [it, fresh] = groups.try_emplace(pattern);
        if (fresh) order.push_back(pattern);
        it->second.push_back(name);
    }
    constexpr std::size_t kListed = 3;  // groups up to this size list their files
    std::vector<std::string> lines;
    for (const auto& pattern : order) {
        const auto& files = groups[pattern];
        if (files.size() <= kListed) lines.insert(lines.end(), files.begin(), files.end());
        else
            lines.push_back(files.front() + " ... " + fs::path(files.back()).filename().string() + " (" +
                            std::to_string(files.size()) + " files)");
    }
    return lines;
}

/// The problem with --tiles for this many ranks, or "".
std::string tiles_problem(const Args& args, int ranks) {
    if (!args.tiles) return "";
    const auto [rows, cols] = *args.tiles;
    const long long tiles = (long long)rows * cols;
    if (tiles == ranks) return "";
    if (tiles < ranks)
        return "--tiles " + args.tiles_text + " makes " + std::to_string(tiles) + " tile" + (tiles == 1 ? "" : "s") +
            " for " + std::to_string(ranks) + " ranks (more ranks than tiles): give --tiles with " +
            std::to_string(ranks) + " tiles, or start " + std::to_string(tiles) + " rank" + (tiles == 1 ? "" : "s") +
            " (mpirun -n " + std::to_string(tiles) + ")";
    return "--tiles " + args.tiles_text + " makes " + std::to_string(tiles) + " tiles for " + std::to_string(ranks) +
        " rank" + (ranks == 1 ? "" : "s") + ", and each rank holds one tile: give --tiles with " +
        std::to_string(ranks) + " tiles, or start " + std::to_string(tiles) + " ranks (mpirun -n " +
        std::to_string(tiles) + ")";
}

std::optional<Checked> check_spec_text(const SpecText& spec, const Session& session, const Args& args);

/// Under mpirun every rank checks the same spec and reaches the same verdict, but rank 0 alone says why.
/// A rank that left at once with exit code 2 would make mpirun end the others, rank 0 perhaps before it
/// had written its message (seen under load: the exit code right, the message missing). So the ranks meet
/// here after rank 0 has written it; failed on any rank is failed on all. One collective on every path.
bool failed_on_any_rank(bool failed) { return g_mpi ? g_mpi->failed_on_any(failed) : failed; }

/// Whether this process prints what the ranks agree on: the only one, or rank 0 under mpirun.
bool speaks_for_all() { return !g_mpi || g_mpi->rank() == 0; }

/// The tiled run this process is part of (nullopt: a single process).
std::optional<TiledSettings> tiled_settings(const Args& args) {
    if (!g_mpi) return std::nullopt;
    return TiledSettings{g_mpi->rank(), g_mpi->size(), args.tiles, g_mpi->ranks_on_this_machine()};
}

std::optional<Checked> load_spec(const std::string& path, const Session& session, const Args& args) {
    std::optional<SpecText> text;
    std::string problem;
    try {
        text = SpecText::read(path);
    } catch (const std::exception& e) { problem = e.what(); }
    if (!text) {
        if (speaks_for_all()) std::fprintf(stderr, "orogen: error: %s\n", problem.c_str());
        failed_on_any_rank(true);
        return std::nullopt;
    }
    return check_spec_text(*text, session, args);
}

/// Check `spec`; prints every diagnostic (rank 0 alone under mpirun); nullopt on error.
std::optional<Checked> check_spec_text(const SpecText& spec, const Session& session, const Args& args) {
    CheckSettings settings;
    settings.overrides = args.overrides;
    settings.seed = args.seed;
    settings.out_dir = args.out;
    settings.allow_outside_out = args.allow_outside_out;
    settings.tiled = tiled_settings(args);
    Checked checked = session.check(spec, settings);
    // Under mpirun every rank checks the same plan; rank 0 alone prints.
    if (speaks_for_all()) std::fputs(checked.report().text_with_count().c_str(), stderr);
    if (failed_on_any_rank(!checked.ok())) return std::nullopt;
    return checked;
}

int cmd_check(const Args& args, const Session& session) {
    if (args.positional.size() != 1) return usage_error("check needs one spec file");
    auto checked = load_spec(args.positional[0], session, args);
    if (!checked) return exit_bad_input;
    if (!speaks_for_all()) return exit_ok;
    // The grid's defaults are said, not left to be discovered: no grid line is 513 x 513, no cell= is 1 m.
    const GridSpec grid = checked->grid();
    const std::size_t nodes = checked->nodes().size();
    std::printf("%s: ok (%zu node%s, grid %dx%d%s, cell %g m%s, seed %llu)\n", args.positional[0].c_str(), nodes,
                nodes == 1 ? "" : "s", grid.width, grid.height,
                checked->grid_given() ? "" : " (the default: no grid line)", grid.cell,
                checked->cell_given() ? "" : " (the default: no cell=)",
                static_cast<unsigned long long>(checked->seed()));
    return exit_ok;
}

int run_checked(const Checked& checked, const Args& args, const Session& session, bool summary);

int cmd_run(const Args& args, const Session& session) {
    if (args.positional.size() != 1) return usage_error("run needs one spec file");
    auto checked = load_spec(args.positional[0], session, args);
    if (!checked) return exit_bad_input;
    return run_checked(*checked, args, session, true);
}

/// Run a checked spec: progress, cancellation, the cache as `args` says. With `summary`, prints the files
/// written and the timing table.
int run_checked(const Checked& checked, const Args& args, const Session& session, bool summary) {
    std::signal(SIGINT, on_interrupt);
    std::signal(SIGTERM, on_interrupt);
    const bool speaks = speaks_for_all();  // under mpirun, rank 0 shows progress and the summary
    RunSettings settings;
    settings.out_dir = args.out;
    settings.threads = args.threads;
    settings.progress = stderr;
    settings.quiet = args.quiet || !speaks;
    settings.cancel = &g_cancel;
    settings.cancel_signal = &g_signal;
    settings.on_note = [](const std::string& note) { std::fprintf(stderr, "orogen: %s\n", note.c_str()); };
    settings.cache = cache_settings(args);
    settings.tiled = tiled_settings(args);
    const RunResult result = session.run(checked, settings);
    if (result.exit_code != 0) {
        std::fputs(result.error.c_str(), stderr);
        if (result.exit_code == 130 && g_signal.load() == SIGTERM) return 143;
        return result.exit_code;
    }
    if (!args.quiet && speaks && summary) {
        if (g_mpi) {
            const TileSplit& split = checked.tiles();
            std::printf("tiled run: %d rank%s, the %dx%d grid in %dx%d tiles\n", g_mpi->size(),
                        g_mpi->size() == 1 ? "" : "s", split.grid_width, split.grid_height, split.rows, split.cols);
            for (const CheckedNode& node : checked.nodes())
                if (node.node->tile_halo >= 0 && !node.untiled_reason.empty())
                    std::printf("  '%s' (%s) ran on rank 0 over the whole grid: %s\n", node.label.c_str(),
                                node.node->qualified_name().c_str(), node.untiled_reason.c_str());
        }
        std::printf("wrote %zu file%s to %s:\n", result.outputs.size(), result.outputs.size() == 1 ? "" : "s",
                    args.out.c_str());
        for (const auto& line : summarise_outputs(result.outputs)) std::printf("  %s\n", line.c_str());
        std::printf("\n%s", format_timings(result).c_str());
    }
    return exit_ok;
}

/// `orogen analyze`: the command line becomes a spec (cli/analyze.cpp), run without the cache; the table
/// the analyze:terrain node wrote is printed.
int cmd_analyze(int argc, char** argv, const Session& plugins) {
    cli::AnalyzeArgs a;
    if (const std::string problem = cli::parse_analyze_args(argc, argv, a); !problem.empty())
        return usage_error(problem);
    const cli::ComposedSpec composed = cli::compose_analyze_spec(a);
    if (!composed.problem.empty()) {
        std::fprintf(stderr, "orogen: error: %s\n", composed.problem.c_str());
        return exit_bad_input;
    }
    Args args;
    args.command = "analyze";
    args.out = a.out;
    args.threads = a.threads;
    args.quiet = a.quiet;
    args.no_cache = true;  // the files may change under the same names; measuring is quick
    // The spec's file name only names it in messages: its paths are absolute.
    const auto checked =
        check_spec_text(SpecText::of("orogen-analyze.orogen", composed.text, fs::current_path()), plugins, args);
    if (!checked) {
        std::fprintf(stderr,
                     "(orogen analyze ran the spec above, composed from its command line: a node's cell= is "
                     "--cell, low= and high= are --heights)\n");
        return exit_bad_input;
    }
    const int rc = run_checked(*checked, args, plugins, false);
    if (rc != exit_ok) return rc;
    try {
        const auto table = read_file(fs::path(a.out) / (a.discriminate ? "discriminate.txt" : "analysis.txt"));
        std::fwrite(table.data(), 1, table.size(), stdout);
    } catch (const Error& e) {
        std::fprintf(stderr, "orogen: error: %s\n", e.what());
        return exit_failed;
    }
    if (!a.quiet && a.discriminate)
        std::printf("\nreport: %s, %s\n", (fs::path(a.out) / "discriminate.json").c_str(),
                    (fs::path(a.out) / "discriminate.png").c_str());
    else if (!a.quiet)
        std::printf("\nreport: %s (analysis.json, charts%s)\n", (fs::path(a.out) / "README.md").c_str(),
                    a.render ? ", renders/" : "");
    return exit_ok;
}

int cmd_list(const Args& args, const Session& plugins) {
    if (args.positional.size() > 1) return usage_error("list takes at most one kind");
    const std::string kind = args.positional.empty() ? "" : args.positional[0];
    static const std::vector<std::string> kinds = {"generate", "erode",  "tectonics", "render",
                                                   "export",   "import", "analyze",   "process"};
    if (!kind.empty() && std::find(kinds.begin(), kinds.end(), kind) == kinds.end()) {
        std::string msg = "unknown kind '" + kind +
            "' (kinds: generate, erode, tectonics, render, export, import, analyze; and process)";
        const std::string guess = closest(kind, kinds);
        if (!guess.empty()) msg += "; did you mean '" + guess + "'?";
        std::fprintf(stderr, "orogen: error: %s\n", msg.c_str());
        return exit_bad_input;
    }
    for (const auto* n : plugins.registry().nodes()) {
        if (!kind.empty() && n->kind != kind) continue;
        std::printf("%-26s %s\n", n->qualified_name().c_str(), n->summary.c_str());
    }
    const auto processes = plugins.registry().processes();
    if ((kind.empty() || kind == "process") && !processes.empty()) {
        std::printf("%sprocesses (a loop node's body, one a line: erode:evolve(...) { uplift() flow() ... }):\n",
                    kind.empty() ? "\n" : "");
        for (const auto* p : processes) std::printf("  %-24s %s\n", p->name.c_str(), p->summary.c_str());
    }
    return exit_ok;
}

std::string value_text(const ParamValue& v, const Param& p) {
    std::ostringstream s;
    s.precision(15);
    std::visit(
        [&](const auto& x) {
            using T = std::decay_t<decltype(x)>;
            if constexpr (std::is_same_v<T, std::monostate>) s << "(required)";
            else if constexpr (std::is_same_v<T, bool>) s << (x ? "true" : "false");
            else if constexpr (std::is_same_v<T, std::string>) s << (p.type == ParamType::choice ? x : "\"" + x + "\"");
            else if constexpr (std::is_same_v<T, Point2>) s << "(" << x.x << ", " << x.y << ")";
            else if constexpr (std::is_same_v<T, std::vector<Point2>>) {
                s << "[";
                for (std::size_t i = 0; i < x.size(); ++i)
                    s << (i ? ", " : "") << "(" << x[i].x << ", " << x[i].y << ")";
                s << "]";
            } else s << x;
        },
        v);
    return s.str();
}

void print_params(const std::vector<Param>& params) {
    std::printf("\nparameters:%s\n", params.empty() ? " none" : "");
    for (const auto& p : params) {
        const std::string type = std::string(to_string(p.type));
        std::string range;
        if (p.minimum || p.maximum) {
            range = std::string(p.minimum ? (p.minimum_exclusive ? "(" : "[") : "(") +
                (p.minimum ? value_text(*p.minimum, p) : "-inf") + ", " +
                (p.maximum ? value_text(*p.maximum, p) : "inf") + (p.maximum ? (p.maximum_exclusive ? ")" : "]") : ")");
        }
        std::printf("  %-16s %-12s default %-12s%s%s\n", p.name.c_str(), type.c_str(),
                    value_text(p.default_value, p).c_str(), range.empty() ? "" : ("  range " + range).c_str(),
                    p.unit_text.empty() ? "" : ("  unit " + p.unit_text).c_str());
        if (p.type == ParamType::choice) {
            std::string options;
            for (const auto& c : p.choices) options += (options.empty() ? "" : ", ") + c;
            std::printf("      one of: %s\n", options.c_str());
        }
        if (!p.help_text.empty()) std::printf("      %s\n", p.help_text.c_str());
    }
}

int help_process(const ProcessDescriptor& p, const Session& plugins) {
    std::printf("process %s — %s\n", p.name.c_str(), p.summary.c_str());
    if (!p.description.empty()) std::printf("\n%s\n", p.description.c_str());
    std::printf("\nruns: %s%s\n",
                p.cadence == Cadence::once_per_step ? "once a step (on its first sub-step)" : "every sub-step",
                p.tile_halo >= 0 ? ("; tiles under mpirun (halo " + std::to_string(p.tile_halo) + ")").c_str()
                                 : "; not tiled (a loop with it runs on rank 0 under mpirun)");
    std::printf("fields:\n");
    for (const auto& f : p.fields)
        std::printf("  %-17s %-20s%s%s\n", std::string(to_string(f.access)).c_str(),
                    f.field == kFlowGraph ? "flow (the flow graph)" : f.field.c_str(),
                    f.unit.empty() ? "" : ("  " + f.unit).c_str(), f.help.empty() ? "" : ("  — " + f.help).c_str());
    if (!p.adds_layers.empty()) {
        std::string layers;
        for (const auto& l : p.adds_layers) layers += (layers.empty() ? "" : ", ") + l;
        std::printf("adds layers: %s\n", layers.c_str());
    }
    print_params(p.params);
    std::printf("\nprovided by %s\n", plugins.registry().provider(p.name).c_str());
    return exit_ok;
}

int cmd_help(const Args& args, const Session& plugins) {
    if (args.positional.size() != 1) return usage_error("help needs a node, e.g. `orogen help generate:fault`");
    const std::string& name = args.positional[0];
    const NodeDescriptor* n = plugins.registry().find(name);
    if (!n) {
        const std::string bare = name.rfind("process:", 0) == 0 ? name.substr(8) : name;
        if (const ProcessDescriptor* p = plugins.registry().find_process(bare)) return help_process(*p, plugins);
        std::vector<std::string> names;
        for (const auto* d : plugins.registry().nodes()) {
            names.push_back(d->qualified_name());
            if (d->name == name) n = d;  // `orogen help fault` is fine too
        }
        for (const auto* p : plugins.registry().processes()) names.push_back(p->name);
        if (!n) {
            std::string msg = "unknown node '" + name + "'";
            const std::string guess = closest(name, names);
            msg += guess.empty() ? "; `orogen list` shows them all" : "; did you mean '" + guess + "'?";
            std::fprintf(stderr, "orogen: error: %s\n", msg.c_str());
            return exit_bad_input;
        }
    }
    std::printf("%s — %s\n", n->qualified_name().c_str(), n->summary.c_str());
    if (!n->description.empty()) std::printf("\n%s\n", n->description.c_str());
    std::printf("\ninputs:%s\n", n->inputs.empty() ? " none" : "");
    for (std::size_t i = 0; i < n->inputs.size(); ++i) {
        const auto& in = n->inputs[i];
        const std::string type = in.many == Many::either
            ? describe_type(in.type, false) + " or " + describe_type(in.type, true)
            : describe_type(in.type, in.many == Many::series);
        std::printf("  %zu. %-14s %s%s%s\n", i + 1, in.name.c_str(), type.c_str(),
                    in.need == Need::optional ? ", optional" : "", in.help.empty() ? "" : (" — " + in.help).c_str());
    }
    std::printf("output: %s\n", describe_type(n->output, n->output_series).c_str());
    if (!n->adds_layers.empty()) {
        std::string layers;
        for (const auto& l : n->adds_layers) layers += (layers.empty() ? "" : ", ") + l;
        std::printf("adds layers: %s\n", layers.c_str());
    }
    for (const auto& s : n->side_outputs)
        std::printf("side value: NAME.%s (%s)%s\n", s.name.c_str(), describe_type(s.type, s.series).c_str(),
                    s.help.empty() ? "" : (" — " + s.help).c_str());
    if (n->processes) std::printf("body: processes in braces after the call, one a line (`orogen list process`)\n");
    print_params(n->params);
    std::printf("\nprovided by %s\n", plugins.registry().provider(n->qualified_name()).c_str());
    return exit_ok;
}

int cmd_version(const Session& plugins) {
    std::printf("orogen %s (plugin API %d)\n", OROGEN_VERSION, OROGEN_PLUGIN_API_VERSION);
    std::printf("plugins:\n");
    for (const auto& p : plugins.plugins())
        std::printf("  %-22s %-10s %s\n", p.name.c_str(), p.version.c_str(), p.file.c_str());
    if (plugins.plugins().empty()) std::printf("  (none found)\n");
    std::printf("searched:\n");
    for (const auto& f : plugins.searched()) std::printf("  %s\n", f.string().c_str());
    return exit_ok;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) return usage_error("no command given");
    Args args;
    args.command = argv[1];
    if (args.command == "--help" || args.command == "-h" || (args.command == "help" && argc == 2)) {
        std::fputs(usage_text, stdout);
        return exit_ok;
    }
    if (args.command == "--version") args.command = "version";
    static const std::vector<std::string> commands = {"run", "check", "list", "help", "version", "cache", "analyze"};
    if (std::find(commands.begin(), commands.end(), args.command) == commands.end()) {
        std::string msg = "unknown command '" + args.command + "'";
        const std::string guess = closest(args.command, commands);
        if (!guess.empty()) msg += "; did you mean '" + guess + "'?";
        return usage_error(msg);
    }
    // `orogen run --help`, `orogen analyze -h`: help, whatever else is on the line.
    for (int i = 2; i < argc; ++i)
        if (std::string_view(argv[i]) == "--help" || std::string_view(argv[i]) == "-h") {
            std::fputs(usage_text, stdout);
            return exit_ok;
        }
    if (args.command == "analyze") {  // its own options (--against FILE...): see cli/analyze.cpp
        const Session plugins(self_path(argv[0]));
        print_problems(plugins);
        try {
            return cmd_analyze(argc, argv, plugins);
        } catch (const Error& e) {
            std::fprintf(stderr, "orogen: error: %s\n", e.what());
            return e.kind() == Error::Kind::bad_input ? exit_bad_input : exit_failed;
        } catch (const std::exception& e) {
            std::fprintf(stderr, "orogen: error: %s\n", e.what());
            return exit_failed;
        }
    }
    if (auto rc = parse_args(argc, argv, args)) return *rc;

    // Started by mpirun: MPI for the life of main, one tile per rank.
    std::optional<MpiScope> mpi_scope;
    if (MpiScope::launched_size() > 0 && (args.command == "run" || args.command == "check")) {
        try {
            g_mpi = &mpi_scope.emplace(argc, argv);
        } catch (const Error& e) {
            std::fprintf(stderr, "orogen: error: %s\n", e.what());
            return exit_failed;
        }
        if (const std::string problem = tiles_problem(args, g_mpi->size()); !problem.empty()) {
            if (speaks_for_all()) std::fprintf(stderr, "orogen: error: %s\n", problem.c_str());
            failed_on_any_rank(true);
            return exit_bad_input;
        }
    } else if (args.tiles) {
        return usage_error(
            "--tiles splits a run under mpirun (mpirun -n N orogen run SPEC --tiles RxC); "
            "this orogen was not started by mpirun");
    }

    if (args.command == "cache") {  // no plugins needed
        try {
            return cmd_cache(args);
        } catch (const Error& e) {
            std::fprintf(stderr, "orogen: error: %s\n", e.what());
            return e.kind() == Error::Kind::bad_input ? exit_bad_input : exit_failed;
        }
    }

    const Session plugins(self_path(argv[0]));
    print_problems(plugins);

    try {
        if (args.command == "run") return cmd_run(args, plugins);
        if (args.command == "check") return cmd_check(args, plugins);
        if (args.command == "list") return cmd_list(args, plugins);
        if (args.command == "help") return cmd_help(args, plugins);
        return cmd_version(plugins);
    } catch (const Error& e) {
        std::fprintf(stderr, "orogen: error: %s\n", e.what());
        return e.kind() == Error::Kind::bad_input ? exit_bad_input : exit_failed;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "orogen: error: %s\n", e.what());
        return exit_failed;
    }
}
