#include "runner.hpp"

#include "json.hpp"
#include "outputs.hpp"
#include "tiles.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/random.hpp>

#include <tbb/global_control.h>

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
        : plan_(plan), node_(node), inputs_(std::move(inputs)), options_(options), staging_(staging),
          outside_(outside), seed_(node_seed(plan.seed, node.label)), for_entry_(for_entry) {}

    const std::string& label() const override { return node_.label; }
    std::uint64_t seed() const override { return seed_; }
    const GridSpec& grid() const override { return plan_.grid; }
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
                throw Error("cannot write " + target.string() + ": a folder has that name; move it away or write elsewhere");
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
        if (options_.progress) options_.progress->message(node_.label + ": " + std::string(message));
    }
    void warn(std::string_view message) override {
        if (options_.progress) options_.progress->message(node_.label + ": warning: " + std::string(message));
    }
    Tiling* tiling() override {
        return options_.tiled && !for_entry_ && TiledRun::runs_tiled(node_) ? options_.tiled : nullptr;
    }

private:
    const Plan& plan_;
    const PlannedNode& node_;
    std::vector<Value> inputs_;
    const RunOptions& options_;
    const fs::path& staging_;  ///< the staging folder (in a tiled run, rank 0's: every rank writes into it)
    std::vector<fs::path>& outside_;
    std::uint64_t seed_;
    bool for_entry_;
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
        } catch (const Cancelled&) {
            throw;
        } catch (const Error& e) {
            throw Error("entry " + std::to_string(j) + " of '" + node.label + "' (" + node.node->qualified_name() +
                            ", line " + std::to_string(node.where.line) + "): " + e.what(),
                        e.kind());
        }
    };
    return result;
}

std::string node_error(const PlannedNode& node, const std::string& message) {
    spec::Diagnostic d;
    d.where = node.where;
    d.message = "node '" + node.label + "' (" + node.node->qualified_name() + ") failed: " + message;
    return spec::format(d);
}

/// manifest.json into the staging folder: `staged` are the run's files relative to --out (and to the
/// staging folder), `outside` those written outside --out.
void write_manifest(const Plan& plan, const RunOptions& options, const Staging& staging,
                    const std::vector<fs::path>& staged, const std::vector<fs::path>& outside) {
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
        j.key("name").value(p.name).key("version").value(p.version).key("file").value(fs::path(p.file).filename().string());
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
    for (const auto& f : staged) entry(f, staging.folder() / f);
    for (const auto& f : outside)
        if (std::error_code ec; fs::exists(f, ec)) entry(f, f);
    j.end_array();
    j.end_object();
    const std::string& text = j.str();
    write_file_atomically(staging.folder() / "manifest.json",
                          std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

std::string cancel_reason(const RunOptions& options) {
    const int sig = options.cancel_signal ? options.cancel_signal->load() : 0;
    return sig == SIGTERM ? "stopped by SIGTERM" : "cancelled by the user";
}

/// Collective in a tiled run: every rank learns the worst exit code; only the lowest failing rank keeps its message.
void agree_across_ranks(TiledRun& tiled, RunResult& result) {
    const int mine = result.exit_code;
    int reporter = 0;
    const int worst = tiled.agree(mine, &reporter);
    if (worst != 0 && (mine == 0 || reporter != tiled.rank())) result.error.clear();
    result.exit_code = worst;
}

void cancelled(RunResult& result, std::string message) {
    result.exit_code = 130;
    result.error = std::move(message);
}

}  // namespace

RunResult run(const Plan& plan, const RunOptions& options) {
    RunResult result;
    const auto t0 = std::chrono::steady_clock::now();
    const int threads = options.threads > 0 ? options.threads : int(std::max(1u, std::thread::hardware_concurrency()));
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));

    std::error_code ec;
    fs::create_directories(options.out_dir, ec);
    if (ec || !fs::is_directory(options.out_dir, ec)) {
        result.exit_code = 1;
        result.error = "orogen: error: cannot create the output folder " + options.out_dir.string() + " (" +
                       (ec ? ec.message() : std::string("a file of that name exists")) + "); pick another with --out\n";
    }
    // In a tiled run every rank learns of a failure on any (and only the first failing rank reports it).
    if (options.tiled) agree_across_ranks(*options.tiled, result);
    if (result.exit_code != 0) return result;
    // Debris of earlier runs that were killed, then a staging folder of our own. In a tiled run rank 0
    // cleans up before the other ranks make theirs (it would see their fresh folders as debris).
    const bool rank0 = !options.tiled || options.tiled->rank() == 0;
    if (rank0) result.notes = clean_debris(options.out_dir);
    if (options.tiled) options.tiled->agree(0);
    if (options.on_note)
        for (const auto& note : result.notes) options.on_note(note);
    // A tiled run stages in rank 0's folder alone: every rank writes its files there, and rank 0 moves them
    // into place with its own, the manifest (which lists and hashes them all) last, or removes them all.
    std::optional<Staging> staging;
    fs::path staging_folder;
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
    if (result.exit_code != 0) return result;
    if (options.tiled) {
        std::string folder = staging_folder.string();
        options.tiled->broadcast(folder);
        staging_folder = folder;
    }
    std::vector<fs::path> outside;  // outputs written outside --out (allowed with --allow-outside-out)

    std::map<std::string, Value, std::less<>> values;
    const int total = int(plan.nodes.size());
    for (std::size_t i = 0; i < plan.nodes.size(); ++i) {
        const PlannedNode& node = plan.nodes[i];
        std::vector<Value> inputs;
        for (const auto& key : node.inputs) inputs.push_back(key.empty() ? Value() : values.at(key));
        // Values read for the last time are released now, so a node may modify its input in place.
        for (const auto& key : node.inputs) {
            auto it = plan.last_use.find(key);
            if (!key.empty() && it != plan.last_use.end() && it->second == i) values.erase(key);
        }
        if (options.progress) options.progress->start(int(i) + 1, total, node.label, node.node->qualified_name());
        const auto start = std::chrono::steady_clock::now();
        NodeOutputs out;
        bool runs_here = true;
        bool agreed = false;  // a tiled node found another rank's failure (PeerFailed): already agreed on
        try {
            // A tiled run: tiles for a tiled node, the whole values on rank 0 for the others (collective).
            if (options.tiled) runs_here = options.tiled->prepare_inputs(node, inputs);
            const std::vector<Value> mapped_inputs = node.mapped_input >= 0 ? inputs : std::vector<Value>{};
            Context ctx(plan, node, std::move(inputs), options, staging_folder, outside);
            ctx.check_cancelled();
            if (!runs_here)
                ;  // rank 0 runs it
            else if (node.mapped_input >= 0)  // entries are made when a later node pulls them
                out = NodeOutputs(map_over_series(plan, node, mapped_inputs, std::size_t(node.mapped_input), options,
                                                  staging_folder, outside));
            else
                out = node.node->run(ctx);
        } catch (const Cancelled&) {
            cancelled(result, node_error(node, cancel_reason(options)));
        } catch (const PeerFailed& e) {
            result.exit_code = e.exit_code();
            result.error.clear();  // the rank that failed says why
            agreed = true;
        } catch (const Error& e) {
            result.exit_code = e.kind() == Error::Kind::bad_input ? 2 : 1;
            result.error = node_error(node, e.what());
        } catch (const std::bad_alloc&) {
            result.exit_code = 1;
            result.error = node_error(node, "out of memory; try a smaller grid");
        } catch (const std::exception& e) {
            result.exit_code = 1;
            result.error = node_error(node, e.what());
        } catch (...) {
            result.exit_code = 1;
            result.error = node_error(node, "unknown exception");
        }
        // A tiled run goes on only if every rank finished the node; one rank (the lowest that failed) reports.
        if (options.tiled && !agreed) agree_across_ranks(*options.tiled, result);
        if (result.exit_code != 0) break;
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (options.progress) options.progress->finish(seconds);
        result.timings.push_back({node.label, node.node->qualified_name(), node.where.line, seconds});

        if (options.tiled) options.tiled->produced(node);
        const bool series_out = node.node->output_series || node.mapped_input >= 0;
        const ValueType returned_entry = out.main.type() == ValueType::series ? out.main.series()->element : out.main.type();
        if (runs_here && ((out.main.type() == ValueType::series) != series_out || returned_entry != node.node->output)) {
            result.exit_code = 1;
            result.error = node_error(node, "internal error: it returned a " +
                                                (returned_entry == ValueType::none
                                                     ? std::string("nothing")
                                                     : describe_type(returned_entry, out.main.type() == ValueType::series)) +
                                                " but declares a " + describe_type(node.node->output, series_out));
            break;
        }
        if (!node.value_name.empty()) {
            if (plan.last_use.count(node.value_name)) values[node.value_name] = std::move(out.main);
            for (auto& [side, v] : out.side) {
                const std::string key = node.value_name + "." + side;
                if (plan.last_use.count(key)) values[key] = std::move(v);
            }
        }
    }
    result.total_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (result.exit_code == 0 && options.cancel && options.cancel->load())  // stopped after the last node
        cancelled(result, "orogen: error: " + cancel_reason(options) + " before the outputs were moved into place\n");
    if (result.exit_code == 0 && !rank0) {
        // Another rank of a tiled run: its files are in rank 0's staging folder; rank 0 commits them (and says
        // whether that worked).
        agree_across_ranks(*options.tiled, result);
    } else if (result.exit_code == 0) {
        // All or nothing: the manifest is staged with the rest and moves into place last.
        try {
            const std::vector<fs::path> staged = staging->files();
            write_manifest(plan, options, *staging, staged, outside);
            staging->commit("manifest.json");
            for (const auto& f : staged) result.outputs.push_back(options.out_dir / f);
            for (const auto& f : outside) result.outputs.push_back(f);
            result.outputs.push_back(options.out_dir / "manifest.json");
        } catch (const std::exception& e) {
            result.exit_code = 1;
            result.error = std::string("orogen: error: ") + e.what() + "\n";
        }
        if (options.tiled) agree_across_ranks(*options.tiled, result);
    }
    return result;  // on failure `staging` goes out of scope and takes every staged file with it
}

std::string format_timings(const RunResult& result) {
    std::ostringstream out;
    char line[256];
    std::snprintf(line, sizeof line, "%-16s %-26s %5s %10s %6s\n", "node", "kind:name", "line", "seconds", "share");
    out << line;
    for (const auto& t : result.timings) {
        std::snprintf(line, sizeof line, "%-16s %-26s %5d %10.3f %5.1f%%\n", t.label.c_str(), t.node.c_str(), t.line,
                      t.seconds, result.total_seconds > 0 ? 100.0 * t.seconds / result.total_seconds : 0.0);
        out << line;
    }
    std::snprintf(line, sizeof line, "%-16s %-26s %5s %10.3f\n", "total", "", "", result.total_seconds);
    out << line;
    return out.str();
}

}  // namespace orogen
