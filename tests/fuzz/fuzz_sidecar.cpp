// libFuzzer target: the RAW sidecar JSON parser (export:raw's <file>.json, read by import:raw).
#include <orogen/formats/raw.hpp>

#include <orogen/error.hpp>

#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        const auto s = orogen::formats::raw::parse_sidecar(std::string_view(reinterpret_cast<const char*>(data), size),
                                                           "fuzz.json");
        if (s.width < 1 || s.height < 1 || !(s.cell > 0) || s.range.high < s.range.low) __builtin_trap();
    } catch (const orogen::BadInput&) {}
    return 0;
}
