#include "plan.hpp"

#include "io/outputs.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/process.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <set>
#include <sstream>
#include <unistd.h>

namespace fs = std::filesystem;

namespace orogen {

namespace {

using spec::Diagnostics;
using spec::Literal;
using spec::Location;

std::string number_text(double v) {
    std::ostringstream s;
    s.precision(15);  // 1000000, not 1e+06; 0.1, not 0.10000000000000001
    s << v;
    return s.str();
}

std::string range_text(const Param& p) {
    std::string lo = p.minimum ? (p.minimum_exclusive ? "(" : "[") + number_text(*p.minimum) : "(-inf";
    std::string hi = p.maximum ? number_text(*p.maximum) + (p.maximum_exclusive ? ")" : "]") : "inf)";
    return lo + ", " + hi;
}

bool in_range(const Param& p, double v) {
    if (p.minimum && (p.minimum_exclusive ? !(v > *p.minimum) : !(v >= *p.minimum))) return false;
    if (p.maximum && (p.maximum_exclusive ? !(v < *p.maximum) : !(v <= *p.maximum))) return false;
    return true;
}

std::string lower(std::string s) {
    for (auto& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

/// Convert a literal to a parameter value of `p`'s type, checking its range.
std::optional<ParamValue> convert(const Param& p, const Literal& l, const std::string& node, Diagnostics& diags) {
    const std::string who = "'" + p.name + "' of " + node;
    auto wrong = [&](const std::string& expected) {
        diags.error(l.where, who + " must be " + expected + ", got " + spec::describe(l));
        return std::nullopt;
    };
    auto non_finite_word = [&]() {
        return l.kind == Literal::Kind::word &&
            (lower(l.text) == "nan" || lower(l.text) == "inf" || lower(l.text) == "infinity");
    };
    auto number = [&](const Literal& n, bool integer) -> std::optional<double> {
        if (n.kind != Literal::Kind::number) {
            if (n.kind == Literal::Kind::word &&
                (lower(n.text) == "nan" || lower(n.text) == "inf" || lower(n.text) == "infinity")) {
                diags.error(n.where, who + " must be a finite number, got " + n.text);
                return std::nullopt;
            }
            diags.error(n.where,
                        who + " must be " + (integer ? "an integer" : "a number") + ", got " + spec::describe(n));
            return std::nullopt;
        }
        if (!std::isfinite(n.number)) {
            diags.error(n.where, who + " must be a finite number, got " + n.text);
            return std::nullopt;
        }
        if (integer && (!n.integer && n.number != std::floor(n.number))) {
            diags.error(n.where, who + " must be an integer, got " + n.text);
            return std::nullopt;
        }
        if (!in_range(p, n.number)) {
            diags.error(n.where,
                        who + " is " + n.text + ", out of range " + range_text(p) +
                            (p.unit_text.empty() ? "" : " " + p.unit_text));
            return std::nullopt;
        }
        return n.number;
    };
    auto point = [&](const Literal& pt) -> std::optional<Point2> {
        if (pt.kind != Literal::Kind::point) {
            diags.error(pt.where, who + " must be a point (x, y), got " + spec::describe(pt));
            return std::nullopt;
        }
        auto x = number(pt.items[0], false);
        auto y = number(pt.items[1], false);
        if (!x || !y) return std::nullopt;
        return Point2{*x, *y};
    };

    switch (p.type) {
        case ParamType::integer: {
            if (non_finite_word()) return number(l, true), std::nullopt;
            auto v = number(l, true);
            if (!v) return std::nullopt;
            if (std::fabs(*v) > 9.0e18) return wrong("an integer of at most 19 digits");
            return ParamValue(std::int64_t(*v));
        }
        case ParamType::real: {
            auto v = number(l, false);
            if (!v) return std::nullopt;
            return ParamValue(*v);
        }
        case ParamType::boolean:
            if (l.kind != Literal::Kind::boolean) return wrong("true or false");
            return ParamValue(l.boolean);
        case ParamType::string:
            if (l.kind != Literal::Kind::string && l.kind != Literal::Kind::word) return wrong("a string");
            return ParamValue(l.text);
        case ParamType::choice: {
            if (l.kind != Literal::Kind::string && l.kind != Literal::Kind::word) {
                std::string options;
                for (const auto& c : p.choices) options += (options.empty() ? "" : ", ") + c;
                return wrong("one of " + options);
            }
            if (std::find(p.choices.begin(), p.choices.end(), l.text) == p.choices.end()) {
                std::string options;
                for (const auto& c : p.choices) options += (options.empty() ? "" : ", ") + c;
                std::string msg = who + " is '" + l.text + "', which is not one of " + options;
                const std::string guess = spec::closest(l.text, p.choices);
                if (!guess.empty()) msg += "; did you mean '" + guess + "'?";
                diags.error(l.where, msg);
                return std::nullopt;
            }
            return ParamValue(l.text);
        }
        case ParamType::point: {
            auto v = point(l);
            if (!v) return std::nullopt;
            return ParamValue(*v);
        }
        case ParamType::points: {
            std::vector<Point2> pts;
            if (l.kind == Literal::Kind::point) {
                auto v = point(l);
                if (!v) return std::nullopt;
                pts.push_back(*v);
            } else if (l.kind == Literal::Kind::list) {
                bool ok = true;
                for (const auto& item : l.items) {
                    auto v = point(item);
                    if (!v) ok = false;
                    else pts.push_back(*v);
                }
                if (!ok) return std::nullopt;
                if (pts.empty()) {
                    diags.error(l.where, who + " needs at least one point, e.g. [(0.5, 0.5)]");
                    return std::nullopt;
                }
            } else {
                return wrong("a point (x, y) or a list of points [(x, y), ...]");
            }
            if (pts.size() > p.max_points) {
                diags.error(l.where,
                            who + " takes at most " + std::to_string(p.max_points) + " points, got " +
                                std::to_string(pts.size()));
                return std::nullopt;
            }
            return ParamValue(std::move(pts));
        }
        case ParamType::path:
            if (l.kind != Literal::Kind::string) return wrong("a path in quotes, e.g. \"out.png\"");
            if (l.text.empty()) return wrong("a non-empty path");
            return ParamValue(l.text);
    }
    return std::nullopt;
}

/// Thrown to a node's check hook that reads a parameter with an error: the hook stops there, quietly.
/// Not a std::exception, so a hook that catches those does not swallow it.
struct InvalidParamRead {};

class CheckContextImpl : public CheckContext {
public:
    CheckContextImpl(const GridSpec& grid, std::vector<const ValueInfo*> inputs, const PlannedNode& node,
                     const std::map<std::string, Location, std::less<>>& param_where, const Location& call_where,
                     const fs::path& spec_folder, Diagnostics& diags, ValueInfo output,
                     const std::set<std::string, std::less<>>& invalid)
        : grid_(grid), inputs_(std::move(inputs)), node_(node), param_where_(param_where), call_where_(call_where),
          spec_folder_(spec_folder), diags_(diags), output_(std::move(output)), invalid_(invalid) {}

    const GridSpec& grid() const override { return grid_; }
    // A node with a parameter error never runs, and whether it would tile may hang on that parameter
    // (untiled_because reads the parameters): its whole-grid share stands.
    double memory_share() const override { return invalid_.empty() && runs_tiled(node_) ? tiled_share_ : 1.0; }
    void set_tiled_share(double share) { tiled_share_ = share; }
    const ValueInfo* input(std::size_t i) const override { return i < inputs_.size() ? inputs_[i] : nullptr; }
    bool given(std::string_view param) const override { return node_.given.count(param) > 0; }
    const ParamValue& param(std::string_view name) const override {
        if (invalid_.count(name)) throw InvalidParamRead{};
        auto it = node_.params.find(name);
        if (it == node_.params.end())
            throw Error("internal error: " + node_.node->qualified_name() + " has no parameter '" + std::string(name) +
                        "'");
        return it->second;
    }
    fs::path resolved_path(std::string_view name) const override {
        const fs::path p = std::get<std::string>(param(name));
        return p.is_absolute() ? p : spec_folder_ / p;
    }
    void error(std::string_view param, std::string message) override {
        auto it = param_where_.find(param);
        const Location& where = it != param_where_.end() ? it->second : call_where_;
        diags_.error(where, node_.node->qualified_name() + ": " + message);
        ++errors_;
        note_overrides(param);
    }
    ValueInfo& output() override { return output_; }
    const std::vector<ProcessCall>& processes() const override { return node_.processes; }
    void process_error(std::size_t index, std::string_view param, std::string message) override {
        if (process_error_) process_error_(index, param, std::move(message));
        else error(param, std::move(message));
        ++errors_;
    }
    void set_process_error(std::function<void(std::size_t, std::string_view, std::string)> report) {
        process_error_ = std::move(report);
    }
    ValueInfo* side_output(std::string_view name) override {
        auto it = sides_.find(name);
        return it != sides_.end() ? &it->second : nullptr;
    }
    void set_sides(std::map<std::string, ValueInfo, std::less<>> sides) { sides_ = std::move(sides); }
    std::map<std::string, ValueInfo, std::less<>> take_sides() { return std::move(sides_); }
    int errors() const { return errors_; }
    ValueInfo take_output() { return std::move(output_); }

private:
    /// A cross-parameter error that a --set may have caused (the hook blames one parameter, maybe in the
    /// spec, for a clash with one set on the command line): each other parameter of this node set by --set
    /// gets a note at the override, once.
    void note_overrides(std::string_view blamed) {
        if (noted_) return;
        noted_ = true;
        for (const auto& [name, where] : param_where_)
            if (name != blamed && where.source && where.source->name.rfind("--set", 0) == 0)
                diags_.note(where, "'" + name + "' of " + node_.label + " is set here, on the command line");
    }

    bool noted_ = false;
    std::function<void(std::size_t, std::string_view, std::string)> process_error_;
    double tiled_share_ = 1.0;
    const GridSpec& grid_;
    std::vector<const ValueInfo*> inputs_;
    const PlannedNode& node_;
    const std::map<std::string, Location, std::less<>>& param_where_;
    const Location& call_where_;
    const fs::path& spec_folder_;
    Diagnostics& diags_;
    ValueInfo output_;
    std::map<std::string, ValueInfo, std::less<>> sides_;
    const std::set<std::string, std::less<>>& invalid_;
    int errors_ = 0;
};

/// What a process's check hook sees: its checked call, the grid, the loop node's inputs.
class ProcessCheckContextImpl : public ProcessCheckContext {
public:
    ProcessCheckContextImpl(const GridSpec& grid, const ProcessCall& call, const std::vector<const ValueInfo*>& inputs,
                            const std::map<std::string, Location, std::less<>>& param_where, const Location& where,
                            Diagnostics& diags)
        : grid_(grid), call_(call), inputs_(inputs), param_where_(param_where), where_(where), diags_(diags) {}
    const GridSpec& grid() const override { return grid_; }
    const ProcessCall& call() const override { return call_; }
    const ValueInfo* node_input(std::size_t i) const override { return i < inputs_.size() ? inputs_[i] : nullptr; }
    void error(std::string_view param, std::string message) override {
        auto it = param_where_.find(param);
        diags_.error(it != param_where_.end() ? it->second : where_, call_.label + ": " + message);
    }

private:
    const GridSpec& grid_;
    const ProcessCall& call_;
    const std::vector<const ValueInfo*>& inputs_;
    const std::map<std::string, Location, std::less<>>& param_where_;
    const Location& where_;
    Diagnostics& diags_;
};

bool has_extension(const std::string& path, const std::string& ext) {
    return path.size() >= ext.size() && lower(path.substr(path.size() - ext.size())) == lower(ext);
}

/// The checker's walk over one spec: the state that outlives one statement, and a named step for each part
/// of a statement's check. Every step reports what it finds and goes on, so one `orogen check` shows every
/// mistake at once.
class Checker {
public:
    Checker(const spec::Spec& parsed, const Registry& registry, const fs::path& spec_path, const CheckOptions& options,
            Diagnostics& diags)
        : parsed_(parsed), registry_(registry), options_(options), diags_(diags), file_start_{parsed.source, 1, 1, 1} {
        plan_.spec_path = spec_path;
        plan_.spec_folder = spec_path.parent_path();  // "" for a spec in the current folder: paths stay as written
        plan_.source = parsed.source;
        plan_.overrides = options.overrides;
    }

    Plan run() {
        check_header();
        parse_overrides();
        index_names();
        for (std::size_t si = 0; si < parsed_.statements.size(); ++si) check_statement(si);
        report_unused_overrides();
        warn_if_nothing_is_written();
        return std::move(plan_);
    }

private:
    struct PendingOverride {
        spec::Override o;
        bool used = false;
    };

    /// One statement's node while it is checked.
    struct NodeCheck {
        NodeCheck(const spec::Statement& statement, const NodeDescriptor* descriptor)
            : st(statement), node(descriptor) {}
        const spec::Statement& st;
        const NodeDescriptor* node;
        PlannedNode planned;
        bool inputs_ok = true;
        std::vector<const ValueInfo*> input_infos;
        std::unique_ptr<ValueInfo> mapped_entry;  ///< what the check hook sees of a mapped series input
        std::map<std::string, Location, std::less<>> param_where;
        std::map<std::string, const Literal*, std::less<>> literals;
        std::set<std::string, std::less<>> invalid;  ///< parameters with an error: the check hook must not read them
        /// A loop node's body, as checked: one entry per process the registry knows.
        struct BodyProcess {
            const spec::ProcessCallSyntax* syntax = nullptr;
            ProcessCall call;
            std::map<std::string, Location, std::less<>> param_where;
            std::map<std::string, const Literal*, std::less<>> literals;
            std::set<std::string, std::less<>> invalid;
        };
        std::vector<BodyProcess> body;
    };

    void check_header() {
        if (!parsed_.version) {
            if (!parsed_.broken_header)  // a header line that did not parse was reported already
                diags_.error(file_start_, "a spec starts with its format version: add `orogen 1` as the first line");
        } else if (*parsed_.version != 1) {
            diags_.error(parsed_.version_where,
                         "format version " + std::to_string(*parsed_.version) +
                             " is not supported; this orogen reads `orogen 1`");
        }
        plan_.seed = options_.seed ? *options_.seed : parsed_.seed.value_or(0);
        plan_.grid.width = parsed_.grid_width;
        plan_.grid.height = parsed_.grid_height;
        plan_.grid.cell = parsed_.grid_cell;
        plan_.grid_given = parsed_.has_grid;
        plan_.cell_given = parsed_.has_cell;
        if (const std::string problem =
                heightmap_memory_problem(plan_.grid.width, plan_.grid.height, options_.heightmap_memory_limit);
            !problem.empty())
            diags_.error(
                parsed_.has_grid ? parsed_.grid_where : file_start_,
                "grid " + std::to_string(plan_.grid.width) + "x" + std::to_string(plan_.grid.height) + " " + problem);
    }

    /// Each --set parsed as its own little source, so its errors point into the override.
    void parse_overrides() {
        int override_order = 0;
        for (const auto& text : options_.overrides) {
            auto src = std::make_shared<spec::Source>("--set " + text, text, ++override_order);
            if (auto o = spec::parse_override(src, diags_)) overrides_.push_back({std::move(*o)});
        }
    }

    void index_names() {
        for (const auto* n : registry_.nodes()) all_nodes_.push_back(n->qualified_name());
        for (const auto& st : parsed_.statements)
            if (!st.name.empty()) defined_anywhere_.emplace(st.name, st.name_where);
        nested_key_.assign(parsed_.statements.size(), "");
        for (const auto& [name, info] : options_.bound) values_[name] = info;  // made before the first line
        // A line that did not parse: its syntax error was reported; a read of its value says nothing more.
        for (const auto& name : parsed_.broken_names) {
            values_.emplace(name, ValueInfo{});
            poisoned_.insert(name);
            labels_.push_back(name);
        }
    }

    void check_statement(std::size_t si) {
        const auto& st = parsed_.statements[si];
        const auto& call = st.call;
        const std::string label = label_of(si);
        if (!st.name.empty())
            if (auto it = defined_at_.find(st.name); it != defined_at_.end())
                diags_.error(st.name_where,
                             "'" + st.name + "' is already defined on line " + std::to_string(it->second.line) +
                                 "; give this value another name");
        if (!st.name.empty() && options_.bound.count(st.name))
            diags_.error(st.name_where,
                         "'" + st.name +
                             "' is a value the caller hands to the run (an input of "
                             "orogen.node()); give this value another name");
        const NodeDescriptor* node = registry_.find(call.qualified());
        if (!node) {
            report_unknown_node(st, label);
            return;
        }
        NodeCheck nc(st, node);
        nc.planned.node = node;
        nc.planned.value_name = st.nested ? label : st.name;  // a label holds ':', so it never meets a name
        nc.planned.in_place = st.nested;
        nc.planned.label = label;
        nc.planned.where = call.where;
        check_inputs(nc);
        gather_params(nc);
        convert_params(nc);
        check_paths(nc);
        check_body(nc);
        auto [out, sides] = node_output(nc);
        define_value(nc, std::move(out), std::move(sides));
    }

    /// Unnamed calls (exporters, and calls written where an input goes) are labelled kind:node, then
    /// kind:node#2, #3...: the label seeds the node, and --set reaches it by its label.
    std::string label_of(std::size_t si) {
        const auto& st = parsed_.statements[si];
        std::string label = st.name;
        if (st.name.empty()) {
            const std::string q = st.call.qualified();
            label = q;
            if (++unnamed_count_[q] > 1) label += "#" + std::to_string(unnamed_count_[q]);
        }
        labels_.push_back(label);
        if (st.nested) nested_key_[si] = label;
        return label;
    }

    void report_unknown_node(const spec::Statement& st, const std::string& label) {
        std::string msg = "unknown node '" + st.call.qualified() + "'";
        const std::string guess = spec::closest(st.call.qualified(), all_nodes_);
        msg += guess.empty() ? "; `orogen list` shows the nodes the loaded plugins provide"
                             : "; did you mean '" + guess + "'?";
        msg +=
            " (a plugin of your own: its folder in OROGEN_PLUGIN_PATH; `orogen version` lists the folders "
            "searched)";
        diags_.error(st.call.where, msg);
        if (!st.name.empty() || st.nested) {
            if (!st.name.empty()) defined_at_.emplace(st.name, st.name_where);
            values_.emplace(label, ValueInfo{});  // so later uses do not also say "undefined"
            poisoned_.insert(label);
        }
    }

    void check_inputs(NodeCheck& nc) {
        const auto& call = nc.st.call;
        const NodeDescriptor* node = nc.node;
        nc.input_infos.assign(node->inputs.size(), nullptr);
        nc.planned.inputs.assign(node->inputs.size(), "");
        if (call.inputs.size() > node->inputs.size()) {
            const auto& extra = call.inputs[node->inputs.size()];
            diags_.error(extra.where,
                         call.qualified() + " takes " +
                             (node->inputs.empty() ? std::string("no inputs")
                                                   : "at most " + std::to_string(node->inputs.size()) +
                                      (node->inputs.size() == 1 ? " input" : " inputs")) +
                             ", but '" + extra.full() + "' is input " + std::to_string(node->inputs.size() + 1));
            nc.inputs_ok = false;
        }
        for (std::size_t i = 0; i < call.inputs.size() && i < node->inputs.size(); ++i) check_input(nc, i);
        for (std::size_t i = call.inputs.size(); i < node->inputs.size(); ++i) {
            if (node->inputs[i].need != Need::required) continue;
            diags_.error(call.where,
                         call.qualified() + " needs input " + std::to_string(i + 1) + " ('" + node->inputs[i].name +
                             "', a " + describe_type(node->inputs[i].type, node->inputs[i].many == Many::series) +
                             "): " + call.qualified() + "(NAME, ...)");
            nc.inputs_ok = false;
        }
    }

    void report_undefined_input(const spec::Input& in) {
        if (!in.side.empty() && values_.count(in.name)) {
            diags_.error(in.where, "'" + in.name + "' has no side value '" + in.side + "'");
            return;
        }
        std::vector<std::string> names;
        for (const auto& [k, _] : values_)
            if (k.find(':') == std::string::npos) names.push_back(k);  // not the labels of calls in place
        std::string msg = "'" + in.full() + "' is not defined";
        if (auto later = defined_anywhere_.find(in.name);
            later != defined_anywhere_.end() && defined_at_.count(in.name) == 0) {
            msg += " yet: it is defined later, on line " + std::to_string(later->second.line) +
                "; move that line above this one (a node reads only values made before it)";
        } else if (defined_at_.count(in.name) == 0) {
            const std::string guess = spec::closest(in.full(), names);
            msg += guess.empty() ? "; define it with `" + in.name + " = kind:node(...)` on an earlier line"
                                 : "; did you mean '" + guess + "'?";
        }
        diags_.error(in.where, msg);
    }

    void check_input(NodeCheck& nc, std::size_t i) {
        const auto& call = nc.st.call;
        const NodeDescriptor* node = nc.node;
        const auto& in = call.inputs[i];
        const auto& want = node->inputs[i];
        const std::string key = in.statement >= 0 ? nested_key_[std::size_t(in.statement)] : in.full();
        auto it = values_.find(key);
        if (it == values_.end()) {
            report_undefined_input(in);
            nc.inputs_ok = false;
            return;
        }
        if (poisoned_.count(in.statement >= 0 ? key
                                              : in.name)) {  // its node is unknown: that error was reported already
            nc.inputs_ok = false;
            return;
        }
        if (it->second.type == ValueType::none) {
            diags_.error(in.where, "'" + in.full() + "' holds no value (its node only writes files)");
            nc.inputs_ok = false;
            return;
        }
        // One value, a series, or either; a series given for one value maps the node over it.
        const ValueInfo& have = it->second;
        const bool have_series = have.type == ValueType::series;
        const ValueType have_entry = have_series ? have.element : have.type;
        const bool maps = want.many == Many::one && have_series && node->output != ValueType::none &&
            !node->output_series && nc.planned.mapped_input < 0;
        // An input declared ValueType::none takes any value; the node's check hook says which it accepts.
        const bool fits = (want.type == ValueType::none || have_entry == want.type) &&
            (want.many == Many::either || (want.many == Many::series) == have_series || maps);
        if (!fits) {
            std::string msg = call.qualified() + " input " + std::to_string(i + 1) + " ('" + want.name +
                "') must be a " + describe_type(want.type, want.many == Many::series) +
                (want.many == Many::either ? " or a " + describe_type(want.type, true) : "") + ", but '" + in.full() +
                "' is a " + describe_type(have_entry, have_series);
            if ((want.type == ValueType::none || have_entry == want.type) && want.many == Many::one && have_series)
                msg += node->output == ValueType::none ? " (a node that only writes files is not mapped over a series)"
                                                       : " (a node is mapped over one series input at a time)";
            diags_.error(in.where, msg);
            nc.inputs_ok = false;
            return;
        }
        if (maps) {
            nc.planned.mapped_input = int(i);
            ValueInfo entry = have;  // the node's check hook sees one entry
            entry.type = have.element;
            entry.element = ValueType::none;
            entry.count = 0;
            nc.mapped_entry = std::make_unique<ValueInfo>(std::move(entry));
            nc.input_infos[i] = nc.mapped_entry.get();
        } else {
            nc.input_infos[i] = &have;
        }
        nc.planned.inputs[i] = key;
    }

    /// The literal of each parameter: spec arguments, then overrides on top.
    void gather_params(NodeCheck& nc) {
        const auto& call = nc.st.call;
        const NodeDescriptor* node = nc.node;
        std::vector<std::string> param_names;
        for (const auto& p : node->params) param_names.push_back(p.name);
        for (const auto& arg : call.params) {
            const Param* p = node->find_param(arg.key);
            if (!p) {
                std::string msg = call.qualified() + " has no parameter '" + arg.key + "'";
                const std::string guess = spec::closest(arg.key, param_names);
                msg += guess.empty() ? "; `orogen help " + call.qualified() + "` lists them"
                                     : "; did you mean '" + guess + "'?";
                diags_.error(arg.key_where, msg);
                continue;
            }
            if (nc.literals.count(arg.key)) {
                diags_.error(arg.key_where, "'" + arg.key + "' is set twice in this call");
                nc.invalid.insert(arg.key);
                continue;
            }
            nc.literals[arg.key] = &arg.value;
            nc.param_where[arg.key] = arg.value.where;
        }
        for (auto& o : overrides_) {
            if (o.o.target != nc.planned.label || !o.o.process.empty()) continue;  // a process's: check_body
            o.used = true;
            if (!node->find_param(o.o.param)) {
                std::string msg =
                    call.qualified() + " ('" + nc.planned.label + "') has no parameter '" + o.o.param + "'";
                const std::string guess = spec::closest(o.o.param, param_names);
                if (!guess.empty()) msg += "; did you mean '" + guess + "'?";
                diags_.error(o.o.param_where, msg);
                continue;
            }
            nc.literals[o.o.param] = &o.o.value;
            nc.param_where[o.o.param] = o.o.value.where;
        }
    }

    /// Each parameter converted and range-checked on its own; one that fails is marked invalid.
    void convert_params(NodeCheck& nc) {
        const auto& call = nc.st.call;
        for (const auto& p : nc.node->params) {
            auto it = nc.literals.find(p.name);
            if (it == nc.literals.end()) {
                if (p.required()) {
                    diags_.error(call.where,
                                 call.qualified() + " needs parameter '" + p.name + "'" +
                                     (p.help_text.empty() ? "" : " (" + p.help_text + ")"));
                    nc.invalid.insert(p.name);
                } else {
                    nc.planned.params[p.name] = p.default_value;
                }
                continue;
            }
            auto v = convert(p, *it->second, call.qualified(), diags_);
            if (!v) {
                nc.invalid.insert(p.name);
                continue;
            }
            nc.planned.params[p.name] = std::move(*v);
            nc.planned.given.insert(p.name);
        }
    }

    /// Every valid path parameter: inputs exist, outputs have an allowed extension, stay in --out, and are
    /// written by one node.
    void check_paths(NodeCheck& nc) {
        for (const auto& p : nc.node->params) {
            if (p.type != ParamType::path || nc.invalid.count(p.name)) continue;
            auto it = nc.planned.params.find(p.name);
            if (it == nc.planned.params.end() || !std::holds_alternative<std::string>(it->second)) continue;
            const std::string& value = std::get<std::string>(it->second);
            const Location where = nc.param_where.count(p.name) ? nc.param_where[p.name] : nc.st.call.where;
            const bool ok =
                p.path_role == PathRole::input ? input_path_ok(value, where) : output_path_ok(nc, p, value, where);
            if (!ok) nc.invalid.insert(p.name);
        }
    }

    bool input_path_ok(const std::string& value, const Location& where) {
        const fs::path resolved = fs::path(value).is_absolute() ? fs::path(value) : plan_.spec_folder / value;
        std::error_code ec;
        if (!fs::exists(resolved, ec)) {
            diags_.error(where,
                         "no such file: " + value +
                             (fs::path(value).is_absolute() ? std::string()
                                                            : " (looked for " + resolved.string() +
                                      "; input paths are relative to the spec's folder)"));
            return false;
        }
        if (const std::string problem = regular_file_problem(resolved); !problem.empty()) {
            diags_.error(where, value + " " + problem);
            return false;
        }
        return true;
    }

    bool output_path_ok(NodeCheck& nc, const Param& p, const std::string& value, const Location& where) {
        const std::string node_name = nc.st.call.qualified();
        if (!p.choices.empty()) {
            bool ok = false;
            std::string list;
            for (const auto& ext : p.choices) {
                ok = ok || has_extension(value, ext);
                list += (list.empty() ? "" : ", ") + ext;
            }
            if (!ok) {
                diags_.error(where, node_name + " writes " + list + " files; '" + value + "' has another extension");
                return false;
            }
        }
        const fs::path out(value);
        const OutputPlace place = place_output(options_.out_dir, value);
        if (!place.inside && !options_.allow_outside_out) {
            diags_.error(where, node_name + ": " + outside_out_message(options_.out_dir, value, place));
            return false;
        }
        if (out.is_absolute()) {
            std::error_code ec;
            if (!fs::is_directory(out.parent_path(), ec)) {
                diags_.error(where,
                             "cannot write " + value + ": folder " + out.parent_path().string() + " does not exist");
                return false;
            }
        }
        const std::string key = place.resolved.string();
        if (auto prev = output_files_.find(key); prev != output_files_.end()) {
            diags_.error(where,
                         "'" + value + "' is already written by the node on line " + std::to_string(prev->second.line) +
                             "; give each output its own path");
            return false;
        }
        output_files_.emplace(key, where);
        nc.planned.output_files.push_back(value);
        return true;
    }

    /// A loop node's body (NodeDescriptor::processes): each process known, its parameters checked as a
    /// node's are (with --set NAME.PROCESS.PARAM=VALUE on top), its own check hook run, then the fields
    /// wired: every field a process reads is made by the node or by a process before it, and one process
    /// writes each field.
    void check_body(NodeCheck& nc) {
        const auto& call = nc.st.call;
        if (!nc.node->processes) {
            if (call.has_body)
                diags_.error(call.body_where,
                             call.qualified() +
                                 " takes no processes: only a loop node (erode:evolve) takes a body "
                                 "of processes in braces after its call");
            return;
        }
        if (!call.has_body) {
            diags_.error(call.where,
                         call.qualified() +
                             " runs the processes given in braces after its call, one a line: end the line "
                             "with '{', then e.g. flow() and stream-power() on lines of their own, then '}'; "
                             "`orogen list process` shows the processes");
            return;
        }
        if (call.body.empty() && !call.body_broken)
            diags_.error(
                call.body_where,
                "the body of " + call.qualified() + " holds no processes; give one a line, e.g. stream-power()");
        std::map<std::string, int, std::less<>> count;
        bool all_known = true;
        for (const auto& ps : call.body) {
            NodeCheck::BodyProcess bp;
            bp.syntax = &ps;
            const int k = ++count[ps.name];
            bp.call.label = k > 1 ? ps.name + "#" + std::to_string(k) : ps.name;
            bp.call.process = registry_.find_process(ps.name);
            if (!bp.call.process) {
                report_unknown_process(ps);
                all_known = false;
                continue;
            }
            gather_process_params(nc, bp);
            convert_process_params(bp);
            nc.body.push_back(std::move(bp));
        }
        report_unmatched_process_overrides(nc);
        if (all_known && !call.body_broken) check_fields(nc);  // a broken line's process may be what is missing
        // A process's own check, once its parameters are all valid (an error in one is reported already).
        for (auto& bp : nc.body) {
            if (!bp.call.process->check || !bp.invalid.empty()) continue;
            ProcessCheckContextImpl ctx(plan_.grid, bp.call, nc.input_infos, bp.param_where, bp.syntax->where, diags_);
            try {
                bp.call.process->check(ctx);
            } catch (const std::exception& e) { diags_.error(bp.syntax->where, bp.call.label + ": " + e.what()); }
        }
        for (const auto& bp : nc.body) nc.planned.processes.push_back(bp.call);
    }

    void report_unknown_process(const spec::ProcessCallSyntax& ps) {
        std::vector<std::string> names;
        for (const auto* p : registry_.processes()) names.push_back(p->name);
        std::string msg = "unknown process '" + ps.name + "'";
        const std::string guess = spec::closest(ps.name, names);
        std::string node_of_that_name;
        for (const auto& n : all_nodes_)
            if (n.substr(n.find(':') + 1) == ps.name) node_of_that_name = n;
        if (!guess.empty()) msg += "; did you mean '" + guess + "'?";
        else if (!node_of_that_name.empty())
            msg += "; " + node_of_that_name + " is a node, not a process: run it on the loop's result, after it";
        else
            msg +=
                "; `orogen list process` shows the processes the loaded plugins provide (a process of your "
                "own: its folder in OROGEN_PLUGIN_PATH, docs/processes.md)";
        diags_.error(ps.where, msg);
    }

    void gather_process_params(NodeCheck& nc, NodeCheck::BodyProcess& bp) {
        const ProcessDescriptor* d = bp.call.process;
        std::vector<std::string> names;
        for (const auto& p : d->params) names.push_back(p.name);
        auto unknown = [&](const std::string& key, const Location& where) {
            std::string msg = "process " + bp.call.label + " has no parameter '" + key + "'";
            const std::string guess = spec::closest(key, names);
            msg += guess.empty() ? "; `orogen help " + d->name + "` lists them" : "; did you mean '" + guess + "'?";
            diags_.error(where, msg);
        };
        for (const auto& arg : bp.syntax->params) {
            if (!find_param(d->params, arg.key)) {
                unknown(arg.key, arg.key_where);
                continue;
            }
            if (bp.literals.count(arg.key)) {
                diags_.error(arg.key_where, "'" + arg.key + "' is set twice in this process");
                bp.invalid.insert(arg.key);
                continue;
            }
            bp.literals[arg.key] = &arg.value;
            bp.param_where[arg.key] = arg.value.where;
        }
        for (auto& o : overrides_) {
            if (o.o.target != nc.planned.label || o.o.process != bp.call.label) continue;
            o.used = true;
            if (!find_param(d->params, o.o.param)) {
                unknown(o.o.param, o.o.param_where);
                continue;
            }
            bp.literals[o.o.param] = &o.o.value;
            bp.param_where[o.o.param] = o.o.value.where;
        }
    }

    static const Param* find_param(const std::vector<Param>& params, std::string_view name) {
        for (const auto& p : params)
            if (p.name == name) return &p;
        return nullptr;
    }

    void convert_process_params(NodeCheck::BodyProcess& bp) {
        for (const auto& p : bp.call.process->params) {
            auto it = bp.literals.find(p.name);
            if (it == bp.literals.end()) {
                if (p.required()) {
                    diags_.error(bp.syntax->where,
                                 "process " + bp.call.label + " needs parameter '" + p.name + "'" +
                                     (p.help_text.empty() ? "" : " (" + p.help_text + ")"));
                    bp.invalid.insert(p.name);
                } else {
                    bp.call.params[p.name] = p.default_value;
                }
                continue;
            }
            auto v = convert(p, *it->second, "process " + bp.call.label, diags_);
            if (!v) {
                bp.invalid.insert(p.name);
                continue;
            }
            bp.call.params[p.name] = std::move(*v);
            bp.call.given.insert(p.name);
        }
    }

    /// --set NAME.PROCESS.PARAM for this node whose PROCESS is not in its body.
    void report_unmatched_process_overrides(NodeCheck& nc) {
        std::vector<std::string> labels;
        for (const auto& bp : nc.body) labels.push_back(bp.call.label);
        for (auto& o : overrides_) {
            if (o.used || o.o.target != nc.planned.label || o.o.process.empty()) continue;
            o.used = true;
            std::string msg = "'" + nc.planned.label + "' has no process '" + o.o.process + "'";
            const std::string guess = spec::closest(o.o.process, labels);
            if (!guess.empty()) msg += "; did you mean '" + guess + "'?";
            else {
                msg += "; its processes are:";
                for (const auto& l : labels) msg += " " + l;
            }
            diags_.error(o.o.process_where, msg);
        }
    }

    /// The fields' wiring, in the body's order.
    void check_fields(NodeCheck& nc) {
        std::set<std::string, std::less<>> made = {kElevation, kUplifted};  // the node makes these
        std::map<std::string, const NodeCheck::BodyProcess*, std::less<>> writer;
        std::multimap<std::string, const NodeCheck::BodyProcess*, std::less<>> optional_readers;
        for (const auto& bp : nc.body) {
            for (const auto& f : bp.call.process->fields) {
                switch (f.access) {
                    case FieldAccess::reads:
                    case FieldAccess::updates:
                        if (!made.count(f.field)) report_missing_field(bp, f);
                        break;
                    case FieldAccess::reads_if_present:
                        if (!made.count(f.field)) optional_readers.emplace(f.field, &bp);
                        break;
                    case FieldAccess::writes:
                        if (auto it = writer.find(f.field); it != writer.end())
                            diags_.error(bp.syntax->where,
                                         bp.call.label + " writes '" + f.field + "', which " + it->second->call.label +
                                             " (line " + std::to_string(it->second->syntax->where.line) +
                                             ") writes too: a field has one writer; remove one of them, or use a "
                                             "process that adds to the field");
                        writer.emplace(f.field, &bp);
                        made.insert(f.field);
                        break;
                    case FieldAccess::adds: made.insert(f.field); break;
                }
                if (f.access == FieldAccess::writes || f.access == FieldAccess::adds) {
                    auto [b, e] = optional_readers.equal_range(f.field);
                    for (auto it = b; it != e; ++it)
                        diags_.warning(it->second->syntax->where,
                                       it->second->call.label + " uses '" + f.field + "' when it is made, but " +
                                           bp.call.label + ", which makes it, comes after it: " +
                                           it->second->call.label + " sees the last sub-step's; move " + bp.call.label +
                                           " before " + it->second->call.label + " if it should see this one's");
                    optional_readers.erase(b, e);
                }
            }
        }
    }

    void report_missing_field(const NodeCheck::BodyProcess& bp, const FieldUse& f) {
        std::string makers;
        for (const auto* p : registry_.processes())
            for (const auto& g : p->fields)
                if (g.field == f.field && (g.access == FieldAccess::writes || g.access == FieldAccess::adds))
                    makers += std::string(makers.empty() ? "" : " or ") + p->name + "()";
        const std::string what = f.field == kFlowGraph ? "the flow graph ('flow')" : "'" + f.field + "'";
        diags_.error(bp.syntax->where,
                     bp.call.label + " " + std::string(to_string(f.access)) + " " + what +
                         (f.unit.empty() || f.field == kFlowGraph ? "" : " (" + f.unit + ")") +
                         ", which no process before it makes; " +
                         (makers.empty() ? "no loaded process makes it" : "add " + makers + " before it"));
    }

    /// What the node makes: by default the first heightmap input's info (or the grid's) plus declared layers,
    /// then whatever its check hook says; side values as declared.
    std::pair<ValueInfo, std::map<std::string, ValueInfo, std::less<>>> node_output(NodeCheck& nc) {
        const NodeDescriptor* node = nc.node;
        ValueInfo out;
        out.type = node->output;
        if (node->output == ValueType::heightmap) {
            const ValueInfo* base = nullptr;
            for (std::size_t i = 0; i < node->inputs.size() && !base; ++i)
                if (nc.input_infos[i] && node->inputs[i].type == ValueType::heightmap) base = nc.input_infos[i];
            if (base) {
                out = *base;
            } else {
                out.width = plan_.grid.width;
                out.height = plan_.grid.height;
                out.cell = plan_.grid.cell;
            }
            out.type = ValueType::heightmap;
            out.element = ValueType::none;  // the base may have been a series of heightmaps
            out.count = 0;
            for (const auto& l : node->adds_layers) out.layers.insert(l);
            for (const auto& p : nc.planned.processes)
                for (const auto& l : p.process->adds_layers) out.layers.insert(l);
        }
        // What the side values hold; a mapped node's hold nothing (it ran once per entry).
        std::map<std::string, ValueInfo, std::less<>> sides;
        for (const auto& side : node->side_outputs) {
            ValueInfo si;
            si.type = nc.planned.mapped_input >= 0 ? ValueType::none : side.series ? ValueType::series : side.type;
            if (side.series && nc.planned.mapped_input < 0) si.element = side.type;
            sides[side.name] = si;
        }
        if (nc.inputs_ok && node->check) run_check_hook(nc, out, sides);
        // A series output: `out` describes its entries.
        if (node->output_series || nc.planned.mapped_input >= 0) {
            out.element = out.type;
            out.type = ValueType::series;
            if (nc.planned.mapped_input >= 0)
                out.count = values_[nc.planned.inputs[std::size_t(nc.planned.mapped_input)]].count;
        }
        return {std::move(out), std::move(sides)};
    }

    /// The node's own check, once everything it reads is known: it runs even if some parameters have errors
    /// (so its cross-parameter checks of the valid ones are reported too), and stops quietly where it reads
    /// a parameter with an error (that error was reported; a check on a wrong value would only add noise).
    void run_check_hook(NodeCheck& nc, ValueInfo& out, std::map<std::string, ValueInfo, std::less<>>& sides) {
        const auto& call = nc.st.call;
        CheckContextImpl ctx(plan_.grid, nc.input_infos, nc.planned, nc.param_where, call.where, plan_.spec_folder,
                             diags_, std::move(out), nc.invalid);
        ctx.set_sides(std::move(sides));
        ctx.set_tiled_share(options_.tiled_memory_share);
        ctx.set_process_error([&](std::size_t index, std::string_view param, std::string message) {
            if (index >= nc.body.size()) return diags_.error(call.where, call.qualified() + ": " + message);
            const auto& bp = nc.body[index];
            auto it = bp.param_where.find(param);
            diags_.error(it != bp.param_where.end() ? it->second : bp.syntax->where, bp.call.label + ": " + message);
        });
        try {
            nc.node->check(ctx);
        } catch (const InvalidParamRead&) {
            // stopped at a parameter whose error is already reported
        } catch (const std::exception& e) { diags_.error(call.where, call.qualified() + ": " + e.what()); }
        out = ctx.take_output();
        sides = ctx.take_sides();
    }

    void define_value(NodeCheck& nc, ValueInfo out, std::map<std::string, ValueInfo, std::less<>> sides) {
        const auto& st = nc.st;
        if (!st.name.empty()) {
            defined_at_.emplace(st.name, st.name_where);
            values_[st.name] = out;
            for (auto& [side, info] : sides) values_[st.name + "." + side] = std::move(info);
        } else if (st.nested) {
            values_[nc.planned.label] = out;
        }
        for (const auto& in : nc.planned.inputs)
            if (!in.empty()) plan_.last_use[in] = plan_.nodes.size();
        plan_.nodes.push_back(std::move(nc.planned));
    }

    void report_unused_overrides() {
        for (const auto& o : overrides_) {
            if (o.used ||
                std::find(parsed_.broken_names.begin(), parsed_.broken_names.end(), o.o.target) !=
                    parsed_.broken_names.end())
                continue;
            std::string msg = "--set names '" + o.o.target + "', but the spec has no value or node of that name";
            const std::string guess = spec::closest(o.o.target, labels_);
            if (!guess.empty()) msg += "; did you mean '" + guess + "'?";
            else msg += "; an unnamed node is set by its label in the timing table (kind:node, then kind:node#2, ...)";
            diags_.error(o.o.target_where, msg);
        }
    }

    /// A spec that writes nothing runs, and leaves only manifest.json: say so before it runs.
    void warn_if_nothing_is_written() {
        const bool writes = std::any_of(plan_.nodes.begin(), plan_.nodes.end(),
                                        [](const PlannedNode& n) { return !n.output_files.empty(); });
        if (diags_.has_errors() || writes) return;
        std::string last;  // the last named heightmap or image, for the example
        for (const auto& n : plan_.nodes)
            if (!n.value_name.empty() && n.value_name.find(':') == std::string::npos &&
                (n.node->output == ValueType::heightmap || n.node->output == ValueType::image))
                last = n.value_name;
        diags_.warning(Location{parsed_.source, 1, 1, 0},
                       "this spec writes no files: a run would leave only manifest.json; add an exporter, e.g. " +
                           (last.empty() ? std::string("export:png(NAME, path=\"NAME.png\")")
                                         : "export:png(" + last + ", path=\"" + last + ".png\")"));
    }

    const spec::Spec& parsed_;
    const Registry& registry_;
    const CheckOptions& options_;
    Diagnostics& diags_;
    const Location file_start_;
    Plan plan_;
    std::vector<PendingOverride> overrides_;
    std::map<std::string, ValueInfo, std::less<>> values_;  // value key → info
    std::map<std::string, Location, std::less<>> defined_at_;  // value name → statement
    std::map<std::string, Location, std::less<>> output_files_;  // output path → where
    std::map<std::string, int, std::less<>> unnamed_count_;
    std::set<std::string, std::less<>> poisoned_;  // names whose node is unknown
    std::vector<std::string> all_nodes_;
    std::map<std::string, Location, std::less<>> defined_anywhere_;  // for "'x' is defined later, on line N"
    std::vector<std::string> nested_key_;  // value key of each call written where an input goes (its label)
    std::vector<std::string> labels_;  // every node's label, for --set's "did you mean"
};

}  // namespace

Plan check(const spec::Spec& parsed, const Registry& registry, const fs::path& spec_path, const CheckOptions& options,
           Diagnostics& diags) {
    return Checker(parsed, registry, spec_path, options, diags).run();
}

std::string untiled_reason(const PlannedNode& node) {
    if (node.node->tile_halo < 0) return "it cannot be tiled";
    if (node.mapped_input >= 0) return "it is mapped over a series";
    std::vector<bool> given;
    for (const auto& key : node.inputs) given.push_back(!key.empty());
    if (node.node->untiled_because)
        if (std::string why = node.node->untiled_because(node.params, given); !why.empty()) return why;
    for (const auto& process : node.processes)
        if (process.process->tile_halo < 0) return "process " + process.label + " is not tiled";
    return node.node->untiled_body_because ? node.node->untiled_body_because(node.processes) : "";
}

}  // namespace orogen
