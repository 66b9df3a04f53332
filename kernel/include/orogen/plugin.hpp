// orogen/plugin.hpp — the one seam between the kernel and a plugin.
//
// A plugin is a shared library exporting one `extern "C"` function,
// `orogen_plugin_info`, that returns a plain struct: the plugin API version it
// was built against, its name and version, and a callback that adds its nodes
// to the registry. (The model is LLVM's llvmGetPassPluginInfo.) The kernel
// refuses a library whose API version differs from its own, naming the file
// and both versions, and goes on loading the others.
//
// Write a plugin with the macro:
//
//   #include <orogen/plugin.hpp>
//   OROGEN_PLUGIN("generate-my-node", "1.0.0", registry) {  // id: kind-name
//       registry.add({ .kind = "generate", .name = "my-node", ... });
//   }
#pragma once

#include <orogen/node.hpp>
#include <orogen/process.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

/// Bumped whenever a public header changes in a way that breaks plugins built
/// against the previous one (layout of a shared type, a virtual function...).
/// 3: NodeDescriptor::cache (the node cache), NodeDescriptor::tile_halo and NodeContext::tiling() (MPI tiles).
/// 4: NodeDescriptor::tiled_timelapse, Timelapse's tiled constructor (its layout), Tiling::carry.
/// 5: NodeDescriptor::untiled_because, Tiling::exchange_double_halos and Tiling::gather_to_rank0.
/// 6: Tiling::scatter_from_rank0 (a series input of a tiled node stays on rank 0).
/// 7: Tiling in the shape of PETSc's DMDA (orogen/tiles.hpp): the ghost width is the node's tile_halo,
///    ghosted grids and one typed exchange, typed reductions with an operator, gather() to rank 0 or to
///    every rank, TiledFields for a grid eroder's tiled loop; six virtual primitives instead of twenty.
/// 8: Tiling::send_to_ranks (a seventh primitive: bytes to chosen ranks only) and Tiling::ranks_meeting.
/// 9: processes (orogen/process.hpp): Registry::add(ProcessDescriptor), NodeDescriptor::processes,
///    NodeDescriptor::untiled_body_because, NodeContext::processes() and CheckContext::processes().
#define OROGEN_PLUGIN_API_VERSION 9

namespace orogen {

/// The node table. Plugins add to it; the kernel reads it.
class Registry {
public:
    Registry();
    ~Registry();
    Registry(const Registry&) = delete;
    Registry& operator=(const Registry&) = delete;

    /// Add a node. A second node with the same kind:name is refused (the
    /// error names both plugins' files); the first one stays.
    void add(NodeDescriptor node);

    /// Add a process (a part of a loop node's body). A second process with the same name is refused.
    void add(ProcessDescriptor process);

    const NodeDescriptor* find(std::string_view qualified_name) const;
    const ProcessDescriptor* find_process(std::string_view name) const;
    /// All processes, sorted by name.
    std::vector<const ProcessDescriptor*> processes() const;
    /// All nodes, sorted by kind then name.
    std::vector<const NodeDescriptor*> nodes() const;
    /// The file of the plugin that registered `qualified_name` ("" if built in); for a process, its name.
    std::string provider(std::string_view qualified_name) const;

    /// Set by the loader while a plugin's callback runs.
    void set_current_plugin(std::string plugin_name, std::string file);
    /// Errors met while adding (duplicates, malformed descriptors).
    const std::vector<std::string>& errors() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace orogen

extern "C" {

/// What a plugin returns from `orogen_plugin_info`.
struct OrogenPluginInfo {
    std::uint32_t api_version;  ///< OROGEN_PLUGIN_API_VERSION at build time
    const char* plugin_name;  ///< kebab-case
    const char* plugin_version;  ///< the plugin's own version, free form ("1.2.0")
    void (*register_nodes)(orogen::Registry& registry);
};

/// The entry point's type; its symbol name is "orogen_plugin_info".
typedef OrogenPluginInfo (*OrogenPluginInfoFn)(void);
}

#define OROGEN_PLUGIN_ENTRY_SYMBOL "orogen_plugin_info"

#define OROGEN_PLUGIN(NAME, VERSION, REGISTRY)                                                    \
    static void orogen_register_nodes_(orogen::Registry& REGISTRY);                               \
    extern "C" __attribute__((visibility("default"))) OrogenPluginInfo orogen_plugin_info(void) { \
        return {OROGEN_PLUGIN_API_VERSION, NAME, VERSION, &orogen_register_nodes_};               \
    }                                                                                             \
    static void orogen_register_nodes_(orogen::Registry& REGISTRY)
