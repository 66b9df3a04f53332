#include "runner.hpp"

#include "io/digest.hpp"
#include "io/json.hpp"
#include "io/outputs.hpp"
#include "tiles/tiles.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/random.hpp>

#include <tbb/global_control.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>
#include <fcntl.h>
#include <unistd.h>
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
    void info(std::string_view message) override { say(node_.label + ": " + std::string(message), ProgressDisplay::Kind::info); }
    void warn(std::string_view message) override {
        say(node_.label + ": warning: " + std::string(message), ProgressDisplay::Kind::warning);
    }
    /// What the node said, for the cache to replay when its result is reused.
    const std::vector<std::string>& said() const { return said_; }
    Tiling* tiling() override {
        return options_.tiled && !for_entry_ && TiledRun::runs_tiled(node_) ? options_.tiled : nullptr;
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
    write_file_atomically(staging.folder() / "manifest.json",
                          std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

std::string cancel_reason(const RunOptions& options) {
    const int sig = options.cancel_signal ? options.cancel_signal->load() : 0;
    return sig == SIGTERM ? "stopped by SIGTERM" : "cancelled by the user";
}

/// Collective in a tiled run, after the last node: the digests the other ranks took while writing their files
/// into the staging folder go to rank 0, which adopts those whose file it sees unchanged, so the manifest
/// does not read them again (a world's engine tiles can be gigabytes). Every rank calls it, failed or not.
void share_digests(TiledRun& tiled, const fs::path& staging_folder, bool ok) {
    std::string mine;  // records of three fields, each ended by '\0': path in the folder, digest, identity
    if (ok && tiled.rank() != 0) {
        std::error_code ec;
        for (auto it = fs::recursive_directory_iterator(staging_folder, ec); !ec && it != fs::recursive_directory_iterator();
             it.increment(ec)) {
            if (!it->is_regular_file(ec)) continue;
            const std::string hex = detail::remembered_sha256(it->path());  // "" for files this rank did not write
            if (hex.empty()) continue;
            for (const std::string& field :
                 {fs::relative(it->path(), staging_folder, ec).string(), hex, detail::file_identity(it->path())})
                mine.append(field).push_back('\0');
        }
    }
    const std::vector<std::string> all = tiled.gather_text(mine);
    for (const std::string& text : all) {
        std::vector<std::string> fields;
        for (std::size_t at = 0; at < text.size();) {
            const std::size_t end = text.find('\0', at);
            if (end == std::string::npos) break;
            fields.push_back(text.substr(at, end - at));
            at = end + 1;
        }
        for (std::size_t k = 0; k + 2 < fields.size(); k += 3)
            detail::adopt_sha256(staging_folder / fields[k], fields[k + 1], fields[k + 2]);
    }
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


/// A node failed; the message is formatted (node_error), on its way out of nested evaluation.
struct NodeFailed {
    int exit_code;
    std::string message;
};

/// Runs a plan's nodes in spec order, with the node cache (docs/cache.md) when there is one: a node whose
/// key has an entry does not run; its values are read from the entry only when a node that does run needs
/// them (so a cached upstream is never read when everything downstream is cached too), and the files it
/// wrote are put back into the staging folder at its turn. A damaged entry is recomputed: evaluation is by
/// demand, so a node runs whenever a value it makes is needed and not at hand.
class Evaluation {
public:
    /// `staging`: this process's staging folder, or nullptr on a rank of a tiled run other than 0, which
    /// writes into rank 0's (`staging_folder`) and keeps no cache.
    Evaluation(const Plan& plan, const RunOptions& options, const Staging* staging, fs::path staging_folder,
               std::vector<fs::path>& outside, RunResult& result)
        : plan_(plan), options_(options), staging_(staging), staging_folder_(std::move(staging_folder)),
          outside_(outside), result_(result), states_(plan.nodes.size()) {
        for (std::size_t j = 0; j < plan.nodes.size(); ++j) {
            const PlannedNode& n = plan.nodes[j];
            if (n.value_name.empty()) continue;
            producer_[n.value_name] = {j, ""};
            for (const auto& side : n.node->side_outputs) producer_[n.value_name + "." + side.name] = {j, side.name};
        }
        if (options.cache && staging_ && !options.tiled) {
            store_.emplace(*options.cache, [this](const std::string& line) { warn(line); });
            if (!store_->usable()) store_.reset();
        }
    }

    /// Throws NodeFailed.
    void run_all() {
        for (std::size_t i = 0; i < plan_.nodes.size(); ++i) {
            current_ = i;
            const PlannedNode& node = plan_.nodes[i];
            State& s = states_[i];
            s.row = result_.timings.size();
            result_.timings.push_back({node.label, node.node->qualified_name(), node.where.line, 0.0, false, false});
            compute_key(i);
            if (s.key && !s.rerun) {
                if (const auto info = store_->probe(*s.key, node.label)) {
                    // Files and messages are this node's effects: they are put back now. Values wait for a reader.
                    // A node whose large files are recorded, not kept, runs again if they are not in --out.
                    if (info->files == 0) {
                        mark_cached(i, "cached", info->texts);
                    } else if (restore(i)) {
                        mark_cached(i, "cached (files restored)", info->texts);
                    }
                } else if (node.output_files.empty() && (node.node->output_series || node.mapped_input >= 0)) {
                    // A series is made on demand and never kept: make it only if a node that runs reads it.
                    s.status = Status::deferred;
                    result_.timings[s.row].cached = true;
                }
            }
            if (s.status == Status::pending) execute(i);
            else release_inputs(i);
        }
    }

    int reused() const {
        int n = 0;
        for (const auto& t : result_.timings) n += t.cached ? 1 : 0;
        return n;
    }
    const std::optional<cache::Store>& store() const { return store_; }
    /// The values still held once every node ran (see RunResult::values).
    std::map<std::string, Value, std::less<>> take_values() { return std::move(values_); }
    /// Files of cached exports that were already in --out with the same bytes (relative to --out).
    const std::vector<fs::path>& kept() const { return kept_; }

private:
    enum class Status { pending, ran, cached, deferred };
    struct State {
        std::optional<cache::Digest> key;  ///< nullopt: not cached (no cache, a series' producer unknown...)
        bool rerun = false;                ///< always runs; its outputs are keyed by their contents
        Status status = Status::pending;
        std::size_t row = 0;  ///< in result_.timings
    };

    void warn(const std::string& line) {
        if (options_.on_warning) options_.on_warning(line);
        else if (options_.progress) options_.progress->message(line, ProgressDisplay::Kind::warning);
    }

    void compute_key(std::size_t i) {
        const PlannedNode& node = plan_.nodes[i];
        State& s = states_[i];
        s.rerun = node.node->cache == CachePolicy::rerun;
        for (const auto& p : node.node->params)
            if (p.type == ParamType::path && p.path_role == PathRole::input) s.rerun = true;
        if (!store_) return;
        const auto plugin = options_.node_plugins.find(node.node->qualified_name());
        if (plugin == options_.node_plugins.end() || plugin->second.identity.empty()) return;
        std::vector<std::optional<cache::Digest>> inputs;
        for (const auto& k : node.inputs) {
            if (k.empty()) {
                inputs.emplace_back();
                continue;
            }
            const auto it = value_keys_.find(k);
            if (it == value_keys_.end() || !it->second) return;  // made by a node whose result has no key
            inputs.push_back(it->second);
        }
        s.key = cache::node_key(plan_, node, inputs, plugin->second.name, plugin->second.version, plugin->second.identity,
                                node_seed(plan_.seed, node.label));
        if (s.rerun || node.value_name.empty()) return;
        value_keys_[node.value_name] = cache::output_key(*s.key, "");
        for (const auto& side : node.node->side_outputs)
            value_keys_[node.value_name + "." + side.name] = cache::output_key(*s.key, side.name);
    }

    void mark_cached(std::size_t i, const std::string& why, const std::vector<std::string>& said) {
        const PlannedNode& node = plan_.nodes[i];
        if (options_.progress)
            for (const auto& line : said)  // replayed as the node said them: "label: ..." or "label: warning: ..."
                options_.progress->message(line, line.find(": warning: ") != std::string::npos
                                                     ? ProgressDisplay::Kind::warning
                                                     : ProgressDisplay::Kind::info);
        states_[i].status = Status::cached;
        result_.timings[states_[i].row].cached = true;
        if (options_.progress)
            options_.progress->skipped(int(i) + 1, int(plan_.nodes.size()), node.label, node.node->qualified_name(), why);
        release_inputs(i);
    }

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

    /// Put node j's files back into the staging folder and its values at hand; false if its entry failed, or
    /// if a file it recorded (too large to keep, docs/cache.md) is not in --out with its bytes: it runs again.
    bool restore(std::size_t j) {
        const PlannedNode& node = plan_.nodes[j];
        const auto t0 = std::chrono::steady_clock::now();
        auto contents = store_->load(*states_[j].key, node.label);
        if (!contents) return false;
        try {
            // Recorded files first: if one is missing or differs, nothing is staged and the node runs.
            std::vector<fs::path> recorded_in_place;
            for (const auto& f : contents->recorded) {
                if (!recorded_in_place_at(fs::path(f.path), f.bytes, f.sha256)) {
                    result_.timings[states_[j].row].seconds += seconds_since(t0);
                    return false;
                }
                recorded_in_place.emplace_back(f.path);
            }
            kept_.insert(kept_.end(), recorded_in_place.begin(), recorded_in_place.end());
            int written = 0;
            for (const auto& [relative, bytes] : contents->files) {
                const fs::path rel(relative);
                if (rel.empty() || rel.is_absolute() || std::any_of(rel.begin(), rel.end(), [](const fs::path& p) { return p == ".."; }))
                    throw Error("a cached file has a bad path: " + relative);
                if (already_in_place(rel, bytes)) {  // nothing to stage or move: it is listed as it is
                    kept_.push_back(rel);
                    continue;
                }
                const fs::path full = staging_folder_ / rel;
                fs::create_directories(full.parent_path());
                write_plain(full, bytes);
                ++written;
            }
            // One flush for all of them (an fsync each costs ~8 ms: 123 files of plates/ took a second).
            const int fd = written ? ::open(staging_folder_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC) : -1;
            if (fd >= 0) {
                ::syncfs(fd);
                ::close(fd);
            }
        } catch (const std::exception& e) {
            throw NodeFailed{1, node_error(node, std::string("cannot put back its cached files: ") + e.what())};
        }
        for (auto& [name, v] : contents->values) keep(name.empty() ? node.value_name : node.value_name + "." + name, std::move(v));
        result_.timings[states_[j].row].seconds += seconds_since(t0);
        return true;
    }

    /// True if `--out/rel` is a regular file inside --out of `size` bytes whose SHA-256 is `sha256` (a file
    /// recorded by its digest). The digest is remembered, so the manifest does not read the file again.
    bool recorded_in_place_at(const fs::path& rel, std::uint64_t size, const std::string& sha256) const {
        const OutputPlace place = place_output(options_.out_dir, rel.string());
        if (!place.inside) return false;
        const fs::path target = options_.out_dir / place.relative;
        std::error_code ec;
        if (!fs::is_regular_file(fs::symlink_status(target, ec)) || fs::file_size(target, ec) != size || ec) return false;
        std::string hex = detail::remembered_sha256(target);
        if (hex.empty()) {
            hex = sha256_file(target);
            detail::remember_sha256(target, hex);
        }
        return hex == sha256;
    }

    /// True if `--out/rel` is a regular file inside --out holding exactly `bytes` (a re-run whose export
    /// is cached: its file is left alone rather than staged and renamed over itself).
    bool already_in_place(const fs::path& rel, std::span<const std::uint8_t> bytes) const {
        const OutputPlace place = place_output(options_.out_dir, rel.string());
        if (!place.inside) return false;
        const fs::path target = options_.out_dir / place.relative;
        std::error_code ec;
        if (!fs::is_regular_file(fs::symlink_status(target, ec)) || fs::file_size(target, ec) != bytes.size() || ec)
            return false;
        std::ifstream in(target, std::ios::binary);
        std::vector<char> buf(std::size_t(1) << 20);
        std::size_t at = 0;
        while (at < bytes.size()) {
            const std::size_t n = std::min(buf.size(), bytes.size() - at);
            if (!in.read(buf.data(), std::streamsize(n)) || std::memcmp(buf.data(), bytes.data() + at, n) != 0) return false;
            at += n;
        }
        return true;
    }

    /// Write a file into the private staging folder (no other process looks there; the commit moves it).
    static void write_plain(const fs::path& path, std::span<const std::uint8_t> bytes) {
        const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
        if (fd < 0) throw Error("cannot write " + path.string() + ": " + std::strerror(errno));
        std::size_t done = 0;
        while (done < bytes.size()) {
            const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
            if (n < 0 && errno == EINTR) continue;
            if (n < 0) {
                const int err = errno;
                ::close(fd);
                throw Error("cannot write " + path.string() + ": " + std::strerror(err));
            }
            done += std::size_t(n);
        }
        if (::close(fd) != 0) throw Error("cannot write " + path.string() + ": " + std::strerror(errno));
    }

    static double seconds_since(std::chrono::steady_clock::time_point t0) {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }

    /// Value `key` for the current node: at hand, read from node j's cache entry, or made by running node j.
    Value ensure(const std::string& key) {
        if (auto it = values_.find(key); it != values_.end()) return it->second;
        const auto [j, output] = producer_.at(key);
        State& s = states_[j];
        const PlannedNode& node = plan_.nodes[j];
        if (store_ && s.key && !s.rerun && s.status != Status::deferred) {
            const auto t0 = std::chrono::steady_clock::now();
            // A node that ran this time kept its entry (or could not); one marked cached was probed at its turn.
            if (s.status == Status::cached || store_->probe(*s.key, node.label)) {
                if (auto contents = store_->load(*s.key, node.label)) {
                    result_.timings[s.row].seconds += seconds_since(t0);
                    result_.timings[s.row].read = true;
                    Value wanted;
                    for (auto& [name, v] : contents->values) {
                        const std::string k = name.empty() ? node.value_name : node.value_name + "." + name;
                        if (k == key) wanted = v;
                        keep(k, std::move(v));
                    }
                    if (wanted) return wanted;
                }
            }
        }
        NodeOutputs out = execute(j);
        Value wanted = output.empty() ? out.main : out.side[output];
        if (!wanted) throw NodeFailed{1, node_error(node, "internal error: it did not make its value '" + key + "'")};
        return wanted;
    }

    /// Run node j (its inputs made or read first), keep its values and its cache entry.
    NodeOutputs execute(std::size_t j) {
        const PlannedNode& node = plan_.nodes[j];
        State& s = states_[j];
        std::vector<Value> inputs;
        for (const auto& key : node.inputs) inputs.push_back(key.empty() ? Value() : ensure(key));
        if (j == current_) release_inputs(j);
        const bool writes_files = !node.output_files.empty();
        const std::vector<fs::path> files_before =
            writes_files && s.key && staging_ ? staging_->files() : std::vector<fs::path>{};
        const std::size_t outside_before = outside_.size();
        if (options_.progress) options_.progress->start(int(j) + 1, int(plan_.nodes.size()), node.label, node.node->qualified_name());
        const auto start = std::chrono::steady_clock::now();
        NodeOutputs out;
        std::optional<Context> ctx;
        RunResult failure;        // exit code and message if the node failed here
        bool agreed = false;      // a tiled node learnt of another rank's failure (PeerFailed): already agreed on
        bool runs_here = true;    // false on ranks other than 0 for a node that is not tiled
        try {
            // A tiled run: tiles for a tiled node, the whole values on rank 0 for the others (collective).
            if (options_.tiled) runs_here = options_.tiled->prepare_inputs(node, inputs);
            const std::vector<Value> mapped_inputs = node.mapped_input >= 0 ? inputs : std::vector<Value>{};
            ctx.emplace(plan_, node, std::move(inputs), options_, staging_folder_, outside_);
            ctx->check_cancelled();
            if (!runs_here)
                ;  // rank 0 runs it
            else if (node.mapped_input >= 0)  // entries are made when a later node pulls them
                out = NodeOutputs(map_over_series(plan_, node, mapped_inputs, std::size_t(node.mapped_input), options_,
                                                  staging_folder_, outside_));
            else
                out = node.node->run(*ctx);
        } catch (const Cancelled&) {
            cancelled(failure, node_error(node, cancel_reason(options_)));
        } catch (const PeerFailed& e) {
            failure.exit_code = e.exit_code();  // the rank that failed says why
            agreed = true;
        } catch (const Error& e) {
            failure.exit_code = e.kind() == Error::Kind::bad_input ? 2 : 1;
            failure.error = node_error(node, e.what());
        } catch (const std::bad_alloc&) {
            failure.exit_code = 1;
            failure.error = node_error(node, "out of memory; try a smaller grid");
        } catch (const std::exception& e) {
            failure.exit_code = 1;
            failure.error = node_error(node, e.what());
        } catch (...) {
            failure.exit_code = 1;
            failure.error = node_error(node, "unknown exception");
        }
        // A tiled run goes on only if every rank finished the node; one rank (the lowest that failed) reports.
        if (options_.tiled && !agreed) agree_across_ranks(*options_.tiled, failure);
        if (failure.exit_code != 0) throw NodeFailed{failure.exit_code, failure.error};
        if (options_.tiled) options_.tiled->produced(node);
        const double seconds = seconds_since(start);
        if (options_.progress) options_.progress->finish(seconds);
        NodeTiming& row = result_.timings[s.row];
        row.seconds += seconds;
        row.cached = row.read = false;
        s.status = Status::ran;

        const bool series_out = node.node->output_series || node.mapped_input >= 0;
        const ValueType returned_entry = out.main.type() == ValueType::series ? out.main.series()->element : out.main.type();
        if (runs_here && ((out.main.type() == ValueType::series) != series_out || returned_entry != node.node->output))
            throw NodeFailed{1, node_error(node, "internal error: it returned a " +
                                                     (returned_entry == ValueType::none
                                                          ? std::string("nothing")
                                                          : describe_type(returned_entry, out.main.type() == ValueType::series)) +
                                                     " but declares a " + describe_type(node.node->output, series_out))};
        if (!node.value_name.empty()) {
            if (s.rerun && s.key) {  // what it made decides the keys of the nodes after it
                auto content_key = [&](const std::string& name, const Value& v) -> std::optional<cache::Digest> {
                    if (!cache::storable(v.type())) return std::nullopt;
                    return cache::content_key(*s.key, name, cache::value_hash(v));
                };
                value_keys_[node.value_name] = content_key("", out.main);
                for (const auto& [side, v] : out.side) value_keys_[node.value_name + "." + side] = content_key(side, v);
            }
            keep(node.value_name, out.main);
            for (const auto& [side, v] : out.side) keep(node.value_name + "." + side, v);
        }
        if (store_ && s.key && !s.rerun && out.main.type() != ValueType::series && outside_.size() == outside_before)
            save(j, out, ctx->said(), files_before);
        return out;
    }

    void save(std::size_t j, const NodeOutputs& out, const std::vector<std::string>& said,
              const std::vector<fs::path>& files_before) {
        const PlannedNode& node = plan_.nodes[j];
        try {
            cache::Contents c;
            if (cache::storable(out.main.type())) c.values.emplace_back("", out.main);
            for (const auto& [side, v] : out.side)
                if (cache::storable(v.type())) c.values.emplace_back(side, v);
            if (!node.output_files.empty()) {
                // Small files are kept whole, so a re-run into another folder puts them back. Files that
                // would take more than 1/64 of the cache's limit together are recorded by size and SHA-256
                // only (the manifest needs that digest anyway, and remembers it): copying them would cost
                // the run as much time and memory again, and the cache its room. A re-run finds them in
                // --out or runs the node again.
                std::vector<fs::path> made;
                std::uint64_t total = 0;
                for (const auto& f : staging_->files())
                    if (!std::binary_search(files_before.begin(), files_before.end(), f)) {
                        made.push_back(f);
                        std::error_code ec;
                        const auto size = fs::file_size(staging_folder_ / f, ec);
                        total += ec ? 0 : size;
                    }
                const bool keep_bytes = total <= store_->max_bytes() / 64;
                for (const auto& f : made) {
                    const fs::path full = staging_folder_ / f;
                    if (keep_bytes) {
                        c.files.emplace_back(f.generic_string(), read_file(full));
                        continue;
                    }
                    std::string hex = detail::remembered_sha256(full);
                    if (hex.empty()) {
                        hex = sha256_file(full);
                        detail::remember_sha256(full, hex);
                    }
                    c.recorded.push_back({f.generic_string(), std::uint64_t(fs::file_size(full)), hex});
                }
            }
            c.messages = said;
            store_->save(*states_[j].key, c);
        } catch (const std::exception& e) {
            warn("orogen: warning: could not keep the result of '" + node.label + "' in the cache (" + e.what() + ")");
        }
    }

    const Plan& plan_;
    const RunOptions& options_;
    const Staging* staging_;
    fs::path staging_folder_;
    std::vector<fs::path>& outside_;
    RunResult& result_;
    std::vector<State> states_;
    std::size_t current_ = 0;
    std::optional<cache::Store> store_;
    std::vector<fs::path> kept_;
    std::map<std::string, Value, std::less<>> values_;
    std::map<std::string, std::optional<cache::Digest>, std::less<>> value_keys_;
    std::map<std::string, std::pair<std::size_t, std::string>, std::less<>> producer_;  ///< value key → node, output
};

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

    Evaluation evaluation(plan, options, staging ? &*staging : nullptr, staging_folder, outside, result);
    try {
        evaluation.run_all();
    } catch (const NodeFailed& f) {
        result.exit_code = f.exit_code;
        result.error = f.message;
    }
    if (result.exit_code == 0) result.values = evaluation.take_values();
    if (options.tiled) share_digests(*options.tiled, staging_folder, result.exit_code == 0);
    if (const auto& store = evaluation.store()) {
        result.cache_summary = "cache: " + std::to_string(evaluation.reused()) + " of " + std::to_string(plan.nodes.size()) +
                               " nodes reused from " + store->folder().string() + " (" +
                               human_bytes(double(store->total_bytes())) + " of " +
                               human_bytes(double(options.cache->max_bytes)) + ")";
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
            write_manifest(plan, options, *staging, staged, outside, evaluation.kept());
            staging->commit("manifest.json");
            std::vector<fs::path> all = staged;
            all.insert(all.end(), evaluation.kept().begin(), evaluation.kept().end());
            std::sort(all.begin(), all.end());
            for (const auto& f : all) result.outputs.push_back(options.out_dir / f);
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
    // Columns as wide as their longest entry (at least the usual 16 and 26), so a long label or
    // kind:name (a mapped node's "frames[12]", a plugin's long name) does not push its row askew.
    std::size_t label_w = 16, node_w = 26;
    for (const auto& t : result.timings) label_w = std::max(label_w, t.label.size()), node_w = std::max(node_w, t.node.size());
    const int lw = int(label_w), nw = int(node_w);
    std::ostringstream out;
    std::vector<char> line(label_w + node_w + 64);
    std::snprintf(line.data(), line.size(), "%-*s %-*s %5s %10s %6s\n", lw, "node", nw, "kind:name", "line", "seconds",
                  "share");
    out << line.data();
    for (const auto& t : result.timings) {
        std::snprintf(line.data(), line.size(), "%-*s %-*s %5d %10.3f %5.1f%%%s\n", lw, t.label.c_str(), nw, t.node.c_str(),
                      t.line, t.seconds, result.total_seconds > 0 ? 100.0 * t.seconds / result.total_seconds : 0.0,
                      t.cached ? (t.read ? "  cached, read" : "  cached") : "");
        out << line.data();
    }
    std::snprintf(line.data(), line.size(), "%-*s %-*s %5s %10.3f\n", lw, "total", nw, "", "", result.total_seconds);
    out << line.data();
    if (!result.cache_summary.empty()) out << result.cache_summary << "\n";
    return out.str();
}

}  // namespace orogen
