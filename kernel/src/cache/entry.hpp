// entry.hpp — inside the cache room: the fixed header of an entry file (docs/cache.md), shared by the
// entry codec (entry.cpp), the folder store (store.cpp, which reads headers alone) and the node key
// (key.cpp, which hashes the format version).
#pragma once

#include "cache.hpp"

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace orogen::cache {

inline constexpr char magic[8] = {'O', 'R', 'G', 'N', 'C', 'A', 'C', 'H'};
inline constexpr std::uint32_t format_version =
    3;  // 2: the payload sealed by XXH3-128 instead of SHA-256; 3: recorded files
inline constexpr std::size_t header_size =
    192;  // a multiple of 64, so arrays aligned in the payload are aligned in the file
inline constexpr std::size_t max_message_bytes = std::size_t(1) << 20;
inline constexpr std::size_t hash_block = std::size_t(1) << 20;  // bytes per block of the payload hash and checksum

// Header layout (little-endian):
//   0 magic[8]  8 u32 format  12 u32 header size  16 char orogen version[32]  48 u64 payload size
//   56 u8 payload checksum[32] (XXH3-128, then 16 zero bytes)  88 u8 key[32]  120 u32 messages  124 u32 files  128 u64 message bytes
//   136 u8 messages' SHA-256[32]  168 reserved (zero) to 192
// then the messages block (u32 count, strings), zero-padded to a multiple of 64, then the payload. The
// messages have their own hash so that a cached node's messages are replayed without reading its payload.
struct Header {
    std::uint32_t format = 0;
    std::string version;
    std::uint64_t payload_size = 0;
    Digest payload_hash{};
    Digest key{};
    std::uint32_t messages = 0, files = 0;
    std::uint64_t message_bytes = 0;
    Digest message_hash{};
    std::uint64_t payload_offset() const { return header_size + (message_bytes + 63) / 64 * 64; }
};

/// Parse the fixed header; throws CorruptEntry if it is not one.
Header read_header(std::span<const std::uint8_t> bytes);
/// Throws OtherVersion unless the entry was written by this orogen version and cache format.
void check_version(const Header& h);
/// The node's messages from the messages block, checked against the header's hash; throws CorruptEntry.
std::vector<std::string> read_messages(std::span<const std::uint8_t> block, const Header& h);

}  // namespace orogen::cache
