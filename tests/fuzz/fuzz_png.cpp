// libFuzzer target: the grayscale PNG reader (header checks, memory budget, chunk walk, libpng decode).
#include <orogen/error.hpp>
#include <orogen/io.hpp>

#include <cstdint>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::vector<std::uint8_t> bytes(data, data + size);
    try {
        const orogen::GrayImage header = orogen::decode_gray_png(bytes, "fuzz.png", true);
        const orogen::GrayImage image = orogen::decode_gray_png(bytes, "fuzz.png", false);
        if (image.width != header.width || image.height != header.height ||
            image.samples.size() != std::size_t(image.width) * std::size_t(image.height))
            __builtin_trap();  // the header and the decoded image disagree
    } catch (const orogen::BadInput&) {}
    return 0;
}
