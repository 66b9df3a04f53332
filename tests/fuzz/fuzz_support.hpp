// Shared by the spec and override fuzz targets: parse and check a spec the way `orogen check` does,
// against the real plugins (loaded once, from the build tree).
#pragma once

#include "run/loader.hpp"
#include "spec/plan.hpp"
#include "spec/spec.hpp"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace orogen::fuzz {

inline const Registry& registry() {
    static PluginSet* plugins = [] {
        auto* p = new PluginSet;  // never destroyed: plugins stay loaded for the whole run
        std::error_code ec;
        p->load_all(std::filesystem::read_symlink("/proc/self/exe", ec));
        return p;
    }();
    return plugins->registry();
}

inline void check_spec(std::string text, const std::vector<std::string>& overrides) {
    auto source = std::make_shared<spec::Source>("fuzz.orogen", std::move(text));
    spec::Diagnostics diags;
    const spec::Spec parsed = spec::parse(source, diags);
    if (!diags.has_errors()) {
        CheckOptions options;
        options.overrides = overrides;
        options.out_dir = "fuzz-out";
        check(parsed, registry(), "fuzz.orogen", options, diags);
    }
    (void)diags.format();
}

}  // namespace orogen::fuzz
