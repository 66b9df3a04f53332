// The front door (orogen/session.hpp): the loader, the parser, the checker, the
// tiled rules and the runner behind one object, so that the CLI, the Python
// module and the tests wire parse → check → run in one place.
#include "loader.hpp"
#include "progress.hpp"
#include "runner.hpp"

#include "spec/plan.hpp"
#include "spec/spec.hpp"
#include "tiles/mpi_comm.hpp"
#include "tiles/tiles.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/session.hpp>

#include <algorithm>
#include <cstdlib>
#include <unistd.h>

namespace fs = std::filesystem;

namespace orogen {

// ------------------------------------------------------------ diagnostics

std::string CheckReport::text() const {
    std::string s;
    for (const auto& d : diagnostics) s += d.formatted;
    return s;
}

std::string CheckReport::count_line() const {
    if (errors == 0) return "";
    return std::to_string(errors) + (errors == 1 ? " error" : " errors") + " in " + name + "\n";
}

namespace {

/// The report of `diags`, in source order (each --set after the spec).
CheckReport report_of(const spec::Diagnostics& diags, const std::string& name) {
    CheckReport r;
    r.name = name;
    std::vector<const spec::Diagnostic*> sorted;
    for (const auto& d : diags.all()) sorted.push_back(&d);
    auto rank = [](const spec::Diagnostic& d) {
        return std::make_tuple(d.where.source ? d.where.source->order : -1, d.where.line, d.where.column);
    };
    std::stable_sort(sorted.begin(), sorted.end(), [&](auto* a, auto* b) { return rank(*a) < rank(*b); });
    for (const auto* d : sorted) {
        Diagnostic out;
        out.severity = Diagnostic::Severity(int(d->severity));
        out.file = d->where.source ? d->where.source->name : "";
        out.line = d->where.line;
        out.column = d->where.column;
        out.message = d->message;
        out.formatted = spec::format(*d);
        if (d->severity == spec::Diagnostic::Severity::error) ++r.errors;
        if (d->severity == spec::Diagnostic::Severity::warning) ++r.warnings;
        r.diagnostics.push_back(std::move(out));
    }
    return r;
}

}  // namespace

// ------------------------------------------------------------------ specs

SpecText SpecText::read(const fs::path& path) {
    std::error_code ec;
    if (!fs::exists(path, ec)) throw BadInput("cannot read spec " + path.string() + ": no such file");
    if (fs::is_directory(path, ec))
        throw BadInput("cannot read spec " + path.string() + ": it is a folder; give a .orogen file");
    const auto bytes = read_file(path);
    return SpecText{path.string(), std::string(bytes.begin(), bytes.end()), path};
}

SpecText SpecText::of(std::string name, std::string text, const fs::path& folder) {
    fs::path path = folder / name;
    return SpecText{std::move(name), std::move(text), std::move(path)};
}

struct Checked::Impl {
    Plan plan;
    CheckReport report;
    TileSplit split;
};

Checked::Checked() : impl_(std::make_unique<Impl>()) {}
Checked::~Checked() = default;
Checked::Checked(Checked&&) noexcept = default;
Checked& Checked::operator=(Checked&&) noexcept = default;

bool Checked::ok() const { return impl_->report.errors == 0; }
const CheckReport& Checked::report() const { return impl_->report; }
std::uint64_t Checked::seed() const { return impl_->plan.seed; }
GridSpec Checked::grid() const { return impl_->plan.grid; }
bool Checked::grid_given() const { return impl_->plan.grid_given; }
bool Checked::cell_given() const { return impl_->plan.cell_given; }
bool Checked::writes_files() const { return orogen::writes_files(impl_->plan); }
const TileSplit& Checked::tiles() const { return impl_->split; }

std::vector<CheckedNode> Checked::nodes() const {
    std::vector<CheckedNode> out;
    for (const PlannedNode& n : impl_->plan.nodes)
        out.push_back(CheckedNode{n.label, n.value_name, n.node, n.where.line, &n.params, &n.processes,
                                  node_seed(impl_->plan.seed, n.label), untiled_reason(n)});
    return out;
}

void Checked::keep(const std::string& key) { impl_->plan.last_use[key] = impl_->plan.nodes.size(); }

void Checked::keep_named_values() {
    // A call written where an input goes is not named: its value is released after its reader.
    for (const PlannedNode& n : impl_->plan.nodes) {
        if (n.value_name.empty() || n.in_place) continue;
        keep(n.value_name);
        for (const auto& side : n.node->side_outputs) keep(n.value_name + "." + side.name);
    }
}

std::vector<std::string> Checked::value_keys() const {
    std::vector<std::string> keys;
    for (const PlannedNode& n : impl_->plan.nodes) {
        if (n.value_name.empty() || n.in_place) continue;
        if (n.node->output != ValueType::none || n.node->output_series) keys.push_back(n.value_name);
        for (const auto& side : n.node->side_outputs) keys.push_back(n.value_name + "." + side.name);
    }
    return keys;
}

void Checked::keep_only(const std::vector<std::string>& keys) {
    Plan& plan = impl_->plan;
    // Which node makes each key: its value name (or, in place, its label) and its side values.
    std::map<std::string, std::size_t, std::less<>> maker;
    for (std::size_t i = 0; i < plan.nodes.size(); ++i) {
        const PlannedNode& n = plan.nodes[i];
        if (n.value_name.empty()) continue;
        maker[n.value_name] = i;
        for (const auto& side : n.node->side_outputs) maker[n.value_name + "." + side.name] = i;
    }
    std::vector<bool> needed(plan.nodes.size(), false);
    std::vector<std::size_t> stack;
    for (const auto& key : keys) {
        auto it = maker.find(key);
        if (it == maker.end()) {
            std::string known;
            for (const auto& k : value_keys()) known += (known.empty() ? "" : ", ") + k;
            throw BadInput("the spec makes no value '" + key + "'" +
                           (known.empty() ? std::string(" (it makes none)") : " (it makes " + known + ")"));
        }
        stack.push_back(it->second);
    }
    while (!stack.empty()) {
        const std::size_t i = stack.back();
        stack.pop_back();
        if (needed[i]) continue;
        needed[i] = true;
        for (const auto& in : plan.nodes[i].inputs)
            if (auto it = maker.find(in); !in.empty() && it != maker.end()) stack.push_back(it->second);
    }
    std::vector<PlannedNode> kept;
    for (std::size_t i = 0; i < plan.nodes.size(); ++i)
        if (needed[i]) kept.push_back(std::move(plan.nodes[i]));
    plan.nodes = std::move(kept);
    plan.last_use.clear();  // as the checker makes it, over the nodes that stay
    for (std::size_t i = 0; i < plan.nodes.size(); ++i)
        for (const auto& in : plan.nodes[i].inputs)
            if (!in.empty()) plan.last_use[in] = i;
    for (const auto& key : keys) keep(key);
}

// ---------------------------------------------------------------- session

namespace {

/// The tiles of a tiled run: as given, or as square as the grid allows.
TileSplit split_of(const TiledSettings& t, const GridSpec& grid) {
    const auto [rows, cols] = t.tiles ? *t.tiles : automatic_tiles(t.ranks, grid.width, grid.height);
    return split_grid(grid.width, grid.height, rows, cols);
}

}  // namespace

struct Session::Impl {
    PluginSet plugins;
};

Session::Session(const fs::path& exe) : impl_(std::make_unique<Impl>()) { impl_->plugins.load_all(exe); }
Session::~Session() = default;

const Registry& Session::registry() const { return impl_->plugins.registry(); }
const std::vector<PluginRecord>& Session::plugins() const { return impl_->plugins.plugins(); }
std::vector<std::string> Session::plugin_problems() const { return impl_->plugins.problems(); }
const std::vector<fs::path>& Session::searched() const { return impl_->plugins.searched(); }

Checked Session::check(const SpecText& spec, const CheckSettings& settings) const {
    auto source = std::make_shared<spec::Source>(spec.name, spec.text);
    spec::Diagnostics diags;
    const spec::Spec parsed = spec::parse(source, diags);
    CheckOptions options;
    options.overrides = settings.overrides;
    options.seed = settings.seed;
    options.out_dir = settings.out_dir;
    options.allow_outside_out = settings.allow_outside_out;
    if (settings.bound)
        for (const auto& [name, v] : *settings.bound) options.bound[name] = describe_bound(v);
    if (settings.tiled) {
        // Each heightmap of a tiled node is one tile, and the ranks on this machine share its memory.
        const int ranks = std::max(1, settings.tiled->ranks);
        const int local = std::clamp(
            settings.tiled->ranks_on_this_machine > 0 ? settings.tiled->ranks_on_this_machine : ranks, 1, ranks);
        options.heightmap_memory_limit = heightmap_memory_limit() / std::uint64_t(local) * std::uint64_t(ranks);
        options.tiled_memory_share = double(local) / double(ranks);
    }
    // After a syntax error, what parsed is still checked: every mistake at once (spec::Spec::broken_names).
    Checked out;
    out.impl_->plan = orogen::check(parsed, registry(), spec.path, options, diags);
    out.impl_->split = split_grid(out.impl_->plan.grid.width, out.impl_->plan.grid.height, 1, 1);
    if (settings.tiled && !diags.has_errors()) {
        out.impl_->split = split_of(*settings.tiled, out.impl_->plan.grid);
        TiledCheckOptions tiled;
        tiled.ranks = settings.tiled->ranks;
        tiled.tiles_given = settings.tiled->tiles.has_value();
        tiled.whole_grid_limit = heightmap_memory_limit();
        check_tiled(out.impl_->plan, out.impl_->split, tiled, diags);
    }
    out.impl_->report = report_of(diags, spec.name);
    return out;
}

RunResult Session::run(const Checked& spec, const RunSettings& settings, BoundValues bound) const {
    if (!spec.ok()) throw Error("internal error: Session::run given a spec that did not pass its check");
    const Plan& plan = spec.impl_->plan;
    std::optional<ProgressDisplay> progress;
    if (settings.progress)
        progress.emplace(settings.progress, ::isatty(::fileno(settings.progress)) != 0, settings.quiet);
    std::optional<TiledRun> tiled;
    if (settings.tiled) tiled.emplace(spec.impl_->split, settings.tiled->rank);
    RunOptions options;
    options.out_dir = settings.out_dir;
    options.threads = settings.threads;
    options.progress = progress ? &*progress : nullptr;
    options.plugins = plugins();
    options.cancel = settings.cancel;
    options.cancel_signal = settings.cancel_signal;
    options.on_note = settings.on_note;
    options.on_warning = settings.on_warning;
    // A tiled run keeps no cache: its values are tiles, which the cache's keys do not describe (docs/cache.md).
    options.cache = tiled ? std::nullopt : settings.cache;
    options.tiled = tiled ? &*tiled : nullptr;
    for (const auto* n : registry().nodes()) {  // which plugin (name, version) makes each node: part of its cache key
        const std::string file = registry().provider(n->qualified_name());
        for (const auto& p : options.plugins)
            if (p.file == file) options.node_plugins[n->qualified_name()] = p;
    }
    return orogen::run(plan, options, std::move(bound));
}

// -------------------------------------------------------------------- MPI

struct MpiScope::Impl {
    mpi::Session session;
    Impl(int& argc, char**& argv) : session(argc, argv) {}
};

int MpiScope::launched_size() { return mpi::launched_size(); }

MpiScope::MpiScope(int& argc, char**& argv) : impl_(std::make_unique<Impl>(argc, argv)) {
    rank_ = impl_->session.rank();
    size_ = impl_->session.size();
}
MpiScope::~MpiScope() = default;

bool MpiScope::failed_on_any(bool failed) const {
    std::fflush(stderr);
    int any = failed ? 1 : 0;
    mpi::max_all(&any, 1);
    return any != 0;
}

int MpiScope::ranks_on_this_machine() const {
    const char* local = std::getenv("OMPI_COMM_WORLD_LOCAL_SIZE");
    return std::clamp(local ? std::atoi(local) : size_, 1, size_);
}

std::string closest(std::string_view word, const std::vector<std::string>& candidates) {
    return spec::closest(word, candidates);
}

}  // namespace orogen
