// A plugin built against a future API version: must be refused, naming both versions.
#include <orogen/plugin.hpp>

static void register_nothing(orogen::Registry&) {}
extern "C" __attribute__((visibility("default"))) OrogenPluginInfo orogen_plugin_info(void) {
    return {OROGEN_PLUGIN_API_VERSION + 1, "future-plugin", "9.0.0", &register_nothing};
}
