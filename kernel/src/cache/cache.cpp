#include "cache.hpp"

#include <orogen/error.hpp>
#include <orogen/parallel.hpp>
#include <orogen/plugin.hpp>

#include <xxhash.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <optional>
#include <elf.h>
#include <fcntl.h>
#include <link.h>
#include <map>
#include <mutex>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace orogen::cache {

static_assert(std::endian::native == std::endian::little, "cache entries are little-endian raw arrays");

namespace {

constexpr char magic[8] = {'O', 'R', 'G', 'N', 'C', 'A', 'C', 'H'};
constexpr std::uint32_t format_version = 3;  // 2: the payload sealed by XXH3-128 instead of SHA-256; 3: recorded files
constexpr std::size_t header_size = 192;  // a multiple of 64, so arrays aligned in the payload are aligned in the file
constexpr std::size_t max_message_bytes = std::size_t(1) << 20;
constexpr std::size_t array_alignment = 64;
constexpr std::size_t hash_block = std::size_t(1) << 20;  // bytes per block of the payload hash and checksum

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

template <typename T>
T get(const std::uint8_t* p) {
    T v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
template <typename T>
void put(std::uint8_t* p, T v) {
    std::memcpy(p, &v, sizeof v);
}

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

// ------------------------------------------------------------------ writing

/// Ask for transparent huge pages on the untouched memory [p, p + n) (where the system leaves them to
/// madvise, as Debian does): fresh memory costs a page fault, a zeroed page and a cgroup charge per 4 KiB, which
/// was half the time of reading an entry; with 2 MiB pages that is 512 times fewer. A hint: errors are ignored.
void advise_huge_pages(void* p, std::size_t n) {
    constexpr std::uintptr_t huge = std::uintptr_t(2) << 20;
    const auto begin = (reinterpret_cast<std::uintptr_t>(p) + huge - 1) & ~(huge - 1);
    const auto end = (reinterpret_cast<std::uintptr_t>(p) + n) & ~(huge - 1);
    if (end > begin) ::madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
}

class Writer {
public:
    explicit Writer(std::size_t reserve) {
        buf_.reserve(reserve);
        if (reserve >= (std::size_t(4) << 20)) advise_huge_pages(buf_.data(), reserve);
    }
    std::vector<std::uint8_t>& buffer() { return buf_; }
    void raw(const void* p, std::size_t n) {
        const auto* b = static_cast<const std::uint8_t*>(p);
        buf_.insert(buf_.end(), b, b + n);
    }
    void u8(std::uint8_t v) { raw(&v, 1); }
    void u32(std::uint32_t v) { raw(&v, 4); }
    void i32(std::int32_t v) { raw(&v, 4); }
    void u64(std::uint64_t v) { raw(&v, 8); }
    void i64(std::int64_t v) { raw(&v, 8); }
    void f64(double v) { raw(&v, 8); }
    void str(std::string_view s) {
        u64(s.size());
        raw(s.data(), s.size());
    }
    /// A count, padding to the next 64-byte boundary, then the elements' bytes.
    template <typename T>
    void array(const T* data, std::size_t n) {
        static_assert(std::is_trivially_copyable_v<T>);
        u64(n);
        buf_.resize((buf_.size() + array_alignment - 1) / array_alignment * array_alignment, 0);
        raw(data, n * sizeof(T));
    }
    template <typename T>
    void array(const std::vector<T>& v) {
        array(v.data(), v.size());
    }

private:
    std::vector<std::uint8_t> buf_;
};

/// The copies out of the mapping that decode() leaves for later, to run them all at once on every core
/// beside the payload hash (see decode()), and what to do once they are done.
struct Deferred {
    struct Copy {
        std::size_t bytes;
        std::function<void()> run;
    };
    std::vector<Copy> copies;
    std::vector<std::function<void()>> after;  ///< in order, once every copy is done (assembling heightmaps)
};

/// Fill the empty `out` with `s`: reserve (untouched memory), advise huge pages on it, then insert, which
/// copies into the reserved memory: each byte written once, no zero-fill first, and a plain std::vector.
template <typename T>
void fill(std::vector<T>& out, std::span<const T> s) {
    out.clear();
    out.reserve(s.size());
    if (s.size_bytes() >= (std::size_t(4) << 20)) advise_huge_pages(out.data(), s.size_bytes());
    out.insert(out.end(), s.begin(), s.end());
}

/// Arrays smaller than this are copied at once while parsing: a task is not worth it.
constexpr std::size_t defer_bytes = std::size_t(256) << 10;

/// Parses a payload. Every count and size is checked against the bytes left before anything is allocated,
/// so a damaged or hostile entry costs at most its own size in memory.
class Reader {
public:
    Reader(std::span<const std::uint8_t> bytes, std::size_t offset, Deferred* deferred = nullptr)
        : bytes_(bytes), pos_(offset), deferred_(deferred) {}
    void need(std::size_t n) const {
        if (n > bytes_.size() - pos_) throw CorruptEntry("payload ends inside a field");
    }
    template <typename T>
    T pod() {
        need(sizeof(T));
        T v = get<T>(bytes_.data() + pos_);
        pos_ += sizeof(T);
        return v;
    }
    std::uint8_t u8() { return pod<std::uint8_t>(); }
    std::uint32_t u32() { return pod<std::uint32_t>(); }
    std::int32_t i32() { return pod<std::int32_t>(); }
    std::uint64_t u64() { return pod<std::uint64_t>(); }
    std::int64_t i64() { return pod<std::int64_t>(); }
    double f64() { return pod<double>(); }
    std::string str() {
        const std::uint64_t n = u64();
        need(n);
        std::string s(reinterpret_cast<const char*>(bytes_.data() + pos_), n);
        pos_ += n;
        return s;
    }
    /// The span of an array written by Writer::array (no copy).
    template <typename T>
    std::span<const T> array_span() {
        const std::uint64_t n = u64();
        pos_ = (pos_ + array_alignment - 1) / array_alignment * array_alignment;
        if (pos_ > bytes_.size() || n > (bytes_.size() - pos_) / sizeof(T)) throw CorruptEntry("an array runs past the payload");
        std::span<const T> s(reinterpret_cast<const T*>(bytes_.data() + pos_), n);  // 64-byte aligned (mmap'd)
        pos_ += n * sizeof(T);
        return s;
    }
    /// Fill `out` (empty, at an address that stays put until the deferred copies run) with an array: a fresh
    /// vector built from the mapped bytes, so each byte is written once (no zero-fill first).
    template <typename T>
    void array(std::vector<T>& out) {
        copy_into(out, array_span<T>());
    }
    template <typename T>
    void copy_into(std::vector<T>& out, std::span<const T> s) {
        if (deferred_ && s.size_bytes() >= defer_bytes)
            deferred_->copies.push_back({s.size_bytes(), [&out, s] { fill(out, s); }});
        else
            fill(out, s);
    }
    /// A count that must be followed by at least `min_bytes_each` bytes per element (so a damaged count
    /// cannot make us allocate gigabytes).
    std::uint64_t count(std::size_t min_bytes_each) { return bounded(u64(), min_bytes_each); }
    std::uint32_t count32(std::size_t min_bytes_each) { return std::uint32_t(bounded(u32(), min_bytes_each)); }
    bool at_end() const { return pos_ == bytes_.size(); }
    Deferred* deferred() const { return deferred_; }

private:
    std::uint64_t bounded(std::uint64_t n, std::size_t min_bytes_each) const {
        if (n > (bytes_.size() - pos_) / std::max<std::size_t>(min_bytes_each, 1)) throw CorruptEntry("a count runs past the payload");
        return n;
    }
    std::span<const std::uint8_t> bytes_;
    std::size_t pos_;
    Deferred* deferred_;
};

void write_value(Writer& w, const Value& v) {
    w.u8(std::uint8_t(v.type()));
    switch (v.type()) {
        case ValueType::heightmap: {
            const Heightmap& hm = *v.heightmap();
            w.i32(hm.width());
            w.i32(hm.height());
            w.f64(hm.cell());
            w.array(hm.heights());
            const auto names = hm.layer_names();
            w.u32(std::uint32_t(names.size()));
            for (const auto& n : names) {
                const ConstGridView l = hm.layer(n);
                w.str(n);
                w.array(l.data, l.size());
            }
            break;
        }
        case ValueType::image: {
            const Image& im = *v.image();
            w.i32(im.width);
            w.i32(im.height);
            w.u8(std::uint8_t(im.format));
            w.array(im.rgba8);
            w.array(im.rgba32f);
            break;
        }
        case ValueType::particles: {
            const ParticleSeries& ps = *v.particles();
            w.u64(ps.frames.size());
            for (const auto& f : ps.frames) {
                w.f64(f.time);
                w.i64(f.step);
                w.u32(std::uint32_t(f.attributes.size()));
                for (const auto& [name, a] : f.attributes) {
                    w.str(name);
                    w.i32(a.components);
                    w.array(a.data);
                }
            }
            break;
        }
        case ValueType::plates: {
            const PlateHistory& ph = *v.plates();
            w.f64(ph.width);
            w.f64(ph.height);
            w.u64(ph.snapshots.size());
            for (const auto& s : ph.snapshots) {
                w.i64(s.step);
                w.f64(s.time);
                w.u64(s.plates.size());
                for (const auto& p : s.plates) {
                    w.i32(p.id);
                    w.array(p.polygon);
                    w.f64(p.velocity.x);
                    w.f64(p.velocity.y);
                    w.f64(p.density);
                }
            }
            w.u64(ph.collisions.size());
            for (const auto& c : ph.collisions) {
                w.i64(c.step);
                w.i32(c.plate_a);
                w.i32(c.plate_b);
                w.f64(c.a.x);
                w.f64(c.a.y);
                w.f64(c.b.x);
                w.f64(c.b.y);
                w.i32(int(c.kind));
                w.f64(c.impulse);
            }
            break;
        }
        case ValueType::none:
        case ValueType::series:
            throw Error("internal error: a " + std::string(to_string(v.type())) + " cannot be kept in the cache");
    }
}

Value read_value(Reader& r) {
    const auto type = ValueType(r.u8());
    switch (type) {
        case ValueType::heightmap: {
            const int width = r.i32(), height = r.i32();
            const double cell = r.f64();
            if (width < 0 || height < 0) throw CorruptEntry("a heightmap of negative size");
            if (!std::isfinite(cell) || cell <= 0) throw CorruptEntry("a heightmap whose cell size is not a positive number");
            const std::size_t size = std::size_t(width) * std::size_t(height);
            // Heights first, then each layer: fresh vectors filled from the mapping (deferred: on every core, beside
            // the checksum), then adopted by the Heightmap, so no byte of it is written twice.
            auto hm = std::make_shared<Heightmap>();
            const auto heights = r.array_span<float>();
            if (heights.size() != size) throw CorruptEntry("a heightmap's size does not match its heights");
            const std::uint32_t layers = r.count32(16);  // each: a name's length and an array's count at least
            auto arrays = std::make_shared<std::vector<std::pair<std::string, std::vector<float>>>>(std::size_t(layers) + 1);
            r.copy_into((*arrays)[0].second, heights);
            for (std::uint32_t i = 1; i <= layers; ++i) {
                std::string name = r.str();
                for (std::uint32_t j = 1; j < i; ++j)
                    if ((*arrays)[j].first == name) throw CorruptEntry("a layer appears twice");
                const auto values = r.array_span<float>();
                if (values.size() != size) throw CorruptEntry("a layer's size does not match its heightmap");
                (*arrays)[i].first = std::move(name);
                r.copy_into((*arrays)[i].second, values);
            }
            auto assemble = [hm, arrays, width, height, cell] {
                *hm = Heightmap(width, height, cell, std::move((*arrays)[0].second));
                for (std::size_t i = 1; i < arrays->size(); ++i) hm->set_layer((*arrays)[i].first, std::move((*arrays)[i].second));
                arrays->clear();
            };
            if (r.deferred()) r.deferred()->after.push_back(std::move(assemble));
            else assemble();
            return Value(std::move(hm));
        }
        case ValueType::image: {
            auto im = std::make_shared<Image>();
            im->width = r.i32();
            im->height = r.i32();
            const std::uint8_t format = r.u8();
            if (format > 1) throw CorruptEntry("an image of unknown format");
            if (im->width < 0 || im->height < 0) throw CorruptEntry("an image of negative size");
            im->format = Image::Format(format);
            const std::size_t samples = std::size_t(im->width) * std::size_t(im->height) * 4;
            const auto rgba8 = r.array_span<std::uint8_t>();
            const auto rgba32f = r.array_span<float>();
            // Exactly one of the two holds the pixels (values.hpp): a reader of the image trusts its size.
            if (rgba8.size() != (im->format == Image::Format::rgba8 ? samples : 0) ||
                rgba32f.size() != (im->format == Image::Format::rgba32f ? samples : 0))
                throw CorruptEntry("an image's pixels do not match its size and format");
            r.copy_into(im->rgba8, rgba8);
            r.copy_into(im->rgba32f, rgba32f);
            return Value(std::move(im));
        }
        case ValueType::particles: {
            auto ps = std::make_shared<ParticleSeries>();
            ps->frames.resize(r.count(20));
            for (auto& f : ps->frames) {
                f.time = r.f64();
                f.step = r.i64();
                const std::uint32_t n = r.count32(20);
                std::optional<std::size_t> particles;
                for (std::uint32_t i = 0; i < n; ++i) {
                    std::string name = r.str();
                    const std::int32_t components = r.i32();
                    if (components < 1) throw CorruptEntry("a particle attribute of " + std::to_string(components) + " components");
                    const auto data = r.array_span<float>();
                    // Every attribute has `components` floats for each of the frame's particles.
                    if (data.size() % std::size_t(components) != 0 ||
                        (particles && data.size() / std::size_t(components) != *particles))
                        throw CorruptEntry("a particle attribute's size does not match the frame's particles");
                    particles = data.size() / std::size_t(components);
                    auto [it, inserted] = f.attributes.try_emplace(std::move(name));
                    if (!inserted) throw CorruptEntry("a particle attribute appears twice");
                    it->second.components = components;
                    r.copy_into(it->second.data, data);
                }
            }
            return Value(std::move(ps));
        }
        case ValueType::plates: {
            auto ph = std::make_shared<PlateHistory>();
            ph->width = r.f64();
            ph->height = r.f64();
            ph->snapshots.resize(r.count(24));
            for (auto& s : ph->snapshots) {
                s.step = r.i64();
                s.time = r.f64();
                s.plates.resize(r.count(36));
                for (auto& p : s.plates) {
                    p.id = r.i32();
                    r.array(p.polygon);
                    p.velocity.x = r.f64();
                    p.velocity.y = r.f64();
                    p.density = r.f64();
                }
            }
            ph->collisions.resize(r.count(60));
            for (auto& c : ph->collisions) {
                c.step = r.i64();
                c.plate_a = r.i32();
                c.plate_b = r.i32();
                c.a.x = r.f64();
                c.a.y = r.f64();
                c.b.x = r.f64();
                c.b.y = r.f64();
                const std::int32_t kind = r.i32();
                if (kind < 1 || kind > 3) throw CorruptEntry("a collision of unknown kind " + std::to_string(kind));
                c.kind = BoundaryKind(kind);
                c.impulse = r.f64();
            }
            return Value(std::move(ph));
        }
        default:
            throw CorruptEntry("a value of unknown type " + std::to_string(int(type)));
    }
}

/// Bytes a value takes in an entry, roughly (to reserve the buffer once).
std::size_t estimate(const Value& v) {
    std::size_t n = 256;
    switch (v.type()) {
        case ValueType::heightmap: {
            const auto& hm = *v.heightmap();
            n += (hm.layer_names().size() + 1) * (hm.size() * 4 + 128);
            break;
        }
        case ValueType::image: n += v.image()->rgba8.size() + v.image()->rgba32f.size() * 4 + 256; break;
        case ValueType::particles:
            for (const auto& f : v.particles()->frames)
                for (const auto& [name, a] : f.attributes) n += a.data.size() * 4 + name.size() + 128;
            break;
        case ValueType::plates:
            for (const auto& s : v.plates()->snapshots)
                for (const auto& p : s.plates) n += p.polygon.size() * 16 + 160;
            n += v.plates()->collisions.size() * 64;
            break;
        default: break;
    }
    return n;
}

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

std::vector<std::string> read_messages(std::span<const std::uint8_t> block, const Header& h) {
    if (detail::sha256_of(block.data(), block.size()) != h.message_hash) throw CorruptEntry("its messages do not match their SHA-256");
    Reader r(block, 0);
    std::vector<std::string> out;
    const std::uint32_t n = r.u32();
    for (std::uint32_t i = 0; i < n; ++i) out.push_back(r.str());
    if (!r.at_end() || n != h.messages) throw CorruptEntry("its messages are damaged");
    return out;
}

/// A read-only mapping of a whole file.
class Mapping {
public:
    explicit Mapping(const fs::path& path) {
        fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
        if (fd_ < 0) throw std::system_error(errno, std::generic_category());
        struct stat st{};
        if (::fstat(fd_, &st) != 0) throw std::system_error(errno, std::generic_category());
        if (!S_ISREG(st.st_mode)) throw CorruptEntry("not a regular file");
        size_ = std::size_t(st.st_size);
        if (size_ == 0) return;
        void* p = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd_, 0);
        if (p == MAP_FAILED) throw std::system_error(errno, std::generic_category());
        data_ = static_cast<const std::uint8_t*>(p);
    }
    ~Mapping() {
        if (data_) ::munmap(const_cast<std::uint8_t*>(data_), size_);
        if (fd_ >= 0) ::close(fd_);
    }
    Mapping(const Mapping&) = delete;
    Mapping& operator=(const Mapping&) = delete;
    std::span<const std::uint8_t> bytes() const { return {data_, size_}; }
    int fd() const { return fd_; }

private:
    int fd_ = -1;
    const std::uint8_t* data_ = nullptr;
    std::size_t size_ = 0;
};

std::string errno_text(int e) { return std::generic_category().message(e); }

}  // namespace

// ------------------------------------------------------------------ hashing

std::string hex(const Digest& d) {
    static const char* digits = "0123456789abcdef";
    std::string s;
    for (std::uint8_t b : d) {
        s += digits[b >> 4];
        s += digits[b & 15];
    }
    return s;
}

Hasher& Hasher::bytes(const void* data, std::size_t n) {
    sha_.update(data, n);
    return *this;
}
Hasher& Hasher::u64(std::uint64_t v) { return bytes(&v, sizeof v); }
Hasher& Hasher::f64(double v) { return u64(std::bit_cast<std::uint64_t>(v)); }
Hasher& Hasher::text(std::string_view s) {
    u64(s.size());
    return bytes(s.data(), s.size());
}
namespace {
std::size_t hash_blocks(std::size_t payload_bytes) { return std::max<std::size_t>(1, (payload_bytes + hash_block - 1) / hash_block); }

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
    std::stable_sort(jobs.begin(), jobs.end(), [](const Deferred::Copy& a, const Deferred::Copy& b) { return a.bytes > b.bytes; });
    const std::size_t workers = std::min<std::size_t>(
        jobs.size(), std::size_t(std::max(1, thread_count())));
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

Digest node_key(const Plan& plan, const PlannedNode& node, const std::vector<std::optional<Digest>>& inputs,
                std::string_view plugin_name, std::string_view plugin_version, std::string_view plugin_identity,
                std::uint64_t seed) {
    Hasher h;
    h.text("orogen node key").u64(format_version).text(OROGEN_VERSION).u64(OROGEN_PLUGIN_API_VERSION).text(kernel_identity());
    h.text(node.node->qualified_name()).text(plugin_name).text(plugin_version).text(plugin_identity);
    h.u64(seed);
    h.u64(std::uint64_t(plan.grid.width)).u64(std::uint64_t(plan.grid.height)).f64(plan.grid.cell);
    h.u64(std::uint64_t(std::int64_t(node.mapped_input) + 1));
    h.u64(node.params.size());
    for (const auto& [name, value] : node.params) {
        h.text(name).u64(value.index());
        std::visit(
            [&](const auto& x) {
                using T = std::decay_t<decltype(x)>;
                if constexpr (std::is_same_v<T, std::monostate>) {
                } else if constexpr (std::is_same_v<T, std::int64_t>) h.u64(std::uint64_t(x));
                else if constexpr (std::is_same_v<T, double>) h.f64(x);
                else if constexpr (std::is_same_v<T, bool>) h.u64(x ? 1 : 0);
                else if constexpr (std::is_same_v<T, std::string>) h.text(x);
                else if constexpr (std::is_same_v<T, Point2>) h.f64(x.x).f64(x.y);
                else {
                    h.u64(x.size());
                    for (const auto& p : x) h.f64(p.x).f64(p.y);
                }
            },
            value);
    }
    h.u64(inputs.size());
    for (const auto& in : inputs) {
        h.u64(in ? 1 : 0);
        if (in) h.digest(*in);
    }
    return h.finish();
}

namespace {
struct FoundBinary {
    const void* address = nullptr;
    bool found = false;
    std::string file;      ///< "" for the main program
    std::string build_id;  ///< hex, "" if it has none
};

/// The GNU build-id in a PT_NOTE segment mapped at `notes` (`size` bytes, entries aligned to `align`).
std::string build_id_in(const std::uint8_t* notes, std::size_t size, std::size_t align) {
    align = align < 4 ? 4 : align;
    auto up = [align](std::size_t n) { return (n + align - 1) / align * align; };
    std::size_t at = 0;
    while (at + sizeof(ElfW(Nhdr)) <= size) {
        ElfW(Nhdr) n;
        std::memcpy(&n, notes + at, sizeof n);
        const std::size_t name_at = at + sizeof n, desc_at = name_at + up(n.n_namesz);
        if (desc_at > size || n.n_descsz > size - desc_at) break;
        if (n.n_type == NT_GNU_BUILD_ID && n.n_namesz == 4 && std::memcmp(notes + name_at, "GNU", 4) == 0 && n.n_descsz > 0) {
            static const char* digits = "0123456789abcdef";
            std::string hexid;
            for (std::size_t i = 0; i < n.n_descsz; ++i) {
                hexid += digits[notes[desc_at + i] >> 4];
                hexid += digits[notes[desc_at + i] & 15];
            }
            return hexid;
        }
        at = desc_at + up(n.n_descsz);
    }
    return {};
}

int find_binary(dl_phdr_info* info, std::size_t, void* data) {
    auto* want = static_cast<FoundBinary*>(data);
    const auto addr = reinterpret_cast<std::uintptr_t>(want->address);
    bool holds = false;
    for (int i = 0; i < info->dlpi_phnum && !holds; ++i) {
        const auto& ph = info->dlpi_phdr[i];
        const std::uintptr_t begin = info->dlpi_addr + ph.p_vaddr;
        holds = ph.p_type == PT_LOAD && addr >= begin && addr < begin + ph.p_memsz;
    }
    if (!holds) return 0;
    want->found = true;
    want->file = info->dlpi_name ? info->dlpi_name : "";
    for (int i = 0; i < info->dlpi_phnum && want->build_id.empty(); ++i) {
        const auto& ph = info->dlpi_phdr[i];
        if (ph.p_type == PT_NOTE)
            want->build_id = build_id_in(reinterpret_cast<const std::uint8_t*>(info->dlpi_addr + ph.p_vaddr), ph.p_memsz,
                                         std::size_t(ph.p_align));
    }
    return 1;
}

std::optional<Digest> sha256_of_file(const fs::path& file) {
    const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return std::nullopt;
    Hasher h;
    std::vector<std::uint8_t> buf(std::size_t(1) << 20);
    bool ok = true;
    for (;;) {
        const ssize_t n = ::read(fd, buf.data(), buf.size());
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) ok = false;
        if (n <= 0) break;
        h.bytes(buf.data(), std::size_t(n));
    }
    ::close(fd);
    if (!ok) return std::nullopt;
    return h.finish();
}
}  // namespace

std::string binary_identity(const void* address) {
    FoundBinary want;
    want.address = address;
    ::dl_iterate_phdr(find_binary, &want);
    if (!want.found) return {};
    if (!want.build_id.empty()) return "build-id:" + want.build_id;
    // No build-id (linked with --build-id=none): the file's bytes, once per file and process.
    static std::mutex mutex;
    static std::map<std::string, std::string> known;
    const std::string file = want.file.empty() ? std::string("/proc/self/exe") : want.file;
    std::lock_guard lock(mutex);
    if (const auto it = known.find(file); it != known.end()) return it->second;
    const auto digest = sha256_of_file(file);
    return known[file] = digest ? "sha256:" + hex(*digest) : std::string();
}

const std::string& kernel_identity() {
    static const std::string identity = [] {
        const std::string id = binary_identity(reinterpret_cast<const void*>(&kernel_identity));
        // Without one, a kernel rebuilt with other code must not find this one's entries: this process's own.
        return id.empty() ? "process:" + std::to_string(::getpid()) + "-" +
                                std::to_string(std::chrono::steady_clock::now().time_since_epoch().count())
                          : id;
    }();
    return identity;
}

Digest output_key(const Digest& node, std::string_view name) {
    Hasher h;
    h.text("orogen output").digest(node).text(name);
    return h.finish();
}

Digest content_key(const Digest& node, std::string_view name, const Digest& content) {
    Hasher h;
    h.text("orogen content").digest(node).text(name).digest(content);
    return h.finish();
}

// ------------------------------------------------------------ entries

bool storable(ValueType type) {
    return type == ValueType::heightmap || type == ValueType::image || type == ValueType::particles ||
           type == ValueType::plates;
}

std::vector<std::uint8_t> encode(const Digest& key, const Contents& contents) {
    std::size_t reserve = header_size + 1024;
    for (const auto& [name, v] : contents.values) reserve += estimate(v) + name.size();
    for (const auto& [path, bytes] : contents.files) reserve += bytes.size() + path.size() + 128;
    for (const auto& f : contents.recorded) reserve += f.path.size() + f.sha256.size() + 32;
    for (const auto& m : contents.messages) reserve += m.size() + 8;
    Writer w(reserve);
    w.buffer().resize(header_size, 0);
    w.u32(std::uint32_t(contents.messages.size()));
    for (const auto& m : contents.messages) w.str(m);
    const std::size_t message_bytes = w.buffer().size() - header_size;
    if (message_bytes > max_message_bytes) throw Error("the node printed more than 1 MiB of messages");
    w.buffer().resize((w.buffer().size() + 63) / 64 * 64, 0);
    const std::size_t payload_offset = w.buffer().size();
    write_payload(w, contents);
    std::vector<std::uint8_t>& buf = w.buffer();
    const std::span<const std::uint8_t> payload(buf.data() + payload_offset, buf.size() - payload_offset);
    std::uint8_t* h = buf.data();
    std::memcpy(h, magic, sizeof magic);
    put<std::uint32_t>(h + 8, format_version);
    put<std::uint32_t>(h + 12, header_size);
    std::strncpy(reinterpret_cast<char*>(h + 16), OROGEN_VERSION, 31);
    put<std::uint64_t>(h + 48, payload.size());
    const Digest ph = payload_checksum(payload);
    std::memcpy(h + 56, ph.data(), 32);
    std::memcpy(h + 88, key.data(), 32);
    put<std::uint32_t>(h + 120, std::uint32_t(contents.messages.size()));
    put<std::uint32_t>(h + 124, std::uint32_t(contents.files.size() + contents.recorded.size()));
    put<std::uint64_t>(h + 128, message_bytes);
    const Digest messages = detail::sha256_of(buf.data() + header_size, message_bytes);
    std::memcpy(h + 136, messages.data(), messages.size());
    return std::move(buf);
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
        if (rel.empty() || rel.is_absolute() ||
            std::any_of(rel.begin(), rel.end(), [](const fs::path& part) { return part.empty() || part == ".." || part == "."; }))
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
    if (combine_checksums(payload.size(), digests) != h.payload_hash) throw CorruptEntry("its payload does not match its checksum");
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

Digest value_hash(const Value& value) {
    Writer w(estimate(value));
    write_value(w, value);
    return payload_hash(w.buffer());
}

// ------------------------------------------------------------ the folder

fs::path default_folder() {
    if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg && fs::path(xdg).is_absolute())
        return fs::path(xdg) / "orogen";
    if (const char* home = std::getenv("HOME"); home && *home) return fs::path(home) / ".cache" / "orogen";
    return {};
}

std::optional<std::uint64_t> parse_size(std::string_view text) {
    std::string s(text);
    if (s.empty()) return std::nullopt;
    char* end = nullptr;
    errno = 0;
    const double number = std::strtod(s.c_str(), &end);
    if (end == s.c_str() || errno == ERANGE || !std::isfinite(number) || number < 0) return std::nullopt;
    std::string unit(end);
    for (auto& ch : unit) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    if (!unit.empty() && unit.back() == 'b') unit.pop_back();   // "GB", "GiB" -> "g", "gi"
    if (!unit.empty() && unit.back() == 'i') unit.pop_back();
    double scale = 1;
    if (unit.empty()) scale = 1;
    else if (unit == "k") scale = 1024.0;
    else if (unit == "m") scale = 1024.0 * 1024;
    else if (unit == "g") scale = 1024.0 * 1024 * 1024;
    else if (unit == "t") scale = 1024.0 * 1024 * 1024 * 1024;
    else return std::nullopt;
    const double bytes = number * scale;
    if (bytes > 9.0e18) return std::nullopt;
    return std::uint64_t(bytes);
}

Store::Store(Settings settings, std::function<void(const std::string&)> warn)
    : settings_(std::move(settings)), warn_(std::move(warn)) {
    std::error_code ec;
    fs::create_directories(settings_.folder, ec);
    std::string why;
    if (ec) why = "cannot create it (" + ec.message() + ")";
    else if (!fs::is_directory(settings_.folder, ec)) why = "it is not a folder";
    else {
        // Writable? Try what save() does: create a file, then remove it.
        const fs::path probe = settings_.folder / (".probe-" + std::to_string(::getpid()));
        const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
        if (fd < 0) why = "it is not writable (" + errno_text(errno) + ")";
        else {
            ::close(fd);
            ::unlink(probe.c_str());
        }
    }
    usable_ = why.empty();
    if (!usable_)
        warn_("orogen: warning: cache folder " + settings_.folder.string() + ": " + why +
              "; running without the cache (choose another with --cache DIR, or --no-cache)");
}

fs::path Store::path(const Digest& key) const { return settings_.folder / (hex(key) + ".orc"); }

std::optional<EntryInfo> Store::probe(const Digest& key, const std::string& what) {
    const fs::path p = path(key);
    const int fd = ::open(p.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return std::nullopt;
    std::uint8_t buf[header_size];
    ssize_t got = 0;
    while (got < ssize_t(header_size)) {
        const ssize_t n = ::read(fd, buf + got, header_size - std::size_t(got));
        if (n <= 0) break;
        got += n;
    }
    struct stat st{};
    const bool stat_ok = ::fstat(fd, &st) == 0;
    ::close(fd);
    try {
        const Header h = read_header({buf, std::size_t(std::max<ssize_t>(got, 0))});
        check_version(h);
        if (!stat_ok || std::uint64_t(st.st_size) != h.payload_offset() + h.payload_size)
            throw CorruptEntry("truncated: " + std::to_string(std::uint64_t(st.st_size)) + " bytes, its header says " +
                               std::to_string(h.payload_offset() + h.payload_size));
        EntryInfo info{std::uint64_t(st.st_size), h.messages, h.files, {}};
        if (h.message_bytes > 0) {  // a few hundred bytes, checked by their own hash
            std::vector<std::uint8_t> block(h.message_bytes);
            const int mfd = ::open(p.c_str(), O_RDONLY | O_CLOEXEC);
            const ssize_t n = mfd < 0 ? -1 : ::pread(mfd, block.data(), block.size(), off_t(header_size));
            if (mfd >= 0) ::close(mfd);
            if (n != ssize_t(block.size())) throw CorruptEntry("cannot read its messages");
            info.texts = read_messages(block, h);
        }
        // LRU: a hit is a use, whether or not its values are read later (a cached node nobody reads is
        // still what makes the run fast).
        ::utimensat(AT_FDCWD, p.c_str(), nullptr, 0);
        return info;
    } catch (const OtherVersion& e) {
        warn_("orogen: note: ignoring the cache entry of '" + what + "': " + e.what());
        return std::nullopt;
    } catch (const CorruptEntry& e) {
        warn_("orogen: warning: the cache entry of '" + what + "' (" + p.filename().string() + ") is damaged (" +
              e.what() + "); recomputing it");
        ::unlink(p.c_str());
        return std::nullopt;
    }
}

std::optional<Contents> Store::load(const Digest& key, const std::string& what) {
    const fs::path p = path(key);
    try {
        Mapping m(p);
        Contents c = decode(m.bytes(), key);
        ::futimens(m.fd(), nullptr);  // LRU: now it is the most recently used (fails quietly on a read-only folder)
        return c;
    } catch (const OtherVersion& e) {
        warn_("orogen: note: ignoring the cache entry of '" + what + "': " + e.what());
    } catch (const CorruptEntry& e) {
        warn_("orogen: warning: the cache entry of '" + what + "' (" + p.filename().string() + ") is damaged (" +
              e.what() + "); recomputing it");
        ::unlink(p.c_str());
    } catch (const std::system_error& e) {
        warn_("orogen: warning: cannot read the cache entry of '" + what + "' (" + p.string() + ": " +
              e.code().message() + "); recomputing it");
    } catch (const std::bad_alloc&) {
        warn_("orogen: warning: not enough memory to read the cache entry of '" + what + "'; recomputing it");
    }
    return std::nullopt;
}

bool Store::save(const Digest& key, const Contents& contents) {
    if (!usable_ || save_failed_) return false;
    std::vector<std::uint8_t> bytes;
    try {
        bytes = encode(key, contents);
    } catch (const std::bad_alloc&) {
        return false;  // too big to copy now: the run goes on uncached
    }
    if (bytes.size() > settings_.max_bytes) return false;  // would evict everything else and itself
    static std::atomic<unsigned> counter{0};
    const fs::path final_path = path(key);
    const fs::path tmp = settings_.folder / (".tmp-" + hex(key).substr(0, 16) + "-" + std::to_string(::getpid()) + "-" +
                                             std::to_string(counter++));
    std::string why;
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0) why = errno_text(errno);
    else {
        std::size_t done = 0;
        while (done < bytes.size()) {
            const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
            if (n < 0) {
                if (errno == EINTR) continue;
                why = errno_text(errno);
                break;
            }
            done += std::size_t(n);
        }
        if (::close(fd) != 0 && why.empty()) why = errno_text(errno);
        // No fsync: an entry torn by a power cut fails its hash and is recomputed.
        if (why.empty() && ::rename(tmp.c_str(), final_path.c_str()) != 0) why = errno_text(errno);
        if (!why.empty()) ::unlink(tmp.c_str());
    }
    if (!why.empty()) {
        save_failed_ = true;
        warn_("orogen: warning: cannot write to the cache folder " + settings_.folder.string() + " (" + why +
              "); this run keeps no more results there");
        return false;
    }
    evict(settings_.max_bytes);
    return true;
}

namespace {
struct FileFact {
    fs::path path;
    std::uint64_t bytes;
    std::int64_t mtime_ns;
};

std::vector<FileFact> list_entries(const fs::path& folder, bool remove_stale_temporaries) {
    std::vector<FileFact> out;
    std::error_code ec;
    const auto now = std::chrono::system_clock::now();
    for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string name = it->path().filename().string();
        struct stat st{};
        if (::lstat(it->path().c_str(), &st) != 0 || !S_ISREG(st.st_mode)) continue;
        const std::int64_t mtime = std::int64_t(st.st_mtim.tv_sec) * 1'000'000'000 + st.st_mtim.tv_nsec;
        if (name.rfind(".tmp-", 0) == 0) {  // a killed run's half entry: gone after an hour
            const auto age = now.time_since_epoch() - std::chrono::nanoseconds(mtime);
            if (remove_stale_temporaries && age > std::chrono::hours(1)) ::unlink(it->path().c_str());
            continue;
        }
        if (name.size() != 68 || name.substr(64) != ".orc") continue;
        out.push_back({it->path(), std::uint64_t(st.st_size), mtime});
    }
    return out;
}
}  // namespace

namespace {
void check_listable(const fs::path& folder) {
    std::error_code ec;
    const auto st = fs::status(folder, ec);
    if (!fs::is_directory(st)) throw BadInput(folder.string() + " is not a folder; give the cache folder with --cache DIR");
    fs::directory_iterator it(folder, ec);
    if (ec) throw BadInput("cannot list the cache folder " + folder.string() + " (" + ec.message() + ")");
}
}  // namespace

FolderFacts folder_facts(const fs::path& folder) {
    FolderFacts f;
    std::error_code ec;
    if (!fs::exists(fs::symlink_status(folder, ec))) return f;
    check_listable(folder);
    f.exists = true;
    for (const auto& e : list_entries(folder, false)) {
        f.oldest_ns = f.entries == 0 ? e.mtime_ns : std::min(f.oldest_ns, e.mtime_ns);
        f.newest_ns = f.entries == 0 ? e.mtime_ns : std::max(f.newest_ns, e.mtime_ns);
        ++f.entries;
        f.bytes += e.bytes;
    }
    for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
        struct stat st{};
        if (it->path().filename().string().rfind(".tmp-", 0) == 0 && ::lstat(it->path().c_str(), &st) == 0 && S_ISREG(st.st_mode)) {
            ++f.temporaries;
            f.temporary_bytes += std::uint64_t(st.st_size);
        }
    }
    return f;
}

Cleared clear_folder(const fs::path& folder) {
    Cleared c;
    std::error_code ec;
    if (!fs::exists(fs::symlink_status(folder, ec))) return c;
    check_listable(folder);
    for (const auto& e : list_entries(folder, true)) {  // true: killed runs' temporaries go too
        if (::unlink(e.path.c_str()) == 0) {
            ++c.entries;
            c.bytes += e.bytes;
        } else if (errno != ENOENT) {
            c.failures.push_back(e.path.string() + ": " + errno_text(errno));
        }
    }
    return c;
}

std::uint64_t Store::total_bytes() const {
    std::uint64_t total = 0;
    for (const auto& f : list_entries(settings_.folder, false)) total += f.bytes;
    return total;
}

void Store::evict(std::uint64_t limit) {
    auto entries = list_entries(settings_.folder, true);
    std::uint64_t total = 0;
    for (const auto& f : entries) total += f.bytes;
    if (total <= limit) return;
    // Least recently used first; equal times in name order, so two runs agree.
    std::sort(entries.begin(), entries.end(), [](const FileFact& a, const FileFact& b) {
        return a.mtime_ns != b.mtime_ns ? a.mtime_ns < b.mtime_ns : a.path < b.path;
    });
    for (const auto& f : entries) {
        if (total <= limit) break;
        if (::unlink(f.path.c_str()) == 0 || errno == ENOENT) total -= f.bytes;
    }
}

}  // namespace orogen::cache
