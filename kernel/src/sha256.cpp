// SHA-256 (FIPS 180-4), for the hashes in manifest.json (users can check them
// with `sha256sum`) and the node cache's keys: OpenSSL's, which uses the CPU's
// SHA instructions where there are some (about 1.4 GB/s against 0.2 for a
// portable loop), so hashing a run's outputs stays a small part of a re-run.
#include <orogen/error.hpp>
#include <orogen/io.hpp>

#include <openssl/evp.h>

#include <array>
#include <fstream>
#include <memory>

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

std::string sha256_file(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error("cannot read " + path.string() + " to hash it");
    std::unique_ptr<EVP_MD_CTX, void (*)(EVP_MD_CTX*)> ctx(EVP_MD_CTX_new(), EVP_MD_CTX_free);
    if (!ctx || EVP_DigestInit_ex(ctx.get(), EVP_sha256(), nullptr) != 1)
        throw Error("internal error: OpenSSL's SHA-256 is not available");
    std::vector<char> buffer(std::size_t(1) << 20);
    while (in) {
        in.read(buffer.data(), std::streamsize(buffer.size()));
        EVP_DigestUpdate(ctx.get(), buffer.data(), std::size_t(in.gcount()));
    }
    unsigned char d[EVP_MAX_MD_SIZE];
    unsigned int n = 0;
    EVP_DigestFinal_ex(ctx.get(), d, &n);
    return to_hex(d, n);
}

}  // namespace orogen
