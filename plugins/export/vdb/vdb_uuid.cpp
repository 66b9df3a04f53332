// vdb_uuid.cpp — a .vdb file's UUID made from its content, so that the same
// data gives the same bytes (OpenVDB stamps every file it writes with a random
// UUID, which made every export differ from the last). No OpenVDB headers here.
#include "vdb_writer.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/random.hpp>

#include <array>
#include <cstdio>
#include <cstring>
#include <fstream>

namespace orogen::vdb {

namespace {
// OpenVDB's header (io::Archive::writeHeader): int64 magic, uint32 file version, uint32 library major
// and minor, one byte "has grid offsets", then the UUID as 36 ASCII characters.
constexpr std::size_t uuid_offset = 8 + 4 + 4 + 4 + 1;
constexpr std::size_t uuid_length = 36;
}  // namespace

void stamp_content_uuid(AtomicFile& file) {
    std::ofstream& out = file.stream();
    out.flush();
    if (!out) throw Error("cannot write " + file.target().string() + ": the disk refused the OpenVDB data");
    std::ifstream in(file.temporary(), std::ios::binary);
    std::array<char, uuid_offset + uuid_length> header{};
    if (!in.read(header.data(), std::streamsize(header.size())) || std::memcmp(header.data(), " BDV", 4) != 0 ||
        header[uuid_offset + 8] != '-' || header[uuid_offset + 13] != '-')
        throw Error("export:vdb: OpenVDB wrote a header this version of orogen does not know (" +
                    file.temporary().string() + "); cannot make its UUID reproducible");
    // Two independent 64-bit hashes of everything after the UUID, 64 KiB at a time.
    std::uint64_t a = 0x6f726f67656e2d31ull, b = 0x766462757569642dull, index = 0;
    std::array<char, 1 << 16> buffer;
    while (in.read(buffer.data(), std::streamsize(buffer.size())) || in.gcount() > 0) {
        const std::size_t n = std::size_t(in.gcount());
        for (std::size_t i = 0; i < n; i += 8) {
            std::uint64_t word = 0;
            std::memcpy(&word, buffer.data() + i, std::min<std::size_t>(8, n - i));
            a = random::hash(a, word, index);
            b = random::hash(b, word ^ 0x9E3779B97F4A7C15ull, index);
            ++index;
        }
    }
    // RFC 9562 version 8 (custom), variant 10: a UUID whose bits come from the content.
    b = (b & 0x3FFFFFFFFFFFFFFFull) | 0x8000000000000000ull;
    a = (a & 0xFFFFFFFFFFFF0FFFull) | 0x0000000000008000ull;
    char uuid[uuid_length + 1];
    std::snprintf(uuid, sizeof uuid, "%08x-%04x-%04x-%04x-%012llx", unsigned(a >> 32), unsigned((a >> 16) & 0xFFFF),
                  unsigned(a & 0xFFFF), unsigned(b >> 48), static_cast<unsigned long long>(b & 0xFFFFFFFFFFFFull));
    out.seekp(std::streamoff(uuid_offset));
    out.write(uuid, std::streamsize(uuid_length));
    out.seekp(0, std::ios::end);
}

}  // namespace orogen::vdb
