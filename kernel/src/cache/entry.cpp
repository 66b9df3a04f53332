// entry.cpp — one entry file: its header, messages and payload encoded, decoded (checksum checked on
// every core beside the copies) and resealed; the payload hash and checksum.

#include "entry.hpp"
#include "serialise.hpp"

#include <orogen/error.hpp>
#include <orogen/parallel.hpp>

#include <xxhash.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <filesystem>

namespace fs = std::filesystem;

namespace orogen::cache {

/// Parse the fixed header; throws CorruptEntry if it is not one.
Header read_header(std::span<const std::uint8_t> bytes) {
    if (bytes.size() < header_size)
        throw CorruptEntry("truncated: " + std::to_string(bytes.size()) + " bytes, shorter than its header");
    if (std::memcmp(bytes.data(), magic, sizeof magic) != 0) throw CorruptEntry("not a cache entry (wrong magic)");
    Header h;
    h.format = get<std::uint32_t>(bytes.data() + 8);
    const char* v = reinterpret_cast<const char*>(bytes.data() + 16);
    h.version.assign(v, strnlen(v, 32));
    h.payload_size = get<std::uint64_t>(bytes.data() + 48);
    std::memcpy(h.payload_hash.data(), bytes.data() + 56, 32);
    std::memcpy(h.key.data(), bytes.data() + 88, 32);
    h.messages = get<std::uint32_t>(bytes.data() + 120);
    h.files = get<std::uint32_t>(bytes.data() + 124);
    h.message_bytes = get<std::uint64_t>(bytes.data() + 128);
    std::memcpy(h.message_hash.data(), bytes.data() + 136, 32);
    if (h.message_bytes > max_message_bytes) throw CorruptEntry("its header is damaged (message size)");
    return h;
}

void check_version(const Header& h) {
    if (h.format != format_version || h.version != OROGEN_VERSION)
        throw OtherVersion("written by orogen " + h.version + " (cache format " + std::to_string(h.format) +
                           "); this is orogen " + OROGEN_VERSION + " (format " + std::to_string(format_version) + ")");
}

std::vector<std::string> read_messages(std::span<const std::uint8_t> block, const Header& h) {
    if (detail::sha256_of(block.data(), block.size()) != h.message_hash)
        throw CorruptEntry("its messages do not match their SHA-256");
    Reader r(block, 0);
    std::vector<std::string> out;
    const std::uint32_t n = r.u32();
    for (std::uint32_t i = 0; i < n; ++i) out.push_back(r.str());
    if (!r.at_end() || n != h.messages) throw CorruptEntry("its messages are damaged");
    return out;
}

namespace {

void write_payload(Writer& w, const Contents& c) {
    w.u32(std::uint32_t(c.values.size()));
    for (const auto& [name, v] : c.values) {
        w.str(name);
        write_value(w, v);
    }
    w.u32(std::uint32_t(c.files.size()));
    for (const auto& [path, bytes] : c.files) {
        w.str(path);
        w.array(bytes);
    }
    w.u32(std::uint32_t(c.recorded.size()));
    for (const auto& f : c.recorded) {
        w.str(f.path);
        w.u64(f.bytes);
        w.str(f.sha256);
    }
}

std::size_t hash_blocks(std::size_t payload_bytes) {
    return std::max<std::size_t>(1, (payload_bytes + hash_block - 1) / hash_block);
}

/// SHA-256 of block `b` of the payload.
Digest block_digest(std::span<const std::uint8_t> payload, std::size_t b) {
    const std::size_t begin = b * hash_block;
    const std::size_t n = std::min(hash_block, payload.size() - std::min(begin, payload.size()));
    return detail::sha256_of(payload.data() + begin, n);
}

/// XXH3-128 of block `b` of the payload, in the first 16 bytes.
Digest block_checksum(std::span<const std::uint8_t> payload, std::size_t b) {
    const std::size_t begin = b * hash_block;
    const std::size_t n = std::min(hash_block, payload.size() - std::min(begin, payload.size()));
    XXH128_canonical_t c;
    XXH128_canonicalFromHash(&c, XXH3_128bits(payload.data() + begin, n));
    Digest d{};
    std::memcpy(d.data(), c.digest, sizeof c.digest);
    return d;
}

Digest combine_checksums(std::size_t payload_bytes, const std::vector<Digest>& blocks) {
    std::vector<std::uint8_t> all(8 + 16 * blocks.size());
    put<std::uint64_t>(all.data(), payload_bytes);
    for (std::size_t b = 0; b < blocks.size(); ++b) std::memcpy(all.data() + 8 + 16 * b, blocks[b].data(), 16);
    XXH128_canonical_t c;
    XXH128_canonicalFromHash(&c, XXH3_128bits(all.data(), all.size()));
    Digest d{};
    std::memcpy(d.data(), c.digest, sizeof c.digest);
    return d;
}

Digest combine_blocks(std::size_t payload_bytes, const std::vector<Digest>& digests) {
    Hasher h;
    h.text("orogen cache payload").u64(payload_bytes);
    for (const auto& d : digests) h.digest(d);
    return h.finish();
}

/// Run `jobs` (each costs about `bytes`) on every core the run may use, largest first, each thread taking the
/// next job as it finishes one: a 16 MiB copy and sixteen 1 MiB hash blocks share two cores evenly.
void run_jobs(std::vector<Deferred::Copy>& jobs) {
    std::stable_sort(jobs.begin(), jobs.end(),
                     [](const Deferred::Copy& a, const Deferred::Copy& b) { return a.bytes > b.bytes; });
    const std::size_t workers = std::min<std::size_t>(jobs.size(), std::size_t(std::max(1, thread_count())));
    std::atomic<std::size_t> next{0};
    parallel_for(0, std::int64_t(workers), 1, [&](std::int64_t w0, std::int64_t w1) {
        for (std::int64_t w = w0; w != w1; ++w)
            for (std::size_t j = next++; j < jobs.size(); j = next++) jobs[j].run();
    });
}
}  // namespace

Digest payload_checksum(std::span<const std::uint8_t> payload) {
    std::vector<Digest> blocks(hash_blocks(payload.size()));
    parallel_for(0, std::int64_t(blocks.size()), 1, [&](std::int64_t b0, std::int64_t b1) {
        for (std::int64_t b = b0; b < b1; ++b) blocks[std::size_t(b)] = block_checksum(payload, std::size_t(b));
    });
    return combine_checksums(payload.size(), blocks);
}

Digest payload_hash(std::span<const std::uint8_t> payload) {
    std::vector<Digest> digests(hash_blocks(payload.size()));
    parallel_for(0, std::int64_t(digests.size()), 1, [&](std::int64_t b0, std::int64_t b1) {
        for (std::int64_t b = b0; b < b1; ++b) digests[std::size_t(b)] = block_digest(payload, std::size_t(b));
    });
    return combine_blocks(payload.size(), digests);
}

std::size_t estimated_size(const Contents& contents) {
    std::size_t bytes = header_size + 1024;
    for (const auto& [name, v] : contents.values) bytes += estimate(v) + name.size();
    for (const auto& [path, data] : contents.files) bytes += data.size() + path.size() + 128;
    for (const auto& f : contents.recorded) bytes += f.path.size() + f.sha256.size() + 32;
    for (const auto& m : contents.messages) bytes += m.size() + 8;
    return bytes;
}

std::uint64_t encode_into(const Digest& key, const Contents& contents, const EntrySink& sink) {
    // 1. The header (zeros for now) and the messages block, padded to 64 bytes.
    Writer head(header_size + 1024);
    head.buffer().resize(header_size, 0);
    head.u32(std::uint32_t(contents.messages.size()));
    for (const auto& m : contents.messages) head.str(m);
    const std::size_t message_bytes = head.buffer().size() - header_size;
    if (message_bytes > max_message_bytes) throw Error("the node printed more than 1 MiB of messages");
    head.buffer().resize((head.buffer().size() + 63) / 64 * 64, 0);
    const Digest messages = detail::sha256_of(head.buffer().data() + header_size, message_bytes);
    sink.append(head.buffer());
    // 2. The payload, streamed in whole hash blocks, each block's checksum taken on its way out (both cores).
    std::vector<Digest> blocks;
    Writer w(0);
    w.stream_to(hash_block, 8 * hash_block, [&](std::span<const std::uint8_t> piece) {
        const std::size_t first = blocks.size(), count = hash_blocks(piece.size());
        blocks.resize(first + count);
        parallel_for(0, std::int64_t(count), 1, [&](std::int64_t b0, std::int64_t b1) {
            for (std::int64_t b = b0; b < b1; ++b)
                blocks[first + std::size_t(b)] = block_checksum(piece, std::size_t(b));
        });
        sink.append(piece);
    });
    write_payload(w, contents);
    w.finish();
    const std::size_t payload_size = w.size();
    if (blocks.empty()) blocks.push_back(block_checksum({}, 0));  // an empty payload is one empty block
    // 3. The header, now that the payload's size and checksum are known.
    std::uint8_t* h = head.buffer().data();
    std::memcpy(h, magic, sizeof magic);
    put<std::uint32_t>(h + 8, format_version);
    put<std::uint32_t>(h + 12, header_size);
    std::strncpy(reinterpret_cast<char*>(h + 16), OROGEN_VERSION, 31);
    put<std::uint64_t>(h + 48, payload_size);
    const Digest ph = combine_checksums(payload_size, blocks);
    std::memcpy(h + 56, ph.data(), 32);
    std::memcpy(h + 88, key.data(), 32);
    put<std::uint32_t>(h + 120, std::uint32_t(contents.messages.size()));
    put<std::uint32_t>(h + 124, std::uint32_t(contents.files.size() + contents.recorded.size()));
    put<std::uint64_t>(h + 128, message_bytes);
    std::memcpy(h + 136, messages.data(), messages.size());
    sink.header(std::span<const std::uint8_t>(h, header_size));
    return head.buffer().size() + payload_size;
}

std::vector<std::uint8_t> encode(const Digest& key, const Contents& contents) {
    std::vector<std::uint8_t> out;
    out.reserve(estimated_size(contents));
    encode_into(key, contents,
                {[&](std::span<const std::uint8_t> bytes) { out.insert(out.end(), bytes.begin(), bytes.end()); },
                 [&](std::span<const std::uint8_t> header) { std::memcpy(out.data(), header.data(), header.size()); }});
    return out;
}

namespace {
/// Parse the payload into `c`, leaving the large copies in `deferred`.
void parse_payload(std::span<const std::uint8_t> entry, std::size_t offset, Contents& c, Deferred& deferred) {
    Reader r(entry, offset, &deferred);
    const std::uint32_t values = r.count32(9);  // a name's length and a type at least (the count bounds the reserve)
    c.values.reserve(values);
    for (std::uint32_t i = 0; i < values; ++i) {
        std::string name = r.str();
        c.values.emplace_back(std::move(name), read_value(r));
    }
    const auto check_path = [](const std::string& path) {
        const fs::path rel(path);
        if (rel.empty() || rel.is_absolute() || std::any_of(rel.begin(), rel.end(), [](const fs::path& part) {
                return part.empty() || part == ".." || part == ".";
            }))
            throw CorruptEntry("a kept file has a bad path ('" + path + "')");
    };
    const std::uint32_t files = r.count32(16);  // a path's length and an array's count at least
    c.files.resize(files);  // sized first: deferred copies write into these vectors where they stand
    for (auto& [path, bytes] : c.files) {
        path = r.str();
        check_path(path);
        r.array(bytes);
    }
    const std::uint32_t recorded = r.count32(24);  // a path's length, a size and a digest's length at least
    c.recorded.resize(recorded);
    for (auto& f : c.recorded) {
        f.path = r.str();
        check_path(f.path);
        f.bytes = r.u64();
        f.sha256 = r.str();
        if (f.sha256.size() != 64 || !std::all_of(f.sha256.begin(), f.sha256.end(), [](char ch) {
                return (ch >= '0' && ch <= '9') || (ch >= 'a' && ch <= 'f');
            }))
            throw CorruptEntry("a recorded file's SHA-256 is not 64 hex digits");
    }
    if (!r.at_end()) throw CorruptEntry("bytes left over after its contents");
}
}  // namespace

Contents decode(std::span<const std::uint8_t> entry, const Digest& key) {
    const Header h = read_header(entry);
    check_version(h);
    if (h.key != key) throw CorruptEntry("it holds another key (" + hex(h.key).substr(0, 12) + "...)");
    if (entry.size() < h.payload_offset() || h.payload_size != entry.size() - h.payload_offset())
        throw CorruptEntry("truncated: " + std::to_string(entry.size()) + " bytes, its header says " +
                           std::to_string(h.payload_offset() + h.payload_size));
    const auto payload = entry.subspan(h.payload_offset());
    Contents c;
    c.messages = read_messages(entry.subspan(header_size, h.message_bytes), h);
    // Parse first (every size checked against the payload, so a damaged entry cannot make us read outside it
    // or allocate more than its size), leaving the large copies for later; then the copies into fresh vectors
    // and the payload checksum run together on every core, each byte of a value written once; only if the
    // checksum matches are the values assembled and returned. So nothing of a damaged entry is ever used.
    Deferred deferred;
    try {
        parse_payload(entry, h.payload_offset(), c, deferred);
    } catch (const CorruptEntry&) {
        // Say why: damage (the checksum fails) rather than what the damage happened to break first.
        if (payload_checksum(payload) != h.payload_hash) throw CorruptEntry("its payload does not match its checksum");
        throw;  // sealed as written, yet not valid: written by something other than this orogen
    }

    std::vector<Digest> digests(hash_blocks(payload.size()));
    std::vector<Deferred::Copy> jobs = std::move(deferred.copies);
    jobs.reserve(jobs.size() + digests.size());
    for (std::size_t b = 0; b < digests.size(); ++b)
        jobs.push_back({std::min(hash_block, payload.size() - std::min(b * hash_block, payload.size())),
                        [&digests, payload, b] { digests[b] = block_checksum(payload, b); }});
    run_jobs(jobs);
    if (combine_checksums(payload.size(), digests) != h.payload_hash)
        throw CorruptEntry("its payload does not match its checksum");
    for (auto& assemble : deferred.after) assemble();
    return c;
}

void reseal(std::vector<std::uint8_t>& entry, const Digest& key) {
    if (entry.size() < header_size) entry.resize(header_size, 0);
    std::uint8_t* h = entry.data();
    std::memcpy(h, magic, sizeof magic);
    put<std::uint32_t>(h + 8, format_version);
    put<std::uint32_t>(h + 12, header_size);
    std::memset(h + 16, 0, 32);
    std::strncpy(reinterpret_cast<char*>(h + 16), OROGEN_VERSION, 31);
    std::memcpy(h + 88, key.data(), 32);
    // The messages block: as long as the header says, within the limit and within the entry.
    std::uint64_t message_bytes = get<std::uint64_t>(h + 128);
    message_bytes = std::min<std::uint64_t>({message_bytes, max_message_bytes, entry.size() - header_size});
    std::uint64_t payload_offset = header_size + (message_bytes + 63) / 64 * 64;
    if (payload_offset > entry.size()) entry.resize(payload_offset, 0);
    h = entry.data();
    put<std::uint64_t>(h + 128, message_bytes);
    put<std::uint32_t>(h + 120, message_bytes >= 4 ? get<std::uint32_t>(h + header_size) : 0);
    const Digest messages = detail::sha256_of(h + header_size, message_bytes);
    std::memcpy(h + 136, messages.data(), messages.size());
    const std::span<const std::uint8_t> payload(entry.data() + payload_offset, entry.size() - payload_offset);
    put<std::uint64_t>(h + 48, payload.size());
    const Digest sum = payload_checksum(payload);
    std::memcpy(h + 56, sum.data(), 32);
}

}  // namespace orogen::cache
