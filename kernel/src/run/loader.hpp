// Finds and loads plugins with Boost.DLL, and fills the registry.
//
// Search order: the folder beside the binary (<bin>/../lib/orogen/plugins:
// the build tree and an installed tree look the same), the install prefix's
// plugin folder, then each entry of OROGEN_PLUGIN_PATH (':'-separated folders
// or .so files). A library that cannot be loaded, has no entry point, or was
// built for another plugin API version is refused with a message naming the
// file (and both versions); the others still load.
#pragma once

#include <orogen/session.hpp>

#include <orogen/plugin.hpp>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace orogen {

class PluginSet {
public:
    PluginSet();
    ~PluginSet();
    PluginSet(const PluginSet&) = delete;
    PluginSet& operator=(const PluginSet&) = delete;

    /// Load every plugin found from `exe` (the running binary's path) and the environment.
    void load_all(const std::filesystem::path& exe);
    /// Load one library; problems are recorded, never thrown.
    void load(const std::filesystem::path& file);

    const Registry& registry() const;
    const std::vector<PluginRecord>& plugins() const;
    /// Problems met while loading (one line each, naming the file).
    std::vector<std::string> problems() const;
    /// The folders searched, in order.
    const std::vector<std::filesystem::path>& searched() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace orogen
