#include <orogen/plugin.hpp>

#include <algorithm>
#include <cctype>
#include <map>

namespace orogen {

struct Registry::Impl {
    struct Entry {
        NodeDescriptor node;
        std::string plugin;
        std::string file;
    };
    std::map<std::string, Entry, std::less<>> nodes;
    struct ProcessEntry {
        ProcessDescriptor process;
        std::string plugin;
        std::string file;
    };
    std::map<std::string, ProcessEntry, std::less<>> processes;
    std::string current_plugin, current_file;
    std::vector<std::string> errors;
};

Registry::Registry() : impl_(std::make_unique<Impl>()) {}
Registry::~Registry() = default;

namespace {
bool is_kebab(std::string_view s) {
    if (s.empty() || !std::islower(static_cast<unsigned char>(s.front()))) return false;
    for (char c : s)
        if (!(std::islower(static_cast<unsigned char>(c)) || std::isdigit(static_cast<unsigned char>(c)) || c == '-'))
            return false;
    return s.back() != '-';
}
}  // namespace

void Registry::add(NodeDescriptor node) {
    const std::string where = impl_->current_file.empty() ? std::string("built-in") : impl_->current_file;
    const std::string qualified = node.qualified_name();
    auto refuse = [&](const std::string& why) {
        impl_->errors.push_back(where + ": node '" + qualified + "' refused: " + why);
    };
    static const char* kinds[] = {"generate", "erode", "tectonics", "render", "export", "import", "analyze"};
    if (std::find(std::begin(kinds), std::end(kinds), node.kind) == std::end(kinds))
        return refuse("unknown kind '" + node.kind +
                      "' (use generate, erode, tectonics, render, export, import or analyze)");
    if (!is_kebab(node.name)) return refuse("the name must be kebab-case (lowercase letters, digits, '-')");
    if (!node.run) return refuse("it has no run function");
    for (const auto& p : node.params) {
        if (p.name.empty()) return refuse("a parameter has no name");
        if (std::count_if(node.params.begin(), node.params.end(), [&](const Param& q) { return q.name == p.name; }) > 1)
            return refuse("parameter '" + p.name + "' is declared twice");
    }
    if (auto it = impl_->nodes.find(qualified); it != impl_->nodes.end()) {
        const auto& first = it->second;
        impl_->errors.push_back("node '" + qualified + "' is registered twice: by plugin '" + first.plugin + "' (" +
                                first.file + ") and by plugin '" + impl_->current_plugin + "' (" + where +
                                "); keeping the first. Duplicate library? Remove one of them from the plugin path.");
        return;
    }
    impl_->nodes.emplace(qualified, Impl::Entry{std::move(node), impl_->current_plugin, where});
}

void Registry::add(ProcessDescriptor process) {
    const std::string where = impl_->current_file.empty() ? std::string("built-in") : impl_->current_file;
    auto refuse = [&](const std::string& why) {
        impl_->errors.push_back(where + ": process '" + process.name + "' refused: " + why);
    };
    if (!is_kebab(process.name)) return refuse("the name must be kebab-case (lowercase letters, digits, '-')");
    if (!process.make) return refuse("it has no make function");
    for (const auto& p : process.params) {
        if (p.name.empty()) return refuse("a parameter has no name");
        if (p.type == ParamType::path)
            return refuse("parameter '" + p.name + "' is a path; processes read fields, not files");
        if (std::count_if(process.params.begin(), process.params.end(),
                          [&](const Param& q) { return q.name == p.name; }) > 1)
            return refuse("parameter '" + p.name + "' is declared twice");
    }
    for (const auto& f : process.fields)
        if (f.field.empty()) return refuse("a field has no name");
    if (auto it = impl_->processes.find(process.name); it != impl_->processes.end()) {
        const auto& first = it->second;
        impl_->errors.push_back("process '" + process.name + "' is registered twice: by plugin '" + first.plugin +
                                "' (" + first.file + ") and by plugin '" + impl_->current_plugin + "' (" + where +
                                "); keeping the first. Duplicate library? Remove one of them from the plugin path.");
        return;
    }
    const std::string name = process.name;
    impl_->processes.emplace(name, Impl::ProcessEntry{std::move(process), impl_->current_plugin, where});
}

const ProcessDescriptor* Registry::find_process(std::string_view name) const {
    auto it = impl_->processes.find(name);
    return it == impl_->processes.end() ? nullptr : &it->second.process;
}

std::vector<const ProcessDescriptor*> Registry::processes() const {
    std::vector<const ProcessDescriptor*> out;
    for (const auto& [_, e] : impl_->processes) out.push_back(&e.process);  // a map: sorted by name
    return out;
}

const NodeDescriptor* Registry::find(std::string_view qualified_name) const {
    auto it = impl_->nodes.find(qualified_name);
    return it == impl_->nodes.end() ? nullptr : &it->second.node;
}

std::vector<const NodeDescriptor*> Registry::nodes() const {
    std::vector<const NodeDescriptor*> out;
    for (const auto& [_, e] : impl_->nodes) out.push_back(&e.node);
    std::sort(out.begin(), out.end(),
              [](auto* a, auto* b) { return std::tie(a->kind, a->name) < std::tie(b->kind, b->name); });
    return out;
}

std::string Registry::provider(std::string_view qualified_name) const {
    if (auto it = impl_->nodes.find(qualified_name); it != impl_->nodes.end()) return it->second.file;
    auto p = impl_->processes.find(qualified_name);
    return p == impl_->processes.end() ? std::string() : p->second.file;
}

void Registry::set_current_plugin(std::string plugin_name, std::string file) {
    impl_->current_plugin = std::move(plugin_name);
    impl_->current_file = std::move(file);
}

const std::vector<std::string>& Registry::errors() const { return impl_->errors; }

}  // namespace orogen
