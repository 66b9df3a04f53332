#include "runner.hpp"

#include "json.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/random.hpp>

#include <tbb/global_control.h>

#include <chrono>
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
            std::vector<fs::path>& outputs, bool for_entry = false)
        : plan_(plan), node_(node), inputs_(std::move(inputs)), options_(options), outputs_(outputs),
          seed_(node_seed(plan.seed, node.label)), for_entry_(for_entry) {}

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
    fs::path output_path(const std::string& relative) override {
        if (for_entry_)
            throw Error("internal error: " + node_.node->qualified_name() +
                        " writes files, so it cannot be mapped over a series");
        const fs::path rel(relative);
        const fs::path full = rel.is_absolute() ? rel : options_.out_dir / rel;
        std::error_code ec;
        fs::create_directories(full.parent_path(), ec);
        if (ec)
            throw Error("cannot write " + full.string() + ": cannot create folder " + full.parent_path().string() +
                        " (" + ec.message() + ")");
        outputs_.push_back(full);
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

private:
    const Plan& plan_;
    const PlannedNode& node_;
    std::vector<Value> inputs_;
    const RunOptions& options_;
    std::vector<fs::path>& outputs_;
    std::uint64_t seed_;
    bool for_entry_;
};

/// The series a node mapped over input `mapped` of `inputs` yields: entry j
/// runs the node on entry j of that input (other inputs as given), when a
/// consumer asks for it. It runs inside run(), which keeps plan, node and
/// options alive for as long as any node can pull an entry.
std::shared_ptr<Series> map_over_series(const Plan& plan, const PlannedNode& node, std::vector<Value> inputs,
                                        std::size_t mapped, const RunOptions& options, std::vector<fs::path>& outputs) {
    const std::shared_ptr<const Series> source = inputs[mapped].series();
    auto result = std::make_shared<Series>();
    result->element = node.node->output;
    result->times = source->times;
    result->make = [&plan, &node, &options, &outputs, inputs = std::move(inputs), mapped,
                    source](std::size_t j) -> Value {
        std::vector<Value> entry_inputs = inputs;
        entry_inputs[mapped] = source->at(j);
        Context ctx(plan, node, std::move(entry_inputs), options, outputs, true);
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

void write_manifest(const Plan& plan, const RunOptions& options, const RunResult& result) {
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
    for (const auto& f : result.outputs) {
        std::error_code ec;
        if (!fs::exists(f, ec)) continue;
        j.begin_object();
        j.key("path").value(fs::relative(f, options.out_dir, ec).string());
        j.key("bytes").value(std::uint64_t(fs::file_size(f, ec)));
        j.key("sha256").value(sha256_file(f));
        j.end_object();
    }
    j.end_array();
    j.end_object();
    const std::string& text = j.str();
    write_file_atomically(options.out_dir / "manifest.json",
                          std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
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
        return result;
    }

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
        const std::vector<Value> mapped_inputs = node.mapped_input >= 0 ? inputs : std::vector<Value>{};
        Context ctx(plan, node, std::move(inputs), options, result.outputs);
        if (options.progress) options.progress->start(int(i) + 1, total, node.label, node.node->qualified_name());
        const auto start = std::chrono::steady_clock::now();
        NodeOutputs out;
        try {
            ctx.check_cancelled();
            if (node.mapped_input >= 0)  // entries are made when a later node pulls them
                out = NodeOutputs(map_over_series(plan, node, mapped_inputs, std::size_t(node.mapped_input), options,
                                                  result.outputs));
            else
                out = node.node->run(ctx);
        } catch (const Cancelled&) {
            result.exit_code = 130;
            result.error = node_error(node, "cancelled by the user");
            break;
        } catch (const Error& e) {
            result.exit_code = e.kind() == Error::Kind::bad_input ? 2 : 1;
            result.error = node_error(node, e.what());
            break;
        } catch (const std::bad_alloc&) {
            result.exit_code = 1;
            result.error = node_error(node, "out of memory; try a smaller grid");
            break;
        } catch (const std::exception& e) {
            result.exit_code = 1;
            result.error = node_error(node, e.what());
            break;
        } catch (...) {
            result.exit_code = 1;
            result.error = node_error(node, "unknown exception");
            break;
        }
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (options.progress) options.progress->finish(seconds);
        result.timings.push_back({node.label, node.node->qualified_name(), node.where.line, seconds});

        const bool series_out = node.node->output_series || node.mapped_input >= 0;
        const ValueType returned_entry = out.main.type() == ValueType::series ? out.main.series()->element : out.main.type();
        if ((out.main.type() == ValueType::series) != series_out || returned_entry != node.node->output) {
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
    if (result.exit_code == 0) {
        try {
            write_manifest(plan, options, result);
            result.outputs.push_back(options.out_dir / "manifest.json");
        } catch (const std::exception& e) {
            result.exit_code = 1;
            result.error = std::string("orogen: error: ") + e.what() + "\n";
        }
    }
    return result;
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
