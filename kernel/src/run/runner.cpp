#include "runner.hpp"

#include "hooks/hooks.hpp"
#include "progress.hpp"

#include "io/json.hpp"
#include "io/outputs.hpp"
#include "tiles/tiles.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/random.hpp>

#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <optional>
#include <cstdio>
#include <sstream>
#include <thread>

namespace fs = std::filesystem;

namespace orogen {

std::uint64_t node_seed(std::uint64_t spec_seed, const std::string& label) {
    return random::hash(spec_seed, random::hash_string(label));
}

namespace {

class Context : public NodeContext {
public:
    Context(const Plan& plan, const PlannedNode& node, std::vector<Value> inputs, const RunOptions& options,
            const fs::path& staging, std::vector<fs::path>& outside, bool for_entry = false)
        : plan_(plan), node_(node), inputs_(std::move(inputs)), options_(options), staging_(staging), outside_(outside),
          seed_(node_seed(plan.seed, node.label)), for_entry_(for_entry) {}

    const std::string& label() const override { return node_.label; }
    std::uint64_t seed() const override { return seed_; }
    const GridSpec& grid() const override { return plan_.grid; }
    const std::vector<ProcessCall>& processes() const override { return node_.processes; }
    const ParamValue& param(std::string_view name) const override {
        auto it = node_.params.find(name);
        if (it == node_.params.end())
            throw Error("internal error: " + node_.node->qualified_name() + " read undeclared parameter '" +
                        std::string(name) + "'");
        return it->second;
    }
    std::size_t input_count() const override { return inputs_.size(); }
    const Value& input(std::size_t i) const override {
        static const Value empty;
        return i < inputs_.size() ? inputs_[i] : empty;
    }
    std::shared_ptr<Heightmap> take_heightmap(std::size_t i) override {
        if (i >= inputs_.size() || inputs_[i].type() != ValueType::heightmap)
            throw Error("internal error: input " + std::to_string(i) + " is not a heightmap");
        std::shared_ptr<const Heightmap> hm = inputs_[i].heightmap();
        inputs_[i] = Value();
        if (hm.use_count() == 1) return std::const_pointer_cast<Heightmap>(hm);  // nobody else reads it: no copy
        return std::make_shared<Heightmap>(*hm);
    }
    // Outputs inside --out are staged and move into place with the rest at the end of the run; one the
    // checker allowed outside (--allow-outside-out) is written where it goes, by itself.
    fs::path output_path(const std::string& relative) override {
        if (options_.out_dir.empty())  // writes_files() said no node of the plan writes files
            throw Error("internal error: " + node_.node->qualified_name() + " writes " + relative +
                        " but declares no output path parameter");
        if (for_entry_)
            throw Error("internal error: " + node_.node->qualified_name() +
                        " writes files, so it cannot be mapped over a series");
        const OutputPlace place = place_output(options_.out_dir, relative);
        const fs::path full = place.inside ? staging_ / place.relative : place.resolved;
        std::error_code ec;
        if (place.inside) {  // where it will go must be free: fail now, naming the node, not at the commit
            const fs::path target = options_.out_dir / place.relative;
            fs::path prefix = options_.out_dir;
            for (const auto& part : place.relative.parent_path()) {
                prefix /= part;
                if (fs::exists(prefix, ec) && !fs::is_directory(prefix, ec))
                    throw Error("cannot write " + target.string() + ": " + prefix.string() +
                                " is a file, not a folder; move it away or write elsewhere");
            }
            if (fs::is_directory(target, ec))
                throw Error("cannot write " + target.string() +
                            ": a folder has that name; move it away or write elsewhere");
        }
        fs::create_directories(full.parent_path(), ec);
        if (ec)
            throw Error("cannot write " + (place.inside ? (options_.out_dir / place.relative) : full).string() +
                        ": cannot create folder " + full.parent_path().string() + " (" + ec.message() + ")");
        if (!place.inside) outside_.push_back(full);
        return full;
    }
    fs::path input_path(std::string_view name) const override {
        const fs::path p = std::get<std::string>(param(name));
        return p.is_absolute() ? p : plan_.spec_folder / p;
    }
    void progress(double fraction) override {
        // An entry of a mapped series is made while another node runs: that node's bar speaks.
        if (options_.progress && !for_entry_) options_.progress->update(fraction);
    }
    void check_cancelled() override {
        if (options_.cancel && options_.cancel->load()) throw Cancelled();
    }
    void info(std::string_view message) override {
        say(node_.label + ": " + std::string(message), ProgressDisplay::Kind::info);
    }
    void warn(std::string_view message) override {
        say(node_.label + ": warning: " + std::string(message), ProgressDisplay::Kind::warning);
    }
    /// What the node said, for the cache to replay when its result is reused.
    const std::vector<std::string>& said() const { return said_; }
    Tiling* tiling() override {
        if (!options_.tiled || for_entry_ || !runs_tiled(node_)) return nullptr;
        if (!tiling_) tiling_.emplace(*options_.tiled, node_.node->tile_halo);  // the node's ghost width
        return &*tiling_;
    }

private:
    void say(std::string line, ProgressDisplay::Kind kind) {
        if (options_.progress) options_.progress->message(line, kind);
        if (!for_entry_) said_.push_back(std::move(line));
    }

    const Plan& plan_;
    const PlannedNode& node_;
    std::vector<Value> inputs_;
    std::vector<std::string> said_;
    const RunOptions& options_;
    const fs::path& staging_;  ///< the staging folder (in a tiled run, rank 0's: every rank writes into it)
    std::vector<fs::path>& outside_;
    std::uint64_t seed_;
    bool for_entry_;
    std::optional<NodeTiling> tiling_;  ///< made at the node's first tiling()
};

/// The series a node mapped over input `mapped` of `inputs` yields: entry j
/// runs the node on entry j of that input (other inputs as given), when a
/// consumer asks for it. It runs inside run(), which keeps plan, node and
/// options alive for as long as any node can pull an entry.
std::shared_ptr<Series> map_over_series(const Plan& plan, const PlannedNode& node, std::vector<Value> inputs,
                                        std::size_t mapped, const RunOptions& options, const fs::path& staging,
                                        std::vector<fs::path>& outside) {
    const std::shared_ptr<const Series> source = inputs[mapped].series();
    auto result = std::make_shared<Series>();
    result->element = node.node->output;
    result->times = source->times;
    result->make = [&plan, &node, &options, &staging, &outside, inputs = std::move(inputs), mapped,
                    source](std::size_t j) -> Value {
        std::vector<Value> entry_inputs = inputs;
        entry_inputs[mapped] = source->at(j);
        Context ctx(plan, node, std::move(entry_inputs), options, staging, outside, true);
        try {
            ctx.check_cancelled();
            Value v = node.node->run(ctx).main;
            if (v.type() != node.node->output)
                throw Error("internal error: it returned a " + std::string(to_string(v.type())) + " but declares a " +
                            std::string(to_string(node.node->output)));
            return v;
        } catch (const Cancelled&) { throw; } catch (const Error& e) {
            throw Error("entry " + std::to_string(j) + " of '" + node.label + "' (" + node.node->qualified_name() +
                            ", line " + std::to_string(node.where.line) + "): " + e.what(),
                        e.kind());
        }
    };
    return result;
}

/// manifest.json into the staging folder: `staged` are the run's files relative to --out (and to the
/// staging folder), `outside` those written outside --out.
void write_manifest(const Plan& plan, const RunOptions& options, const Staging& staging,
                    const std::vector<fs::path>& staged, const std::vector<fs::path>& outside,
                    const std::vector<fs::path>& kept = {}) {
    JsonWriter j;
    j.begin_object();
    j.key("orogen").value(OROGEN_VERSION);
    j.key("plugin_api").value(OROGEN_PLUGIN_API_VERSION);
    j.key("spec").begin_object();
    j.key("path").value(plan.spec_path.string());
    j.key("sha256").value(sha256_hex(std::span<const std::uint8_t>(
        reinterpret_cast<const std::uint8_t*>(plan.source->text.data()), plan.source->text.size())));
    j.key("text").value(plan.source->text);
    j.end_object();
    j.key("seed").value(plan.seed);
    j.key("grid").begin_object();
    j.key("width").value(plan.grid.width).key("height").value(plan.grid.height).key("cell").value(plan.grid.cell);
    j.end_object();
    j.key("overrides").begin_array();
    for (const auto& o : plan.overrides) j.value(o);
    j.end_array();
    j.key("plugins").begin_array();
    for (const auto& p : options.plugins) {
        j.begin_object();
        j.key("name").value(p.name).key("version").value(p.version).key("file").value(
            fs::path(p.file).filename().string());
        j.end_object();
    }
    j.end_array();
    j.key("nodes").begin_array();
    for (const auto& n : plan.nodes) {
        j.begin_object();
        j.key("label").value(n.label).key("node").value(n.node->qualified_name()).key("line").value(n.where.line);
        j.key("seed").value(node_seed(plan.seed, n.label));
        j.end_object();
    }
    j.end_array();
    j.key("outputs").begin_array();
    auto entry = [&](const fs::path& shown, const fs::path& file) {
        std::error_code ec;
        j.begin_object();
        j.key("path").value(shown.string());
        j.key("bytes").value(std::uint64_t(fs::file_size(file, ec)));
        j.key("sha256").value(sha256_file(file));
        j.end_object();
    };
    // In one sorted list with the files a cached export found already in place (kept), so the manifest
    // is the same bytes whichever way a file got there.
    std::vector<std::pair<fs::path, fs::path>> listed;
    for (const auto& f : staged) listed.emplace_back(f, staging.folder() / f);
    for (const auto& f : kept) listed.emplace_back(f, options.out_dir / f);
    std::sort(listed.begin(), listed.end());
    for (const auto& [shown, file] : listed) entry(shown, file);
    for (const auto& f : outside)
        if (std::error_code ec; fs::exists(f, ec)) entry(f, f);
    j.end_array();
    j.end_object();
    const std::string& text = j.str();
    write_file_atomically(
        staging.folder() / "manifest.json",
        std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

std::string cancel_reason(const RunOptions& options) {
    const int sig = options.cancel_signal ? options.cancel_signal->load() : 0;
    return sig == SIGTERM ? "stopped by SIGTERM" : "cancelled by the user";
}

void cancelled(RunResult& result, std::string message) {
    result.exit_code = 130;
    result.error = std::move(message);
}

/// The worst exit code of all ranks on every rank (only the lowest failing rank keeps its message).
void agree_across_ranks(TiledRun& tiled, RunResult& result) {
    agree_across_ranks(tiled, result.exit_code, result.error);
}

/// How node `node` stopped, from the exception in flight (called inside a catch).
Outcome outcome_of_exception(const PlannedNode& node, const RunOptions& options) {
    Outcome outcome;
    outcome.exit_code = 1;
    try {
        throw;
    } catch (const Cancelled&) {
        outcome.exit_code = 130;
        outcome.error = node_error(node, cancel_reason(options));
    } catch (const PeerFailed& e) {
        outcome.exit_code = e.exit_code();  // the rank that failed says why
        outcome.agreed = true;
    } catch (const Error& e) {
        outcome.exit_code = e.kind() == Error::Kind::bad_input ? 2 : 1;
        outcome.error = node_error(node, e.what());
    } catch (const std::bad_alloc&) {
        outcome.error = node_error(node, "out of memory; try a smaller grid");
    } catch (const std::exception& e) { outcome.error = node_error(node, e.what()); } catch (...) {
        outcome.error = node_error(node, "unknown exception");
    }
    return outcome;
}

/// "internal error: ..." if node returned a value other than the one it declares, else "".
std::string wrong_output(const PlannedNode& node, const NodeOutputs& out) {
    const bool series_out = node.node->output_series || node.mapped_input >= 0;
    const ValueType returned_entry =
        out.main.type() == ValueType::series ? out.main.series()->element : out.main.type();
    if ((out.main.type() == ValueType::series) == series_out && returned_entry == node.node->output) return "";
    return "internal error: it returned a " +
        (returned_entry == ValueType::none ? std::string("nothing")
                                           : describe_type(returned_entry, out.main.type() == ValueType::series)) +
        " but declares a " + describe_type(node.node->output, series_out);
}

/// Runs a plan's nodes in spec order. Evaluation is by demand: a node runs at its turn unless a hook says it
/// need not (the node cache: its files are put back now, its values wait for a reader), and a node that
/// runs pulls the values it reads: at hand, supplied by a hook (read from a cache entry), or made by
/// running their node then. Everything else around a node (cache keys and saves, progress and timing, a
/// tiled run's agreement) is a hook (hooks.hpp).
class Evaluation {
public:
    Evaluation(RunShared& shared, std::vector<std::unique_ptr<NodeHooks>> hooks, BoundValues bound)
        : shared_(shared), plan_(shared.plan), options_(shared.options), hooks_(std::move(hooks)) {
        for (std::size_t j = 0; j < plan_.nodes.size(); ++j) {
            const PlannedNode& n = plan_.nodes[j];
            if (n.value_name.empty()) continue;
            producer_[n.value_name] = {j, ""};
            for (const auto& side : n.node->side_outputs) producer_[n.value_name + "." + side.name] = {j, side.name};
        }
        // The caller's values are at hand from the start, held here alone, until their last reader.
        for (auto& [name, v] : bound) {
            for (auto& h : hooks_) h->bound(name, v);
            keep(name, std::move(v));
        }
    }

    /// Throws NodeFailed.
    void run_all() {
        for (std::size_t i = 0; i < plan_.nodes.size(); ++i) {
            current_ = i;
            const PlannedNode& node = plan_.nodes[i];
            rows_.push_back(shared_.result.timings.size());
            shared_.result.timings.push_back(
                {node.label, node.node->qualified_name(), node.where.line, 0.0, false, false});
            const NodeTurn turn = this->turn(i);
            TurnAnswer answer;
            for (auto& h : hooks_) {
                answer = h->at_turn(turn);
                if (answer.kind != TurnAnswer::Kind::run) break;
            }
            if (answer.kind == TurnAnswer::Kind::run) {
                execute(i);
                continue;
            }
            turn.timing.cached = true;
            if (answer.kind == TurnAnswer::Kind::reused) {
                keep_values(node, std::move(answer.reuse.values));
                for (auto& h : hooks_) h->skipped(turn, answer.reuse);
            }
            release_inputs(i);
        }
    }

    void run_finished() {
        for (auto& h : hooks_) h->run_finished();
    }
    /// The values still held once every node ran (see RunResult::values).
    std::map<std::string, Value, std::less<>> take_values() { return std::move(values_); }

private:
    NodeTurn turn(std::size_t j) { return NodeTurn{j, plan_.nodes[j], shared_.result.timings[rows_[j]]}; }

    /// Values read for the last time by node i are dropped (so a node that runs may modify its input in place).
    void release_inputs(std::size_t i) {
        for (const auto& key : plan_.nodes[i].inputs) {
            auto it = plan_.last_use.find(key);
            if (!key.empty() && it != plan_.last_use.end() && it->second == i) values_.erase(key);
        }
    }

    /// Keep value `key` if a node from the current one on reads it.
    void keep(const std::string& key, Value v) {
        const auto it = plan_.last_use.find(key);
        if (it != plan_.last_use.end() && it->second >= current_) values_[key] = std::move(v);
    }

    static std::string value_key(const PlannedNode& node, const std::string& output) {
        return output.empty() ? node.value_name : node.value_name + "." + output;
    }

    void keep_values(const PlannedNode& node, std::vector<std::pair<std::string, Value>> values) {
        for (auto& [name, v] : values) keep(value_key(node, name), std::move(v));
    }

    /// Value `key` for the current node: at hand, supplied by a hook for node j, or made by running node j.
    Value ensure(const std::string& key) {
        if (auto it = values_.find(key); it != values_.end()) return it->second;
        const auto [j, output] = producer_.at(key);
        const PlannedNode& node = plan_.nodes[j];
        const NodeTurn turn = this->turn(j);
        for (auto& h : hooks_) {
            std::optional<Reuse> supplied = h->supply(turn);
            if (!supplied) continue;
            Value wanted;
            for (auto& [name, v] : supplied->values) {
                const std::string k = value_key(node, name);
                if (k == key) wanted = v;
                keep(k, std::move(v));
            }
            if (wanted) return wanted;
        }
        NodeOutputs out = execute(j);
        Value wanted = output.empty() ? out.main : out.side[output];
        if (!wanted) throw NodeFailed{1, node_error(node, "internal error: it did not make its value '" + key + "'")};
        return wanted;
    }

    /// Run node j (its inputs made or read first) between the hooks, and keep its values.
    NodeOutputs execute(std::size_t j) {
        const PlannedNode& node = plan_.nodes[j];
        std::vector<Value> inputs;
        for (const auto& key : node.inputs) inputs.push_back(key.empty() ? Value() : ensure(key));
        if (j == current_) release_inputs(j);
        const NodeTurn turn = this->turn(j);
        NodeOutputs out;
        std::optional<Context> ctx;
        Outcome outcome;
        bool runs_here = true;  // false on ranks other than 0 for a node that is not tiled
        try {
            for (auto& h : hooks_) runs_here = h->before_node(turn, inputs) && runs_here;
            const std::vector<Value> mapped_inputs = node.mapped_input >= 0 ? inputs : std::vector<Value>{};
            ctx.emplace(plan_, node, std::move(inputs), options_, shared_.staging_folder, shared_.outside);
            ctx->check_cancelled();
            if (!runs_here)
                ;  // rank 0 runs it
            else if (node.mapped_input >= 0)  // entries are made when a later node pulls them
                out = NodeOutputs(map_over_series(plan_, node, mapped_inputs, std::size_t(node.mapped_input), options_,
                                                  shared_.staging_folder, shared_.outside));
            else out = node.node->run(*ctx);
        } catch (...) { outcome = outcome_of_exception(node, options_); }
        for (auto& h : hooks_) h->settle(turn, outcome);
        if (outcome.exit_code != 0) throw NodeFailed{outcome.exit_code, outcome.error};
        for (auto& h : hooks_) h->after_node(turn);
        turn.timing.cached = turn.timing.read = false;
        if (runs_here)
            if (const std::string wrong = wrong_output(node, out); !wrong.empty())
                throw NodeFailed{1, node_error(node, wrong)};
        if (!node.value_name.empty()) {
            keep(node.value_name, out.main);
            for (const auto& [side, v] : out.side) keep(node.value_name + "." + side, v);
        }
        for (auto& h : hooks_) h->on_result(turn, out, ctx->said());
        return out;
    }

    RunShared& shared_;
    const Plan& plan_;
    const RunOptions& options_;
    std::vector<std::unique_ptr<NodeHooks>> hooks_;
    std::vector<std::size_t> rows_;  ///< node → its row in result.timings (nodes are added in spec order)
    std::size_t current_ = 0;
    std::map<std::string, Value, std::less<>> values_;
    std::map<std::string, std::pair<std::size_t, std::string>, std::less<>> producer_;  ///< value key → node, output
};
}  // namespace

std::string node_error(const PlannedNode& node, const std::string& message) {
    spec::Diagnostic d;
    d.where = node.where;
    d.message = "node '" + node.label + "' (" + node.node->qualified_name() + ") failed: " + message;
    return spec::format(d);
}

void RunShared::warn(const std::string& line) const {
    if (options.on_warning) options.on_warning(line);
    else if (options.progress) options.progress->message(line, ProgressDisplay::Kind::warning);
}

namespace {

/// The output folder made, debris of killed runs removed and a staging folder of this run's made; false
/// (result's exit code and error set) if that failed. In a tiled run rank 0 cleans up before the other
/// ranks make theirs (it would see their fresh folders as debris), and every rank stages in rank 0's folder:
/// every rank writes its files there, and rank 0 moves them into place with its own, the manifest (which
/// lists and hashes them all) last, or removes them all.
bool prepare_outputs(const RunOptions& options, RunResult& result, std::optional<Staging>& staging,
                     fs::path& staging_folder) {
    std::error_code ec;
    fs::create_directories(options.out_dir, ec);
    if (ec || !fs::is_directory(options.out_dir, ec)) {
        result.exit_code = 1;
        result.error = "orogen: error: cannot create the output folder " + options.out_dir.string() + " (" +
            (ec ? ec.message() : std::string("a file of that name exists")) + "); pick another with --out\n";
    }
    // In a tiled run every rank learns of a failure on any (and only the first failing rank reports it).
    if (options.tiled) agree_across_ranks(*options.tiled, result);
    if (result.exit_code != 0) return false;
    const bool rank0 = !options.tiled || options.tiled->rank() == 0;
    if (rank0) result.notes = clean_debris(options.out_dir);
    if (options.tiled) options.tiled->agree(0);
    if (options.on_note)
        for (const auto& note : result.notes) options.on_note(note);
    try {
        if (rank0) {
            staging.emplace(options.out_dir);
            staging_folder = staging->folder();
        }
    } catch (const Error& e) {
        result.exit_code = 1;
        result.error = std::string("orogen: error: ") + e.what() + "\n";
    }
    if (options.tiled) agree_across_ranks(*options.tiled, result);
    if (result.exit_code != 0) return false;
    if (options.tiled) {
        std::string folder = staging_folder.string();
        options.tiled->broadcast(folder);
        staging_folder = folder;
    }
    return true;
}

/// All or nothing: the staged files, then the manifest (staged with the rest), moved into place; listed in
/// result.outputs. A failure sets result's exit code and error.
void commit_outputs(const RunShared& shared, Staging& staging) {
    const Plan& plan = shared.plan;
    const RunOptions& options = shared.options;
    RunResult& result = shared.result;
    try {
        const std::vector<fs::path> staged = staging.files();
        write_manifest(plan, options, staging, staged, shared.outside, shared.kept);
        staging.commit("manifest.json");
        std::vector<fs::path> all = staged;
        all.insert(all.end(), shared.kept.begin(), shared.kept.end());
        std::sort(all.begin(), all.end());
        for (const auto& f : all) result.outputs.push_back(options.out_dir / f);
        for (const auto& f : shared.outside) result.outputs.push_back(f);
        result.outputs.push_back(options.out_dir / "manifest.json");
    } catch (const std::exception& e) {
        result.exit_code = 1;
        result.error = std::string("orogen: error: ") + e.what() + "\n";
    }
}

}  // namespace

ValueInfo describe_bound(const Value& value) {
    ValueInfo info;
    info.type = value.type();
    if (value.type() == ValueType::heightmap) {
        const Heightmap& hm = *value.heightmap();
        info.width = hm.width();
        info.height = hm.height();
        info.cell = hm.cell();
        for (auto& name : hm.layer_names()) info.layers.insert(std::move(name));
    } else if (value.type() == ValueType::image) {
        info.width = value.image()->width;
        info.height = value.image()->height;
    } else if (value.type() == ValueType::series) {
        info.element = value.series()->element;
        info.count = value.series()->size();
        info.empty = info.count == 0;
    }
    return info;
}

bool writes_files(const Plan& plan) {
    for (const PlannedNode& n : plan.nodes)
        for (const Param& p : n.node->params)
            if (p.type == ParamType::path && p.path_role == PathRole::output) return true;
    return false;
}

RunResult run(const Plan& plan, const RunOptions& options, BoundValues bound) {
    RunResult result;
    const auto t0 = std::chrono::steady_clock::now();
    const int threads = options.threads > 0 ? options.threads : int(std::max(1u, std::thread::hardware_concurrency()));
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));

    const bool writes = !options.out_dir.empty();  // else no folder, no staging, no manifest (RunOptions::out_dir)
    const bool rank0 = !options.tiled || options.tiled->rank() == 0;
    std::optional<Staging> staging;
    fs::path staging_folder;
    if (writes && !prepare_outputs(options, result, staging, staging_folder)) return result;
    std::vector<fs::path> outside;  // outputs written outside --out (allowed with --allow-outside-out)

    RunShared shared{plan, options, staging ? &*staging : nullptr, staging_folder, outside, result, {}};
    std::vector<std::unique_ptr<NodeHooks>> hooks;  // in the order they are called at each point
    for (auto make : {cache_hooks, progress_hooks, tiled_hooks})
        if (auto h = make(shared)) hooks.push_back(std::move(h));
    Evaluation evaluation(shared, std::move(hooks), std::move(bound));
    try {
        evaluation.run_all();
    } catch (const NodeFailed& f) {
        result.exit_code = f.exit_code;
        result.error = f.message;
    }
    if (result.exit_code == 0) result.values = evaluation.take_values();
    evaluation.run_finished();
    result.total_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (result.exit_code == 0 && options.cancel && options.cancel->load())  // stopped after the last node
        cancelled(result, "orogen: error: " + cancel_reason(options) + " before the outputs were moved into place\n");
    if (result.exit_code == 0 && writes && !rank0) {
        // Another rank of a tiled run: its files are in rank 0's staging folder; rank 0 commits them (and says
        // whether that worked).
        agree_across_ranks(*options.tiled, result);
    } else if (result.exit_code == 0 && writes) {
        commit_outputs(shared, *staging);
        if (options.tiled) agree_across_ranks(*options.tiled, result);
    }
    return result;  // on failure `staging` goes out of scope and takes every staged file with it
}

std::string format_timings(const RunResult& result) {
    // Columns as wide as their longest entry (at least the usual 16 and 26), so a long label or
    // kind:name (a mapped node's "frames[12]", a plugin's long name) does not push its row askew.
    std::size_t label_w = 16, node_w = 26;
    for (const auto& t : result.timings)
        label_w = std::max(label_w, t.label.size()), node_w = std::max(node_w, t.node.size());
    const int lw = int(label_w), nw = int(node_w);
    std::ostringstream out;
    std::vector<char> line(label_w + node_w + 64);
    std::snprintf(line.data(), line.size(), "%-*s %-*s %5s %10s %6s\n", lw, "node", nw, "kind:name", "line", "seconds",
                  "share");
    out << line.data();
    for (const auto& t : result.timings) {
        std::snprintf(line.data(), line.size(), "%-*s %-*s %5d %10.3f %5.1f%%%s\n", lw, t.label.c_str(), nw,
                      t.node.c_str(), t.line, t.seconds,
                      result.total_seconds > 0 ? 100.0 * t.seconds / result.total_seconds : 0.0,
                      t.cached ? (t.read ? "  cached, read" : "  cached") : "");
        out << line.data();
    }
    std::snprintf(line.data(), line.size(), "%-*s %-*s %5s %10.3f\n", lw, "total", nw, "", "", result.total_seconds);
    out << line.data();
    if (!result.cache_summary.empty()) out << result.cache_summary << "\n";
    return out.str();
}

}  // namespace orogen
