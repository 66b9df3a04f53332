// The node cache of `orogen run` (docs/cache.md): each node's result kept on
// disk under a key that hashes everything the result depends on, so that a
// re-run after a small change recomputes only the nodes downstream of it.
//
// Keys form a Merkle chain over the graph: a node's key hashes its kind and
// name, the plugin's name and version, the orogen version, its resolved
// parameters, its own seed, the grid, and the keys of the values it reads (not
// the values themselves). So every key is known before anything runs, and a
// cached node whose result no node that runs needs is never even read.
//
// An entry is one file, `<folder>/<key hex>.orc`: a fixed header (magic,
// format version, orogen version, payload size, payload hash, the key), the
// node's messages (with their own hash) and a payload of raw little-endian
// arrays (the values, the files an export wrote). It is read with one mmap, its hash checked before
// anything is used, and written atomically (temporary name + rename), so a
// concurrent run never sees half an entry. LRU: a hit touches the entry's
// modification time; when the folder outgrows its limit the oldest entries go.
#pragma once

#include "io/digest.hpp"
#include "spec/plan.hpp"

#include <orogen/session.hpp>
#include <orogen/values.hpp>

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace orogen::cache {

using Digest = std::array<std::uint8_t, 32>;
std::string hex(const Digest& d);

/// Typed fields into the kernel's one SHA-256 (io/digest.hpp: OpenSSL underneath, which uses the CPU's
/// SHA instructions where there are some). Fields are length-prefixed so that ("ab", "c") and ("a", "bc")
/// hash differently.
class Hasher {
public:
    Hasher& bytes(const void* data, std::size_t n);
    Hasher& u64(std::uint64_t v);
    Hasher& f64(double v);  ///< the bit pattern, so 0.1 and 0.1000000001 differ
    Hasher& text(std::string_view s);
    Hasher& digest(const Digest& d) { return bytes(d.data(), d.size()); }
    Digest finish() { return sha_.bytes(); }

private:
    detail::Sha256 sha_;
};

/// The identity of the loaded binary (executable or shared library) whose code holds `address`: its GNU
/// build-id ("build-id:<hex>", read from the ELF note in memory: free, and it changes whenever the linked
/// code does), else the SHA-256 of its file ("sha256:<hex>", computed once per binary and process); "" if
/// neither can be had (no such binary, or its file is gone).
std::string binary_identity(const void* address);
/// The identity of the orogen kernel library itself (binary_identity of its code), once per process.
const std::string& kernel_identity();

/// A node's key: its kind and name, its plugin's name, version and binary identity, the orogen version,
/// the kernel's binary identity and the cache format, every resolved parameter, its seed, the grid, which
/// input it is mapped over, and the keys of its inputs (nullopt for an optional input not given). `inputs`
/// must all be known.
Digest node_key(const Plan& plan, const PlannedNode& node, const std::vector<std::optional<Digest>>& inputs,
                std::string_view plugin_name, std::string_view plugin_version, std::string_view plugin_identity,
                std::uint64_t seed);
/// The key of output `name` ("" the main value) of a node with key `node`.
Digest output_key(const Digest& node, std::string_view name);
/// The key of an output of a node that always runs: what it produced decides, not how.
Digest content_key(const Digest& node, std::string_view name, const Digest& content);
/// The key of a value the caller bound to a run (run/runner.hpp BoundValues): its content (value_hash)
/// alone, as for what an importer read; its name is not in it (the node that reads it is keyed by its
/// own label and parameters).
Digest bound_key(const Digest& content);

/// The content hash of a payload (value_hash): SHA-256 over the SHA-256 of each 1 MiB block and the
/// payload's length, so that every core hashes a part.
Digest payload_hash(std::span<const std::uint8_t> payload);
/// The checksum that seals an entry's payload against damage (docs/cache.md): XXH3-128 of each 1 MiB block,
/// then of the payload's length and those block checksums; in the first 16 bytes, the rest zero. Not a
/// cryptographic hash, and need not be: it sits in the same file as what it checks, so it catches damage
/// (a flipped bit, a torn write), not forgery, which SHA-256 in that place would not stop either.
Digest payload_checksum(std::span<const std::uint8_t> payload);

/// What a cached node produced.
struct Contents {
    /// Output name ("" the main value, else the side value's name) → value. Series are never stored:
    /// they are made on demand by a function, and a 300-frame film would cost gigabytes to keep.
    std::vector<std::pair<std::string, Value>> values;
    /// Files the node wrote, relative to the output folder, and their bytes (small files: see `recorded`).
    std::vector<std::pair<std::string, std::vector<std::uint8_t>>> files;
    /// Files the node wrote that are too large to be worth a copy in the cache (docs/cache.md): only their
    /// path, size and SHA-256 are kept. A re-run finds them in --out or runs the node again.
    struct Recorded {
        std::string path;  ///< relative to the output folder
        std::uint64_t bytes = 0;
        std::string sha256;  ///< 64 lowercase hex digits
        bool operator==(const Recorded&) const = default;
    };
    std::vector<Recorded> recorded;
    /// What the node said while it ran ("warning: ..."), replayed when its result is reused.
    std::vector<std::string> messages;
};

/// True if `type` can be kept in an entry.
bool storable(ValueType type);

/// Serialize into one buffer: header + payload, as written to disk.
std::vector<std::uint8_t> encode(const Digest& key, const Contents& contents);
/// Where encode_into() puts an entry: `append` gets its bytes in order (the header as zeros first), then
/// `header` the real first header_size bytes, once the payload's size and checksum are known.
struct EntrySink {
    std::function<void(std::span<const std::uint8_t>)> append;
    std::function<void(std::span<const std::uint8_t>)> header;
};
/// The same bytes as encode(), streamed: at most 8 MiB of the payload is held at a time. Returns the size.
std::uint64_t encode_into(const Digest& key, const Contents& contents, const EntrySink& sink);
/// About how large an entry of `contents` is (bytes), before encoding it.
std::size_t estimated_size(const Contents& contents);
/// Parse a whole entry. Throws CorruptEntry (damaged, truncated, wrong hash) or OtherVersion.
Contents decode(std::span<const std::uint8_t> entry, const Digest& key);

/// Make `entry` pass every check of decode() under `key` but the payload's own validity: set the magic,
/// format, version and key, clamp the messages block to what is there, and recompute the sizes, the messages'
/// hash and the payload checksum. For the tests and the fuzz target (tests/fuzz/fuzz_cache.cpp), so that
/// hand-made or mutated payloads reach the parser instead of stopping at the checksum.
void reseal(std::vector<std::uint8_t>& entry, const Digest& key);

/// The content hash of one value (its payload's hash), for values made by nodes that always run.
Digest value_hash(const Value& value);

struct CorruptEntry : std::runtime_error {
    using std::runtime_error::runtime_error;
};
struct OtherVersion : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// Header facts read without touching the payload.
struct EntryInfo {
    std::uint64_t bytes = 0;  ///< whole file
    std::uint32_t messages = 0;  ///< messages the node printed
    std::uint32_t files = 0;  ///< files it wrote (kept or recorded)
    std::vector<std::string> texts;  ///< the messages (read and checked with the header: no payload needed)
};

// Settings, default_folder, parse_size, folder_facts and clear_folder: <orogen/session.hpp> (the front door).

/// A cache folder in use. Every problem is one line to `warn`, never an error:
/// the run goes on, without the cache if the folder cannot be used.
class Store {
public:
    /// Creates the folder if needed and checks it is writable; if not, warns and `usable()` is false.
    Store(Settings settings, std::function<void(const std::string&)> warn);

    bool usable() const { return usable_; }
    const std::filesystem::path& folder() const { return settings_.folder; }
    /// The size limit of this run (--cache-size).
    std::uint64_t max_bytes() const { return settings_.max_bytes; }
    std::filesystem::path path(const Digest& key) const;

    /// The entry's header, if an entry of this orogen version exists (one small read). An entry left
    /// by another orogen version or format is ignored (nullopt) with a note.
    std::optional<EntryInfo> probe(const Digest& key, const std::string& what);
    /// The entry's contents, its hash checked; nullopt (with a one-line warning naming `what`) if it is
    /// missing, damaged or truncated: the caller recomputes. A damaged entry is removed. A hit touches
    /// the entry (LRU).
    std::optional<Contents> load(const Digest& key, const std::string& what);
    /// Keep `contents` under `key` (temporary file + rename), then evict the least recently used entries
    /// beyond the size limit. Returns false (having warned once) if it could not be written.
    bool save(const Digest& key, const Contents& contents);

    /// Bytes of all entries now in the folder.
    std::uint64_t total_bytes() const;
    /// Remove least recently used entries (oldest modification time first) until the folder holds at
    /// most `limit` bytes; temporaries of killed runs older than an hour go too.
    void evict(std::uint64_t limit);

private:
    Settings settings_;
    std::function<void(const std::string&)> warn_;
    bool usable_ = false;
    bool save_failed_ = false;
};

}  // namespace orogen::cache
