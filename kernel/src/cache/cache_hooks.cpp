// The node cache as the runner's hook (run/hooks.hpp, docs/cache.md): a node
// whose key has an entry does not run; its values are read from the entry only
// when a node that does run needs them (so a cached upstream is never read when
// everything downstream is cached too), and the files it wrote are put back
// into the staging folder at its turn. A damaged entry is recomputed: the
// runner evaluates by demand, so a node runs whenever a value it makes is
// needed and not at hand.
#include "cache.hpp"

#include "io/digest.hpp"
#include "io/outputs.hpp"
#include "hooks/hooks.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <unistd.h>

namespace fs = std::filesystem;

namespace orogen {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Write a file into the private staging folder (no other process looks there; the commit moves it).
void write_plain(const fs::path& path, std::span<const std::uint8_t> bytes) {
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

/// Contents' values as the runner keeps them: "" for the main value, else the side output's name.
std::vector<std::pair<std::string, Value>> values_of(cache::Contents& contents) {
    std::vector<std::pair<std::string, Value>> values;
    for (auto& [name, v] : contents.values) values.emplace_back(name, std::move(v));
    return values;
}

class CacheHooks final : public NodeHooks {
public:
    CacheHooks(RunShared& shared, cache::Store store)
        : shared_(shared), plan_(shared.plan), store_(std::move(store)), states_(shared.plan.nodes.size()) {}

    bool usable() const { return store_.usable(); }

    /// Keyed by its content: a node that reads it is reused only for the same bits (and layers, and cell),
    /// whatever it is called and wherever it came from. Hashing costs a pass over it, only with the cache on.
    void bound(const std::string& name, const Value& v) override {
        if (cache::storable(v.type())) value_keys_[name] = cache::bound_key(cache::value_hash(v));
    }

    TurnAnswer at_turn(const NodeTurn& turn) override {
        const std::size_t i = turn.index;
        const PlannedNode& node = turn.node;
        State& s = states_[i];
        compute_key(i);
        TurnAnswer answer;
        if (!s.key || s.rerun) return answer;
        if (const auto info = store_.probe(*s.key, node.label)) {
            // Files and messages are this node's effects: they are put back now. Values wait for a reader.
            // A node whose large files are recorded, not kept, runs again if they are not in --out.
            if (info->files == 0) {
                answer.kind = TurnAnswer::Kind::reused;
                answer.reuse.why = "cached";
            } else if (restore(turn, answer.reuse)) {
                answer.kind = TurnAnswer::Kind::reused;
                answer.reuse.why = "cached (files restored)";
            }
            answer.reuse.said = info->texts;
        } else if (node.output_files.empty() && (node.node->output_series || node.mapped_input >= 0)) {
            // A series is made on demand and never kept: make it only if a node that runs reads it.
            answer.kind = TurnAnswer::Kind::deferred;
        }
        s.answered = answer.kind;
        return answer;
    }

    std::optional<Reuse> supply(const NodeTurn& turn) override {
        const State& s = states_[turn.index];
        if (!s.key || s.rerun || s.answered == TurnAnswer::Kind::deferred) return std::nullopt;
        const auto t0 = std::chrono::steady_clock::now();
        // A node that ran this time kept its entry (or could not); one reused was probed at its turn.
        if (s.answered != TurnAnswer::Kind::reused && !store_.probe(*s.key, turn.node.label)) return std::nullopt;
        auto contents = store_.load(*s.key, turn.node.label);
        if (!contents) return std::nullopt;
        turn.timing.seconds += seconds_since(t0);
        turn.timing.read = true;
        Reuse reuse;
        reuse.values = values_of(*contents);
        return reuse;
    }

    bool before_node(const NodeTurn& turn, std::vector<Value>&) override {
        State& s = states_[turn.index];
        s.answered = TurnAnswer::Kind::run;
        s.files_before = !turn.node.output_files.empty() && s.key && shared_.staging ? shared_.staging->files()
                                                                                     : std::vector<fs::path>{};
        s.outside_before = shared_.outside.size();
        return true;
    }

    void on_result(const NodeTurn& turn, const NodeOutputs& out, const std::vector<std::string>& said) override {
        const PlannedNode& node = turn.node;
        const State& s = states_[turn.index];
        if (!node.value_name.empty() && s.rerun && s.key) {  // what it made decides the keys of the nodes after it
            auto content_key = [&](const std::string& name, const Value& v) -> std::optional<cache::Digest> {
                if (!cache::storable(v.type())) return std::nullopt;
                return cache::content_key(*s.key, name, cache::value_hash(v));
            };
            value_keys_[node.value_name] = content_key("", out.main);
            for (const auto& [side, v] : out.side) value_keys_[node.value_name + "." + side] = content_key(side, v);
        }
        if (s.key && !s.rerun && out.main.type() != ValueType::series && shared_.outside.size() == s.outside_before)
            save(turn, out, said);
    }

    void run_finished() override {
        int reused = 0;
        for (const auto& t : shared_.result.timings) reused += t.cached ? 1 : 0;
        shared_.result.cache_summary = "cache: " + std::to_string(reused) + " of " +
            std::to_string(plan_.nodes.size()) + " nodes reused from " + store_.folder().string() + " (" +
            human_bytes(double(store_.total_bytes())) + " of " + human_bytes(double(shared_.options.cache->max_bytes)) +
            ")";
    }

private:
    struct State {
        std::optional<cache::Digest> key;  ///< nullopt: not cached (a series' producer unknown...)
        bool rerun = false;  ///< always runs; its outputs are keyed by their contents
        TurnAnswer::Kind answered = TurnAnswer::Kind::run;
        std::vector<fs::path> files_before;  ///< the staging folder's files before it ran (sorted)
        std::size_t outside_before = 0;
    };

    void compute_key(std::size_t i) {
        const PlannedNode& node = plan_.nodes[i];
        State& s = states_[i];
        s.rerun = node.node->cache == CachePolicy::rerun;
        for (const auto& p : node.node->params)
            if (p.type == ParamType::path && p.path_role == PathRole::input) s.rerun = true;
        const auto plugin = shared_.options.node_plugins.find(node.node->qualified_name());
        if (plugin == shared_.options.node_plugins.end() || plugin->second.identity.empty()) return;
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
        s.key = cache::node_key(plan_, node, inputs, plugin->second.name, plugin->second.version,
                                plugin->second.identity, node_seed(plan_.seed, node.label));
        if (s.rerun || node.value_name.empty()) return;
        value_keys_[node.value_name] = cache::output_key(*s.key, "");
        for (const auto& side : node.node->side_outputs)
            value_keys_[node.value_name + "." + side.name] = cache::output_key(*s.key, side.name);
    }

    /// Put the node's files back into the staging folder and its values in `reuse`; false if its entry
    /// failed, or if a file it recorded (too large to keep, docs/cache.md) is not in --out with its bytes:
    /// it runs again.
    bool restore(const NodeTurn& turn, Reuse& reuse) {
        const PlannedNode& node = turn.node;
        const auto t0 = std::chrono::steady_clock::now();
        auto contents = store_.load(*states_[turn.index].key, node.label);
        if (!contents) return false;
        try {
            // Recorded files first: if one is missing or differs, nothing is staged and the node runs.
            std::vector<fs::path> recorded_in_place;
            for (const auto& f : contents->recorded) {
                if (!recorded_in_place_at(fs::path(f.path), f.bytes, f.sha256)) {
                    turn.timing.seconds += seconds_since(t0);
                    return false;
                }
                recorded_in_place.emplace_back(f.path);
            }
            shared_.kept.insert(shared_.kept.end(), recorded_in_place.begin(), recorded_in_place.end());
            int written = 0;
            for (const auto& [relative, bytes] : contents->files) {
                const fs::path rel(relative);
                if (rel.empty() || rel.is_absolute() ||
                    std::any_of(rel.begin(), rel.end(), [](const fs::path& p) { return p == ".."; }))
                    throw Error("a cached file has a bad path: " + relative);
                if (already_in_place(rel, bytes)) {  // nothing to stage or move: it is listed as it is
                    shared_.kept.push_back(rel);
                    continue;
                }
                const fs::path full = shared_.staging_folder / rel;
                fs::create_directories(full.parent_path());
                write_plain(full, bytes);
                ++written;
            }
            // One flush for all of them (an fsync each costs ~8 ms: 123 files of plates/ took a second).
            const int fd = written ? ::open(shared_.staging_folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC) : -1;
            if (fd >= 0) {
                ::syncfs(fd);
                ::close(fd);
            }
        } catch (const std::exception& e) {
            throw NodeFailed{1, node_error(node, std::string("cannot put back its cached files: ") + e.what())};
        }
        reuse.values = values_of(*contents);
        turn.timing.seconds += seconds_since(t0);
        return true;
    }

    /// True if `--out/rel` is a regular file inside --out of `size` bytes whose SHA-256 is `sha256` (a file
    /// recorded by its digest). The digest is remembered, so the manifest does not read the file again.
    bool recorded_in_place_at(const fs::path& rel, std::uint64_t size, const std::string& sha256) const {
        const OutputPlace place = place_output(shared_.options.out_dir, rel.string());
        if (!place.inside) return false;
        const fs::path target = shared_.options.out_dir / place.relative;
        std::error_code ec;
        if (!fs::is_regular_file(fs::symlink_status(target, ec)) || fs::file_size(target, ec) != size || ec)
            return false;
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
        const OutputPlace place = place_output(shared_.options.out_dir, rel.string());
        if (!place.inside) return false;
        const fs::path target = shared_.options.out_dir / place.relative;
        std::error_code ec;
        if (!fs::is_regular_file(fs::symlink_status(target, ec)) || fs::file_size(target, ec) != bytes.size() || ec)
            return false;
        std::ifstream in(target, std::ios::binary);
        std::vector<char> buf(std::size_t(1) << 20);
        std::size_t at = 0;
        while (at < bytes.size()) {
            const std::size_t n = std::min(buf.size(), bytes.size() - at);
            if (!in.read(buf.data(), std::streamsize(n)) || std::memcmp(buf.data(), bytes.data() + at, n) != 0)
                return false;
            at += n;
        }
        return true;
    }

    void save(const NodeTurn& turn, const NodeOutputs& out, const std::vector<std::string>& said) {
        const PlannedNode& node = turn.node;
        const State& s = states_[turn.index];
        try {
            cache::Contents c;
            if (cache::storable(out.main.type())) c.values.emplace_back("", out.main);
            for (const auto& [side, v] : out.side)
                if (cache::storable(v.type())) c.values.emplace_back(side, v);
            if (!node.output_files.empty()) add_files(c, s.files_before);
            c.messages = said;
            store_.save(*s.key, c);
        } catch (const std::exception& e) {
            shared_.warn("orogen: warning: could not keep the result of '" + node.label + "' in the cache (" +
                         e.what() + ")");
        }
    }

    /// The files a node wrote into the staging folder (those not in `files_before`), into its entry.
    void add_files(cache::Contents& c, const std::vector<fs::path>& files_before) const {
        // Small files are kept whole, so a re-run into another folder puts them back. Files that
        // would take more than 1/64 of the cache's limit together are recorded by size and SHA-256
        // only (the manifest needs that digest anyway, and remembers it): copying them would cost
        // the run as much time and memory again, and the cache its room. A re-run finds them in
        // --out or runs the node again.
        std::vector<fs::path> made;
        std::uint64_t total = 0;
        for (const auto& f : shared_.staging->files())
            if (!std::binary_search(files_before.begin(), files_before.end(), f)) {
                made.push_back(f);
                std::error_code ec;
                const auto size = fs::file_size(shared_.staging_folder / f, ec);
                total += ec ? 0 : size;
            }
        const bool keep_bytes = total <= store_.max_bytes() / 64;
        for (const auto& f : made) {
            const fs::path full = shared_.staging_folder / f;
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

    RunShared& shared_;
    const Plan& plan_;
    cache::Store store_;
    std::vector<State> states_;
    std::map<std::string, std::optional<cache::Digest>, std::less<>> value_keys_;
};

}  // namespace

std::unique_ptr<NodeHooks> cache_hooks(RunShared& shared) {
    // Rank 0 of a tiled run keeps no cache either: its nodes' values are tiles elsewhere.
    if (!shared.options.cache || !shared.staging || shared.options.tiled) return nullptr;
    auto hooks = std::make_unique<CacheHooks>(
        shared, cache::Store(*shared.options.cache, [&shared](const std::string& line) { shared.warn(line); }));
    if (!hooks->usable()) return nullptr;
    return hooks;
}

}  // namespace orogen
