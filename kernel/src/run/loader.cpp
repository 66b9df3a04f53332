#include "loader.hpp"

#include "cache/cache.hpp"

#include <boost/dll/shared_library.hpp>

#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>
#include <set>

namespace fs = std::filesystem;

namespace orogen {

struct PluginSet::Impl {
    // Declared before the registry: destroyed after it, since the registry's
    // descriptors hold functions that live in these libraries.
    std::vector<boost::dll::shared_library> libraries;
    Registry registry;
    std::vector<PluginRecord> plugins;
    std::vector<std::string> problems;
    std::vector<fs::path> searched;
    std::set<std::string> loaded_files;
};

PluginSet::PluginSet() : impl_(std::make_unique<Impl>()) {}
PluginSet::~PluginSet() = default;  // Impl's members die in reverse order: registry, then libraries

const Registry& PluginSet::registry() const { return impl_->registry; }
const std::vector<PluginRecord>& PluginSet::plugins() const { return impl_->plugins; }
const std::vector<fs::path>& PluginSet::searched() const { return impl_->searched; }
std::vector<std::string> PluginSet::problems() const {
    std::vector<std::string> all = impl_->problems;
    for (const auto& e : impl_->registry.errors()) all.push_back(e);
    return all;
}

void PluginSet::load(const fs::path& file) {
    std::error_code ec;
    const fs::path canonical = fs::weakly_canonical(file, ec);
    const std::string name = (ec ? file : canonical).string();
    if (!impl_->loaded_files.insert(name).second) return;

    boost::dll::shared_library lib;
    try {
        lib.load(boost::dll::fs::path(name), boost::dll::load_mode::rtld_now | boost::dll::load_mode::rtld_local);
    } catch (const std::exception& e) {
        impl_->problems.push_back(name + ": cannot load this library (" + e.what() + "); skipped");
        return;
    }
    if (!lib.has(OROGEN_PLUGIN_ENTRY_SYMBOL)) {
        impl_->problems.push_back(name +
                                  ": not an orogen plugin: it has no entry point '" OROGEN_PLUGIN_ENTRY_SYMBOL
                                  "' (define one with OROGEN_PLUGIN(...)); skipped");
        return;
    }
    OrogenPluginInfo info{};
    std::string identity;
    try {
        auto& entry = lib.get<OrogenPluginInfo()>(OROGEN_PLUGIN_ENTRY_SYMBOL);
        identity = cache::binary_identity(reinterpret_cast<const void*>(&entry));  // the code its nodes run
        info = entry();
    } catch (const std::exception& e) {
        impl_->problems.push_back(name + ": its entry point failed (" + e.what() + "); skipped");
        return;
    }
    const std::string plugin_name = info.plugin_name ? info.plugin_name : "?";
    const std::string plugin_version = info.plugin_version ? info.plugin_version : "?";
    if (info.api_version != OROGEN_PLUGIN_API_VERSION) {
        impl_->problems.push_back(name + ": wrong plugin API version in plugin '" + plugin_name + "': got version " +
                                  std::to_string(info.api_version) + ", supported version is " +
                                  std::to_string(OROGEN_PLUGIN_API_VERSION) +
                                  "; rebuild the plugin against this orogen's headers; skipped");
        return;
    }
    if (!info.register_nodes) {
        impl_->problems.push_back(name + ": plugin '" + plugin_name + "' has no registration callback; skipped");
        return;
    }
    for (const auto& p : impl_->plugins) {
        if (p.name == plugin_name) {
            impl_->problems.push_back(name + ": plugin '" + plugin_name + "' is already loaded from " + p.file +
                                      "; this copy is skipped");
            return;
        }
    }
    impl_->registry.set_current_plugin(plugin_name, name);
    try {
        info.register_nodes(impl_->registry);
    } catch (const std::exception& e) {
        impl_->problems.push_back(name + ": plugin '" + plugin_name + "' failed while registering its nodes (" +
                                  e.what() + "); the nodes it added before that are kept");
    } catch (...) {
        impl_->problems.push_back(name + ": plugin '" + plugin_name +
                                  "' failed while registering its nodes (unknown exception)");
    }
    impl_->registry.set_current_plugin("", "");
    impl_->plugins.push_back({plugin_name, plugin_version, name, identity});
    impl_->libraries.push_back(std::move(lib));
    // A plugin that registered nodes stays mapped until the process ends, even after its PluginSet is gone:
    // what its nodes keep in statics (the one GL context, VTK's, GDAL's and FFmpeg's singletons) is released
    // by destructors and atexit handlers that must still find their code, and LeakSanitizer can still see
    // those statics at exit instead of reporting their memory as leaked from an unmapped library.
    // (RTLD_NOLOAD: the library Boost.DLL loaded above, not a second copy.)
    if (void* pinned = dlopen(name.c_str(), RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE)) (void)pinned;
}

namespace {
std::vector<fs::path> libraries_in(const fs::path& folder) {
    std::vector<fs::path> out;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(folder, ec))
        if (entry.path().extension() == ".so" && !entry.is_directory()) out.push_back(entry.path());
    std::sort(out.begin(), out.end());  // a fixed order: the first of two duplicates always wins
    return out;
}
}  // namespace

void PluginSet::load_all(const fs::path& exe) {
    std::vector<fs::path> entries;
    std::error_code ec;
    const fs::path beside = (exe.parent_path() / ".." / OROGEN_PLUGIN_SUBDIR).lexically_normal();
    entries.push_back(beside);
    const fs::path installed = fs::path(OROGEN_INSTALL_PLUGIN_DIR).lexically_normal();
    if (fs::weakly_canonical(installed, ec) != fs::weakly_canonical(beside, ec)) entries.push_back(installed);
    if (const char* env = std::getenv("OROGEN_PLUGIN_PATH")) {
        std::string s = env;
        std::size_t start = 0;
        while (start <= s.size()) {
            const std::size_t end = std::min(s.find(':', start), s.size());
            if (end > start) entries.emplace_back(s.substr(start, end - start));
            start = end + 1;
        }
    }
    for (const auto& entry : entries) {
        if (fs::is_directory(entry, ec)) {
            impl_->searched.push_back(entry);
            for (const auto& lib : libraries_in(entry)) load(lib);
        } else if (fs::is_regular_file(entry, ec)) {
            impl_->searched.push_back(entry);
            load(entry);
        } else if (entry != installed) {
            if (entry == beside) continue;  // a binary copied elsewhere: only OROGEN_PLUGIN_PATH then
            impl_->problems.push_back(entry.string() + ": in OROGEN_PLUGIN_PATH, but no such folder or file");
        }
    }
}

}  // namespace orogen
