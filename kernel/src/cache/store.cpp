// store.cpp — the cache folder: load, save (temporary + rename), LRU eviction, `orogen cache info|clear`.

#include "entry.hpp"

#include <orogen/error.hpp>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <system_error>
#include <unistd.h>

namespace fs = std::filesystem;

namespace orogen::cache {

namespace {

/// A read-only mapping of a whole file.
class Mapping {
public:
    explicit Mapping(const fs::path& path) {
        fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
        if (fd_ < 0) throw std::system_error(errno, std::generic_category());
        struct stat st {};
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
    if (!unit.empty() && unit.back() == 'b') unit.pop_back();  // "GB", "GiB" -> "g", "gi"
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
    struct stat st {};
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
    if (estimated_size(contents) > settings_.max_bytes) return false;  // would evict everything else and itself
    static std::atomic<unsigned> counter{0};
    const fs::path final_path = path(key);
    const fs::path tmp = settings_.folder /
        (".tmp-" + hex(key).substr(0, 16) + "-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    std::string why;
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0) why = errno_text(errno);
    else {
        // Streamed straight into the file (encode_into): the entry is never whole in memory, so keeping a
        // 4097² heightmap costs 8 MiB beside it, not a second 64 MiB copy.
        auto write_all = [&](std::span<const std::uint8_t> bytes, off_t at, bool positioned) {
            std::size_t done = 0;
            while (why.empty() && done < bytes.size()) {
                const ssize_t n = positioned ? ::pwrite(fd, bytes.data() + done, bytes.size() - done, at + off_t(done))
                                             : ::write(fd, bytes.data() + done, bytes.size() - done);
                if (n < 0) {
                    if (errno != EINTR) why = errno_text(errno);
                    continue;
                }
                done += std::size_t(n);
            }
        };
        std::uint64_t size = 0;
        bool too_big = false;
        try {
            size = encode_into(key, contents,
                               {[&](std::span<const std::uint8_t> b) { write_all(b, 0, false); },
                                [&](std::span<const std::uint8_t> h) { write_all(h, 0, true); }});
            too_big = size > settings_.max_bytes;
        } catch (const std::bad_alloc&) {
            too_big = true;  // too big to encode now: the run goes on uncached
        }
        if (::close(fd) != 0 && why.empty()) why = errno_text(errno);
        // No fsync: an entry torn by a power cut fails its hash and is recomputed.
        if (too_big && why.empty()) {
            ::unlink(tmp.c_str());
            return false;
        }
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
        struct stat st {};
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
    if (!fs::is_directory(st))
        throw BadInput(folder.string() + " is not a folder; give the cache folder with --cache DIR");
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
        struct stat st {};
        if (it->path().filename().string().rfind(".tmp-", 0) == 0 && ::lstat(it->path().c_str(), &st) == 0 &&
            S_ISREG(st.st_mode)) {
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
