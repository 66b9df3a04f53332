#include "plan.hpp"

#include "io/outputs.hpp"
#include "tiles/tiles.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
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
        return l.kind == Literal::Kind::word && (lower(l.text) == "nan" || lower(l.text) == "inf" ||
                                                 lower(l.text) == "infinity");
    };
    auto number = [&](const Literal& n, bool integer) -> std::optional<double> {
        if (n.kind != Literal::Kind::number) {
            if (n.kind == Literal::Kind::word && (lower(n.text) == "nan" || lower(n.text) == "inf" || lower(n.text) == "infinity")) {
                diags.error(n.where, who + " must be a finite number, got " + n.text);
                return std::nullopt;
            }
            diags.error(n.where, who + " must be " + (integer ? "an integer" : "a number") + ", got " + spec::describe(n));
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
            diags.error(n.where, who + " is " + n.text + ", out of range " + range_text(p) +
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
                diags.error(l.where, who + " takes at most " + std::to_string(p.max_points) + " points, got " +
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

class CheckContextImpl : public CheckContext {
public:
    CheckContextImpl(const GridSpec& grid, std::vector<const ValueInfo*> inputs, const PlannedNode& node,
                     const std::map<std::string, Location, std::less<>>& param_where, const Location& call_where,
                     const fs::path& spec_folder, Diagnostics& diags, ValueInfo output)
        : grid_(grid), inputs_(std::move(inputs)), node_(node), param_where_(param_where), call_where_(call_where),
          spec_folder_(spec_folder), diags_(diags), output_(std::move(output)) {}

    const GridSpec& grid() const override { return grid_; }
    double memory_share() const override { return TiledRun::runs_tiled(node_) ? tiled_share_ : 1.0; }
    void set_tiled_share(double share) { tiled_share_ = share; }
    const ValueInfo* input(std::size_t i) const override { return i < inputs_.size() ? inputs_[i] : nullptr; }
    bool given(std::string_view param) const override { return node_.given.count(param) > 0; }
    const ParamValue& param(std::string_view name) const override {
        auto it = node_.params.find(name);
        if (it == node_.params.end())
            throw Error("internal error: " + node_.node->qualified_name() + " has no parameter '" + std::string(name) + "'");
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
    }
    ValueInfo& output() override { return output_; }
    ValueInfo* side_output(std::string_view name) override {
        auto it = sides_.find(name);
        return it != sides_.end() ? &it->second : nullptr;
    }
    void set_sides(std::map<std::string, ValueInfo, std::less<>> sides) { sides_ = std::move(sides); }
    std::map<std::string, ValueInfo, std::less<>> take_sides() { return std::move(sides_); }
    int errors() const { return errors_; }
    ValueInfo take_output() { return std::move(output_); }

private:
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
    int errors_ = 0;
};

bool has_extension(const std::string& path, const std::string& ext) {
    return path.size() >= ext.size() && lower(path.substr(path.size() - ext.size())) == lower(ext);
}

}  // namespace

Plan check(const spec::Spec& parsed, const Registry& registry, const fs::path& spec_path, const CheckOptions& options,
           Diagnostics& diags) {
    Plan plan;
    plan.spec_path = spec_path;
    plan.spec_folder = spec_path.parent_path();  // "" for a spec in the current folder: paths stay as written
    plan.source = parsed.source;
    plan.overrides = options.overrides;
    const Location file_start{parsed.source, 1, 1, 1};

    // --- header statements
    if (!parsed.version) {
        diags.error(file_start, "a spec starts with its format version: add `orogen 1` as the first line");
    } else if (*parsed.version != 1) {
        diags.error(parsed.version_where, "format version " + std::to_string(*parsed.version) +
                                              " is not supported; this orogen reads `orogen 1`");
    }
    plan.seed = options.seed ? *options.seed : parsed.seed.value_or(0);
    plan.grid.width = parsed.grid_width;
    plan.grid.height = parsed.grid_height;
    plan.grid.cell = parsed.grid_cell;
    plan.grid_given = parsed.has_grid;
    plan.cell_given = parsed.has_cell;
    if (const std::string problem = heightmap_memory_problem(plan.grid.width, plan.grid.height,
                                                             options.heightmap_memory_limit);
        !problem.empty())
        diags.error(parsed.has_grid ? parsed.grid_where : file_start,
                    "grid " + std::to_string(plan.grid.width) + "x" + std::to_string(plan.grid.height) + " " + problem);

    // --- overrides: parse each, then find its statement
    struct PendingOverride {
        spec::Override o;
        bool used = false;
    };
    std::vector<PendingOverride> overrides;
    int override_order = 0;
    for (const auto& text : options.overrides) {
        auto src = std::make_shared<spec::Source>("--set " + text, text, ++override_order);
        if (auto o = spec::parse_override(src, diags)) overrides.push_back({std::move(*o)});
    }

    // --- nodes
    std::map<std::string, ValueInfo, std::less<>> values;          // value key → info
    std::map<std::string, Location, std::less<>> defined_at;       // value name → statement
    std::map<std::string, Location, std::less<>> output_files;     // output path → where
    std::map<std::string, int, std::less<>> unnamed_count;
    std::set<std::string, std::less<>> poisoned;                    // names whose node is unknown
    std::vector<std::string> all_nodes;
    for (const auto* n : registry.nodes()) all_nodes.push_back(n->qualified_name());
    // Where each name is defined, for "'x' is defined later, on line N".
    std::map<std::string, Location, std::less<>> defined_anywhere;
    for (const auto& st : parsed.statements)
        if (!st.name.empty()) defined_anywhere.emplace(st.name, st.name_where);
    // The value key of each call written where an input goes (its label: kind:node, kind:node#2, ...).
    std::vector<std::string> nested_key(parsed.statements.size());
    std::vector<std::string> labels;  // every node's label, for --set's "did you mean"

    for (std::size_t si = 0; si < parsed.statements.size(); ++si) {
        const auto& st = parsed.statements[si];
        const auto& call = st.call;
        const NodeDescriptor* node = registry.find(call.qualified());
        // Unnamed calls (exporters, and calls written where an input goes) are labelled kind:node, then
        // kind:node#2, #3...: the label seeds the node, and --set reaches it by its label.
        std::string label = st.name;
        if (st.name.empty()) {
            label = call.qualified();
            if (++unnamed_count[call.qualified()] > 1) label += "#" + std::to_string(unnamed_count[call.qualified()]);
        }
        labels.push_back(label);
        if (st.nested) nested_key[si] = label;
        if (st.name.size()) {
            if (auto it = defined_at.find(st.name); it != defined_at.end()) {
                diags.error(st.name_where, "'" + st.name + "' is already defined on line " +
                                               std::to_string(it->second.line) + "; give this value another name");
            }
        }
        if (!node) {
            std::string msg = "unknown node '" + call.qualified() + "'";
            const std::string guess = spec::closest(call.qualified(), all_nodes);
            if (!guess.empty()) msg += "; did you mean '" + guess + "'?";
            else msg += "; `orogen list` shows the nodes the loaded plugins provide";
            diags.error(call.where, msg);
            if (!st.name.empty() || st.nested) {
                if (!st.name.empty()) defined_at.emplace(st.name, st.name_where);
                values.emplace(label, ValueInfo{});  // so later uses do not also say "undefined"
                poisoned.insert(label);
            }
            continue;
        }

        PlannedNode planned;
        planned.node = node;
        planned.value_name = st.nested ? label : st.name;  // a label holds ':', so it never meets a name
        planned.in_place = st.nested;
        planned.label = label;
        planned.where = call.where;

        // Inputs
        bool inputs_ok = true;
        std::unique_ptr<ValueInfo> mapped_entry;  // what the check hook sees of a mapped series input
        std::vector<const ValueInfo*> input_infos(node->inputs.size(), nullptr);
        planned.inputs.assign(node->inputs.size(), "");
        if (call.inputs.size() > node->inputs.size()) {
            const auto& extra = call.inputs[node->inputs.size()];
            diags.error(extra.where, call.qualified() + " takes " +
                                         (node->inputs.empty() ? std::string("no inputs")
                                                               : "at most " + std::to_string(node->inputs.size()) +
                                                                     (node->inputs.size() == 1 ? " input" : " inputs")) +
                                         ", but '" + extra.full() + "' is input " +
                                         std::to_string(node->inputs.size() + 1));
            inputs_ok = false;
        }
        for (std::size_t i = 0; i < call.inputs.size() && i < node->inputs.size(); ++i) {
            const auto& in = call.inputs[i];
            const auto& want = node->inputs[i];
            const std::string key = in.statement >= 0 ? nested_key[std::size_t(in.statement)] : in.full();
            auto it = values.find(key);
            if (it == values.end()) {
                if (!in.side.empty() && values.count(in.name)) {
                    diags.error(in.where, "'" + in.name + "' has no side value '" + in.side + "'");
                } else {
                    std::vector<std::string> names;
                    for (const auto& [k, _] : values)
                        if (k.find(':') == std::string::npos) names.push_back(k);  // not the labels of calls in place
                    std::string msg = "'" + in.full() + "' is not defined";
                    if (auto later = defined_anywhere.find(in.name);
                        later != defined_anywhere.end() && defined_at.count(in.name) == 0) {
                        msg += " yet: it is defined later, on line " + std::to_string(later->second.line) +
                               "; move that line above this one (a node reads only values made before it)";
                    } else if (defined_at.count(in.name) == 0) {
                        const std::string guess = spec::closest(in.full(), names);
                        msg += guess.empty() ? "; define it with `" + in.name + " = kind:node(...)` on an earlier line"
                                             : "; did you mean '" + guess + "'?";
                    }
                    diags.error(in.where, msg);
                }
                inputs_ok = false;
                continue;
            }
            if (poisoned.count(in.statement >= 0 ? key : in.name)) {  // its node is unknown: that error was reported already
                inputs_ok = false;
                continue;
            }
            if (it->second.type == ValueType::none) {
                diags.error(in.where, "'" + in.full() + "' holds no value (its node only writes files)");
                inputs_ok = false;
                continue;
            }
            // One value, a series, or either; a series given for one value maps the node over it.
            const ValueInfo& have = it->second;
            const bool have_series = have.type == ValueType::series;
            const ValueType have_entry = have_series ? have.element : have.type;
            const bool maps = want.many == Many::one && have_series && node->output != ValueType::none &&
                              !node->output_series && planned.mapped_input < 0;
            // An input declared ValueType::none takes any value; the node's check hook says which it accepts.
            const bool fits = (want.type == ValueType::none || have_entry == want.type) &&
                              (want.many == Many::either || (want.many == Many::series) == have_series || maps);
            if (!fits) {
                std::string msg = call.qualified() + " input " + std::to_string(i + 1) + " ('" + want.name +
                                  "') must be a " + describe_type(want.type, want.many == Many::series) +
                                  (want.many == Many::either ? " or a " + describe_type(want.type, true) : "") +
                                  ", but '" + in.full() + "' is a " + describe_type(have_entry, have_series);
                if ((want.type == ValueType::none || have_entry == want.type) && want.many == Many::one && have_series)
                    msg += node->output == ValueType::none
                               ? " (a node that only writes files is not mapped over a series)"
                               : " (a node is mapped over one series input at a time)";
                diags.error(in.where, msg);
                inputs_ok = false;
                continue;
            }
            if (maps) {
                planned.mapped_input = int(i);
                ValueInfo entry = have;  // the node's check hook sees one entry
                entry.type = have.element;
                entry.element = ValueType::none;
                entry.count = 0;
                mapped_entry = std::make_unique<ValueInfo>(std::move(entry));
                input_infos[i] = mapped_entry.get();
            } else {
                input_infos[i] = &have;
            }
            planned.inputs[i] = key;
        }
        for (std::size_t i = call.inputs.size(); i < node->inputs.size(); ++i) {
            if (node->inputs[i].need == Need::required) {
                diags.error(call.where, call.qualified() + " needs input " + std::to_string(i + 1) + " ('" +
                                            node->inputs[i].name + "', a " +
                                            describe_type(node->inputs[i].type, node->inputs[i].many == Many::series) +
                                            "): " +
                                            call.qualified() + "(NAME, ...)");
                inputs_ok = false;
            }
        }

        // Parameters: spec arguments, then overrides on top.
        bool params_ok = true;
        std::map<std::string, Location, std::less<>> param_where;
        std::vector<std::string> param_names;
        for (const auto& p : node->params) param_names.push_back(p.name);
        std::map<std::string, const Literal*, std::less<>> literals;
        for (const auto& arg : call.params) {
            const Param* p = node->find_param(arg.key);
            if (!p) {
                std::string msg = call.qualified() + " has no parameter '" + arg.key + "'";
                const std::string guess = spec::closest(arg.key, param_names);
                msg += guess.empty() ? "; `orogen help " + call.qualified() + "` lists them"
                                     : "; did you mean '" + guess + "'?";
                diags.error(arg.key_where, msg);
                params_ok = false;
                continue;
            }
            if (literals.count(arg.key)) {
                diags.error(arg.key_where, "'" + arg.key + "' is set twice in this call");
                params_ok = false;
                continue;
            }
            literals[arg.key] = &arg.value;
            param_where[arg.key] = arg.value.where;
        }
        for (auto& o : overrides) {
            if (o.o.target != label) continue;
            o.used = true;
            const Param* p = node->find_param(o.o.param);
            if (!p) {
                std::string msg = call.qualified() + " ('" + label + "') has no parameter '" + o.o.param + "'";
                const std::string guess = spec::closest(o.o.param, param_names);
                if (!guess.empty()) msg += "; did you mean '" + guess + "'?";
                diags.error(o.o.param_where, msg);
                params_ok = false;
                continue;
            }
            literals[o.o.param] = &o.o.value;
            param_where[o.o.param] = o.o.value.where;
        }
        for (const auto& p : node->params) {
            auto it = literals.find(p.name);
            if (it == literals.end()) {
                if (p.required()) {
                    diags.error(call.where, call.qualified() + " needs parameter '" + p.name + "'" +
                                                (p.help_text.empty() ? "" : " (" + p.help_text + ")"));
                    params_ok = false;
                } else {
                    planned.params[p.name] = p.default_value;
                }
                continue;
            }
            auto v = convert(p, *it->second, call.qualified(), diags);
            if (!v) {
                params_ok = false;
                continue;
            }
            planned.params[p.name] = std::move(*v);
            planned.given.insert(p.name);
        }

        // Paths
        if (params_ok) {
            for (const auto& p : node->params) {
                if (p.type != ParamType::path) continue;
                auto it = planned.params.find(p.name);
                if (it == planned.params.end() || !std::holds_alternative<std::string>(it->second)) continue;
                const std::string& value = std::get<std::string>(it->second);
                const Location where = param_where.count(p.name) ? param_where[p.name] : call.where;
                if (p.path_role == PathRole::input) {
                    const fs::path resolved = fs::path(value).is_absolute() ? fs::path(value) : plan.spec_folder / value;
                    std::error_code ec;
                    if (!fs::exists(resolved, ec)) {
                        diags.error(where, "no such file: " + value +
                                               (fs::path(value).is_absolute() ? std::string()
                                                                              : " (looked for " + resolved.string() +
                                                                                    "; input paths are relative to the spec's folder)"));
                        params_ok = false;
                    } else if (const std::string problem = regular_file_problem(resolved); !problem.empty()) {
                        diags.error(where, value + " " + problem);
                        params_ok = false;
                    }
                } else {
                    if (!p.choices.empty()) {
                        bool ok = false;
                        std::string list;
                        for (const auto& ext : p.choices) {
                            ok = ok || has_extension(value, ext);
                            list += (list.empty() ? "" : ", ") + ext;
                        }
                        if (!ok) {
                            diags.error(where, call.qualified() + " writes " + list + " files; '" + value +
                                                   "' has another extension");
                            params_ok = false;
                            continue;
                        }
                    }
                    const fs::path out(value);
                    const OutputPlace place = place_output(options.out_dir, value);
                    if (!place.inside && !options.allow_outside_out) {
                        diags.error(where, call.qualified() + ": " + outside_out_message(options.out_dir, value, place));
                        params_ok = false;
                        continue;
                    }
                    if (out.is_absolute()) {
                        std::error_code ec;
                        if (!fs::is_directory(out.parent_path(), ec)) {
                            diags.error(where, "cannot write " + value + ": folder " + out.parent_path().string() +
                                                   " does not exist");
                            params_ok = false;
                            continue;
                        }
                    }
                    const std::string key = place.resolved.string();
                    if (auto prev = output_files.find(key); prev != output_files.end()) {
                        diags.error(where, "'" + value + "' is already written by the node on line " +
                                               std::to_string(prev->second.line) + "; give each output its own path");
                        params_ok = false;
                        continue;
                    }
                    output_files.emplace(key, where);
                    planned.output_files.push_back(value);
                }
            }
        }

        // Output info: by default, the first heightmap input's (or the grid), plus declared layers.
        ValueInfo out;
        out.type = node->output;
        if (node->output == ValueType::heightmap) {
            const ValueInfo* base = nullptr;
            for (std::size_t i = 0; i < node->inputs.size(); ++i)
                if (input_infos[i] && node->inputs[i].type == ValueType::heightmap) {
                    base = input_infos[i];
                    break;
                }
            if (base) {
                out = *base;
            } else {
                out.width = plan.grid.width;
                out.height = plan.grid.height;
                out.cell = plan.grid.cell;
            }
            out.type = ValueType::heightmap;
            out.element = ValueType::none;  // the base may have been a series of heightmaps
            out.count = 0;
            for (const auto& l : node->adds_layers) out.layers.insert(l);
        }

        // What the side values hold; a mapped node's hold nothing (it ran once per entry).
        std::map<std::string, ValueInfo, std::less<>> sides;
        for (const auto& side : node->side_outputs) {
            ValueInfo si;
            si.type = planned.mapped_input >= 0 ? ValueType::none : side.series ? ValueType::series : side.type;
            if (side.series && planned.mapped_input < 0) si.element = side.type;
            sides[side.name] = si;
        }
        // The node's own check, once everything it reads is known to be valid.
        if (inputs_ok && params_ok && node->check) {
            CheckContextImpl ctx(plan.grid, input_infos, planned, param_where, call.where, plan.spec_folder, diags,
                                 std::move(out));
            ctx.set_sides(std::move(sides));
            ctx.set_tiled_share(options.tiled_memory_share);
            try {
                node->check(ctx);
            } catch (const std::exception& e) {
                diags.error(call.where, call.qualified() + ": " + e.what());
            }
            out = ctx.take_output();
            sides = ctx.take_sides();
        }
        // A series output: `out` describes its entries.
        if (node->output_series || planned.mapped_input >= 0) {
            out.element = out.type;
            out.type = ValueType::series;
            if (planned.mapped_input >= 0) out.count = values[planned.inputs[std::size_t(planned.mapped_input)]].count;
        }

        if (!st.name.empty()) {
            defined_at.emplace(st.name, st.name_where);
            values[st.name] = out;
            for (auto& [side, info] : sides) values[st.name + "." + side] = std::move(info);
        } else if (st.nested) {
            values[label] = out;
        }
        for (const auto& in : planned.inputs)
            if (!in.empty()) plan.last_use[in] = plan.nodes.size();
        plan.nodes.push_back(std::move(planned));
    }

    for (const auto& o : overrides) {
        if (o.used) continue;
        std::string msg = "--set names '" + o.o.target + "', but the spec has no value or node of that name";
        const std::string guess = spec::closest(o.o.target, labels);
        if (!guess.empty()) msg += "; did you mean '" + guess + "'?";
        else msg += "; an unnamed node is set by its label in the timing table (kind:node, then kind:node#2, ...)";
        diags.error(o.o.target_where, msg);
    }

    // A spec that writes nothing runs, and leaves only manifest.json: say so before it runs.
    const bool writes = std::any_of(plan.nodes.begin(), plan.nodes.end(),
                                    [](const PlannedNode& n) { return !n.output_files.empty(); });
    if (!diags.has_errors() && !writes) {
        std::string last;  // the last named heightmap or image, for the example
        for (const auto& n : plan.nodes)
            if (!n.value_name.empty() && n.value_name.find(':') == std::string::npos &&
                (n.node->output == ValueType::heightmap || n.node->output == ValueType::image))
                last = n.value_name;
        diags.warning(Location{parsed.source, 1, 1, 0},
                      "this spec writes no files: a run would leave only manifest.json; add an exporter, e.g. " +
                          (last.empty() ? std::string("export:png(NAME, path=\"NAME.png\")")
                                        : "export:png(" + last + ", path=\"" + last + ".png\")"));
    }
    return plan;
}

}  // namespace orogen
