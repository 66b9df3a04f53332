// libFuzzer target: the description of a .f32 grid (NAME.json: nx, ny, dx_m or lat0/dlat/dlon), read by
// import:f32 and so by `orogen analyze` on whatever file a user hands it.
#include "f32_reader.hpp"

#include <orogen/error.hpp>

#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        const auto d =
            orogen::f32::parse_description(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.json");
        // What the reader relies on: a size it can multiply, a cell that is 0 (none given) or a sane length.
        if (d.width < 1 || d.height < 1 || d.width > 10'000'000 || d.height > 10'000'000 || !(d.cell >= 0.0) ||
            d.cell > 1e6)
            __builtin_trap();
    } catch (const orogen::BadInput&) {}
    return 0;
}
