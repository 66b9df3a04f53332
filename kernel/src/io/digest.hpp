// digest.hpp — inside the kernel: SHA-256 taken while an output is written.
//
// An AtomicFile whose bytes all go through its stream, in order, hashes them
// on the way (io.cpp's HashingBuffer) and, when it commits, leaves the digest
// here keyed by the file's identity (device, inode, size, modification time).
// sha256_file() then answers from here instead of reading the file again: the
// manifest of a run with gigabytes of outputs costs no second pass over them.
// Anything that changes the file changes its identity, so a stale digest is
// never returned; files written by name (VTK, OpenVDB, GDAL) or with seeks are
// simply read back as before. The times are as fine as the file system's clock
// (a few ms on Linux): a rewrite in place, to the same size, within that time
// of the commit would go unseen. Nothing in a run rewrites an output in place
// (every output is a new file renamed over the old), and the staging folder
// the manifest hashes is the run's own.
#pragma once

#include <cstddef>
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

namespace orogen::detail {

/// Incremental SHA-256 (OpenSSL's EVP, which uses the CPU's SHA instructions).
/// SHA-256 of `count` bytes at once (32 bytes).
std::array<std::uint8_t, 32> sha256_of(const void* bytes, std::size_t count);

class Sha256 {
public:
    Sha256();
    ~Sha256();
    Sha256(const Sha256&) = delete;
    Sha256& operator=(const Sha256&) = delete;
    void update(const void* bytes, std::size_t count);
    /// 64 lowercase hex digits; the object must not be used afterwards.
    std::string hex();
    /// The 32 bytes of the digest; the object must not be used afterwards.
    std::array<std::uint8_t, 32> bytes();

private:
    struct Ctx;
    std::unique_ptr<Ctx> ctx_;
};

/// Remember `hex` as the SHA-256 of `file` as it is now (its identity is taken here).
void remember_sha256(const std::filesystem::path& file, const std::string& hex);
/// The remembered digest of `file` if its identity is unchanged, else "".
std::string remembered_sha256(const std::filesystem::path& file);

/// `file`'s identity (device, inode, size, times) as text, "" if it is not a regular file: what another
/// process on a machine that sees the same file compares with its own (a tiled run's ranks).
std::string file_identity(const std::filesystem::path& file);
/// Remember `hex` as `file`'s digest if `identity` (another process's file_identity()) is the file's now; a
/// file that differs (changed since, or a file system that shows it otherwise) is simply read when hashed.
void adopt_sha256(const std::filesystem::path& file, const std::string& hex, const std::string& identity);

}  // namespace orogen::detail
