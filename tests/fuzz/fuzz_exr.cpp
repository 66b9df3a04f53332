// libFuzzer target: the OpenEXR reader (import:exr): magic, OpenEXRCore's header parse under an allocation
// cap, the channel, size and chunk-layout checks, then the decode of every channel as heights or layers.
#include <orogen/exr/exr.hpp>

#include <orogen/error.hpp>

#include <cmath>
#include <cstdint>
#include <span>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::span<const std::uint8_t> bytes(data, size);
    orogen::exr::ReadOptions options;
    options.all_layers = true;
    options.cell = 1.0;
    try {
        const auto info = orogen::exr::probe_bytes(bytes, "fuzz.exr", options);
        const auto hm = orogen::exr::read_bytes(bytes, "fuzz.exr", options);
        // The header and the decoded heightmap agree, and what was read is what the checks promised.
        if (hm->width() != info.width || hm->height() != info.height || hm->heights().size() != hm->size())
            __builtin_trap();
        for (float v : hm->heights())
            if (!std::isfinite(v)) __builtin_trap();
        for (const auto& name : hm->layer_names()) {
            const auto* c = info.find(name);
            if (!c || c->type == orogen::exr::SampleType::uint32) __builtin_trap();
        }
    } catch (const orogen::BadInput&) {}
    return 0;
}
