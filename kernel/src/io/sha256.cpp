// SHA-256 (FIPS 180-4), for the hashes in manifest.json (users can check them
// with `sha256sum`) and the node cache's keys: OpenSSL's, which uses the CPU's
// SHA instructions where there are some (about 1.4 GB/s against 0.2 for a
// portable loop), so hashing a run's outputs stays a small part of a re-run.
// Outputs written through an AtomicFile's stream are hashed while they are
// written (digest.hpp); sha256_file() takes those digests instead of reading
// the file again.
#include "digest.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>

#include <openssl/evp.h>
#include <sys/stat.h>

#include <array>
#include <cstdint>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <utility>

namespace orogen {

namespace {

std::string to_hex(const unsigned char* d, unsigned int n) {
    static const char* digits = "0123456789abcdef";
    std::string out;
    for (unsigned int i = 0; i < n; ++i) {
        out += digits[d[i] >> 4];
        out += digits[d[i] & 15];
    }
    return out;
}

}  // namespace

std::string sha256_hex(std::span<const std::uint8_t> bytes) {
    unsigned char d[EVP_MAX_MD_SIZE];
    unsigned int n = 0;
    if (EVP_Digest(bytes.data(), bytes.size(), d, &n, EVP_sha256(), nullptr) != 1)
        throw Error("internal error: OpenSSL's SHA-256 failed");
    return to_hex(d, n);
}

namespace detail {

struct Sha256::Ctx {
    std::unique_ptr<EVP_MD_CTX, void (*)(EVP_MD_CTX*)> md{EVP_MD_CTX_new(), EVP_MD_CTX_free};
};

Sha256::Sha256() : ctx_(std::make_unique<Ctx>()) {
    if (!ctx_->md || EVP_DigestInit_ex(ctx_->md.get(), EVP_sha256(), nullptr) != 1)
        throw Error("internal error: OpenSSL's SHA-256 is not available");
}
Sha256::~Sha256() = default;

void Sha256::update(const void* bytes, std::size_t count) {
    if (count && EVP_DigestUpdate(ctx_->md.get(), bytes, count) != 1)
        throw Error("internal error: OpenSSL's SHA-256 failed");
}

std::array<std::uint8_t, 32> Sha256::bytes() {
    std::array<std::uint8_t, 32> d{};
    unsigned int n = 0;
    if (EVP_DigestFinal_ex(ctx_->md.get(), d.data(), &n) != 1 || n != d.size())
        throw Error("internal error: OpenSSL's SHA-256 failed");
    return d;
}

std::array<std::uint8_t, 32> sha256_of(const void* bytes, std::size_t count) {
    std::array<std::uint8_t, 32> d{};
    unsigned int n = 0;
    if (EVP_Digest(bytes, count, d.data(), &n, EVP_sha256(), nullptr) != 1 || n != d.size())
        throw Error("internal error: OpenSSL's SHA-256 failed");
    return d;
}

std::string Sha256::hex() {
    unsigned char d[EVP_MAX_MD_SIZE];
    unsigned int n = 0;
    if (EVP_DigestFinal_ex(ctx_->md.get(), d, &n) != 1) throw Error("internal error: OpenSSL's SHA-256 failed");
    return to_hex(d, n);
}

namespace {
/// What must be unchanged for a remembered digest to stand: the same file (device, inode), the same
/// size, and the same modification and status-change times to the nanosecond (the times too, so that
/// a new file that happens to get a deleted one's inode and size is not taken for it).
struct Identity {
    std::uint64_t size = 0;
    std::int64_t mtime_s = 0, mtime_ns = 0, ctime_s = 0, ctime_ns = 0;
    bool operator==(const Identity&) const = default;
};
using FileKey = std::pair<std::uint64_t, std::uint64_t>;  // device, inode

bool identify(const std::filesystem::path& file, FileKey& key, Identity& id) {
    struct stat st {};
    if (::stat(file.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return false;
    key = {std::uint64_t(st.st_dev), std::uint64_t(st.st_ino)};
    id = {std::uint64_t(st.st_size), std::int64_t(st.st_mtim.tv_sec), std::int64_t(st.st_mtim.tv_nsec),
          std::int64_t(st.st_ctim.tv_sec), std::int64_t(st.st_ctim.tv_nsec)};
    return true;
}

struct Remembered {
    std::mutex mutex;
    std::map<FileKey, std::pair<Identity, std::string>> digests;
};
Remembered& remembered() {
    static Remembered r;
    return r;
}
}  // namespace

void remember_sha256(const std::filesystem::path& file, const std::string& hex) {
    FileKey key;
    Identity id;
    if (!identify(file, key, id)) return;
    auto& r = remembered();
    const std::lock_guard lock(r.mutex);
    r.digests[key] = {id, hex};
}

std::string file_identity(const std::filesystem::path& file) {
    FileKey key;
    Identity id;
    if (!identify(file, key, id)) return "";
    return std::to_string(key.first) + ":" + std::to_string(key.second) + ":" + std::to_string(id.size) + ":" +
        std::to_string(id.mtime_s) + "." + std::to_string(id.mtime_ns) + ":" + std::to_string(id.ctime_s) + "." +
        std::to_string(id.ctime_ns);
}

void adopt_sha256(const std::filesystem::path& file, const std::string& hex, const std::string& identity) {
    if (hex.size() != 64 || identity.empty() || file_identity(file) != identity) return;
    remember_sha256(file, hex);
}

std::string remembered_sha256(const std::filesystem::path& file) {
    FileKey key;
    Identity id;
    if (!identify(file, key, id)) return "";
    auto& r = remembered();
    const std::lock_guard lock(r.mutex);
    const auto it = r.digests.find(key);
    if (it == r.digests.end()) return "";
    if (!(it->second.first == id)) {  // rewritten since: forget it
        r.digests.erase(it);
        return "";
    }
    return it->second.second;
}

}  // namespace detail

std::string sha256_file(const std::filesystem::path& path) {
    if (std::string known = detail::remembered_sha256(path); !known.empty()) return known;
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error("cannot read " + path.string() + " to hash it");
    detail::Sha256 sha;
    std::vector<char> buffer(std::size_t(1) << 20);
    while (in) {
        in.read(buffer.data(), std::streamsize(buffer.size()));
        sha.update(buffer.data(), std::size_t(in.gcount()));
    }
    return sha.hex();
}

}  // namespace orogen
