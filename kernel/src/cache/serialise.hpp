// serialise.hpp — inside the cache room: values to and from the raw little-endian arrays of an entry's
// payload (docs/cache.md). The Writer and Reader are here, inline, for the entry codec (entry.cpp), which
// frames the values with the messages, the files and the header.
#pragma once

#include "cache.hpp"

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace orogen::cache {

static_assert(std::endian::native == std::endian::little, "cache entries are little-endian raw arrays");

inline constexpr std::size_t array_alignment = 64;

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

/// Ask for transparent huge pages on the untouched memory [p, p + n) (where the system leaves them to
/// madvise, as Debian does): fresh memory costs a page fault, a zeroed page and a cgroup charge per 4 KiB, which
/// was half the time of reading an entry; with 2 MiB pages that is 512 times fewer. A hint: errors are ignored.
void advise_huge_pages(void* p, std::size_t n);

class Writer {
public:
    explicit Writer(std::size_t reserve) {
        buf_.reserve(reserve);
        if (reserve >= (std::size_t(4) << 20)) advise_huge_pages(buf_.data(), reserve);
    }
    std::vector<std::uint8_t>& buffer() { return buf_; }
    /// Stream from now on: whenever `threshold` bytes are held, hand the whole multiples of `block` among
    /// them to `sink`, in order, and drop them (an entry of a 4097² heightmap then never holds a second
    /// 64 MiB copy). finish() hands on the rest. Offsets (size(), the arrays' alignment) count every byte.
    void stream_to(std::size_t block, std::size_t threshold, std::function<void(std::span<const std::uint8_t>)> sink) {
        block_ = block;
        threshold_ = std::max(threshold, block);
        sink_ = std::move(sink);
        buf_.reserve(threshold_);
    }
    void finish() {
        if (sink_ && !buf_.empty()) sink_(std::span<const std::uint8_t>(buf_));
        flushed_ += buf_.size();
        buf_.clear();
    }
    /// Bytes written so far, streamed or held.
    std::size_t size() const { return flushed_ + buf_.size(); }
    void raw(const void* p, std::size_t n) {
        const auto* b = static_cast<const std::uint8_t*>(p);
        if (!sink_) {
            buf_.insert(buf_.end(), b, b + n);
            return;
        }
        while (n > 0) {
            const std::size_t take = std::min(n, threshold_ - buf_.size());
            buf_.insert(buf_.end(), b, b + take);
            b += take;
            n -= take;
            if (buf_.size() >= threshold_) flush_blocks();
        }
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
        static constexpr std::uint8_t zeros[array_alignment] = {};
        raw(zeros, (array_alignment - size() % array_alignment) % array_alignment);
        raw(data, n * sizeof(T));
    }
    template <typename T>
    void array(const std::vector<T>& v) {
        array(v.data(), v.size());
    }

private:
    void flush_blocks() {
        const std::size_t whole = buf_.size() / block_ * block_;
        sink_(std::span<const std::uint8_t>(buf_.data(), whole));
        buf_.erase(buf_.begin(), buf_.begin() + std::ptrdiff_t(whole));
        flushed_ += whole;
    }
    std::vector<std::uint8_t> buf_;
    std::size_t flushed_ = 0, block_ = 0, threshold_ = 0;
    std::function<void(std::span<const std::uint8_t>)> sink_;
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
        if (pos_ > bytes_.size() || n > (bytes_.size() - pos_) / sizeof(T))
            throw CorruptEntry("an array runs past the payload");
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
        else fill(out, s);
    }
    /// A count that must be followed by at least `min_bytes_each` bytes per element (so a damaged count
    /// cannot make us allocate gigabytes).
    std::uint64_t count(std::size_t min_bytes_each) { return bounded(u64(), min_bytes_each); }
    std::uint32_t count32(std::size_t min_bytes_each) { return std::uint32_t(bounded(u32(), min_bytes_each)); }
    bool at_end() const { return pos_ == bytes_.size(); }
    Deferred* deferred() const { return deferred_; }

private:
    std::uint64_t bounded(std::uint64_t n, std::size_t min_bytes_each) const {
        if (n > (bytes_.size() - pos_) / std::max<std::size_t>(min_bytes_each, 1))
            throw CorruptEntry("a count runs past the payload");
        return n;
    }
    std::span<const std::uint8_t> bytes_;
    std::size_t pos_;
    Deferred* deferred_;
};

/// Append `v` (its type, then its fields and arrays) to `w`.
void write_value(Writer& w, const Value& v);
/// Read a value written by write_value; throws CorruptEntry if it is not one.
Value read_value(Reader& r);
/// Bytes a value takes in an entry, roughly (to reserve the buffer once).
std::size_t estimate(const Value& v);

}  // namespace orogen::cache
