// libFuzzer target: the node cache's entry decoder (kernel/src/cache/entry.cpp, docs/cache.md).
//
// Each input is decoded twice: as it is (so the header, size and checksum checks are exercised) and resealed
// (cache::reseal sets the magic, version and key and recomputes the sizes and checksums, so mutations of the
// payload reach the parser instead of stopping at the checksum, as an entry written wrong would). A damaged or
// hostile entry must be refused with CorruptEntry or OtherVersion: never a crash, a read outside the input, or
// an allocation much larger than the input (run with -malloc_limit_mb). Whatever is accepted must hold values
// whose sizes agree, and encode to an entry that decodes to the same contents.
#include "cache/cache.hpp"

#include <orogen/values.hpp>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <vector>

using namespace orogen;

namespace {

void check_valid(const cache::Contents& c) {
    for (const auto& [name, v] : c.values) {
        switch (v.type()) {
            case ValueType::heightmap: {
                const Heightmap& hm = *v.heightmap();
                if (hm.heights().size() != hm.size() || !(hm.cell() > 0)) __builtin_trap();
                for (const auto& layer : hm.layer_names())
                    if (hm.layer(layer).size() != hm.size()) __builtin_trap();
                break;
            }
            case ValueType::image: {
                const Image& im = *v.image();
                const std::size_t samples = std::size_t(im.width) * std::size_t(im.height) * 4;
                if (im.width < 0 || im.height < 0) __builtin_trap();
                if ((im.format == Image::Format::rgba8 ? im.rgba8.size() : im.rgba32f.size()) != samples)
                    __builtin_trap();
                break;
            }
            case ValueType::particles:
                for (const auto& f : v.particles()->frames) {
                    const std::size_t n = f.attributes.empty() ? 0
                                                               : f.attributes.begin()->second.data.size() /
                            std::size_t(f.attributes.begin()->second.components);
                    for (const auto& [an, a] : f.attributes)
                        if (a.components < 1 || a.data.size() != n * std::size_t(a.components)) __builtin_trap();
                }
                break;
            case ValueType::plates:
                for (const auto& e : v.plates()->collisions)
                    if (int(e.kind) < 1 || int(e.kind) > 3) __builtin_trap();
                break;
            default: __builtin_trap();  // none and series are never kept
        }
    }
    const auto check_path = [](const std::string& path) {  // put back or looked for under --out: never outside it
        const std::filesystem::path rel(path);
        if (rel.empty() || rel.is_absolute()) __builtin_trap();
        for (const auto& part : rel)
            if (part == ".." || part.empty()) __builtin_trap();
    };
    for (const auto& [path, bytes] : c.files) check_path(path);
    for (const auto& f : c.recorded) {
        check_path(f.path);
        if (f.sha256.size() != 64) __builtin_trap();
        for (char ch : f.sha256)
            if (!((ch >= '0' && ch <= '9') || (ch >= 'a' && ch <= 'f'))) __builtin_trap();
    }
}

void try_decode(const std::vector<std::uint8_t>& entry, const cache::Digest& key) {
    cache::Contents c;
    try {
        c = cache::decode(entry, key);
    } catch (const cache::CorruptEntry&) { return; } catch (const cache::OtherVersion&) {
        return;
    }
    check_valid(c);
    const auto again = cache::encode(key, c);
    if (cache::encode(key, cache::decode(again, key)) != again) __builtin_trap();  // a round trip changes nothing
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    // The key the entry says it holds (offset 88), so a real entry passes the key check as it is.
    cache::Digest key{};
    if (size >= 120) std::memcpy(key.data(), data + 88, key.size());
    std::vector<std::uint8_t> entry(data, data + size);
    try_decode(entry, key);
    cache::reseal(entry, key);
    try_decode(entry, key);
    return 0;
}
