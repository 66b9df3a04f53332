#include "digest.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>

#include <atomic>
#include <streambuf>
#include <cmath>
#include <sys/stat.h>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace orogen {

namespace {

std::string errno_text(int err) { return std::strerror(err); }

/// "out/.cut.png.4711.3.tmp": hidden, beside the target (same file system, so rename is atomic).
fs::path temporary_name(const fs::path& target) {
    static std::atomic<unsigned> counter{0};
    const auto name =
        "." + target.filename().string() + "." + std::to_string(::getpid()) + "." + std::to_string(counter++) + ".tmp";
    return target.parent_path() / name;
}

void fsync_path(const fs::path& path) {
    int fd = ::open(path.c_str(), O_RDONLY);
    if (fd < 0) return;
    ::fsync(fd);
    ::close(fd);
}

}  // namespace

/// The buffer in front of an AtomicFile's filebuf: what is written passes through SHA-256 on its way to
/// the file, 64 KiB at a time (a block costs ~40 µs to hash with the CPU's SHA instructions, about what
/// the write costs). tellp() is a seek of 0 from the current position and keeps the digest; any other
/// seek means bytes may be overwritten, so the digest is void and the file is hashed from disk.
class AtomicFile::Hashing : public std::streambuf {
public:
    explicit Hashing(std::streambuf* file) : file_(file), block_(std::size_t(1) << 16) { reset_put_area(); }
    void retarget(std::streambuf* file) { file_ = file; }
    /// Every byte of a file of `size` bytes went through here, in order.
    bool covers(std::uint64_t size) const { return sequential_ && !failed_ && bytes_ > 0 && bytes_ == size; }
    std::string hex() { return sha_.hex(); }

protected:
    int_type overflow(int_type ch) override {
        if (!drain()) return traits_type::eof();
        if (!traits_type::eq_int_type(ch, traits_type::eof())) {
            *pptr() = traits_type::to_char_type(ch);
            pbump(1);
        }
        return traits_type::not_eof(ch);
    }
    std::streamsize xsputn(const char* s, std::streamsize n) override {
        if (n < std::streamsize(block_.size()) / 4) return std::streambuf::xsputn(s, n);  // into the block
        if (!drain()) return 0;
        return pass(s, n) ? n : 0;  // large writes go straight on, hashed in place
    }
    int sync() override { return drain() ? file_->pubsync() : -1; }
    pos_type seekoff(off_type off, std::ios_base::seekdir dir, std::ios_base::openmode which) override {
        if (!drain()) return pos_type(off_type(-1));
        if (off != 0 || dir != std::ios_base::cur) sequential_ = false;
        return file_->pubseekoff(off, dir, which);
    }
    pos_type seekpos(pos_type pos, std::ios_base::openmode which) override {
        if (!drain()) return pos_type(off_type(-1));
        sequential_ = false;
        return file_->pubseekpos(pos, which);
    }

private:
    void reset_put_area() { setp(block_.data(), block_.data() + block_.size()); }
    bool pass(const char* s, std::streamsize n) {
        if (sequential_) sha_.update(s, std::size_t(n));
        bytes_ += std::uint64_t(n);
        if (file_->sputn(s, n) == n) return true;
        failed_ = true;
        return false;
    }
    bool drain() {
        const std::streamsize n = pptr() - pbase();
        const bool ok = n == 0 || pass(pbase(), n);
        reset_put_area();
        return ok;
    }

    std::streambuf* file_;
    std::vector<char> block_;
    detail::Sha256 sha_;
    std::uint64_t bytes_ = 0;
    bool sequential_ = true, failed_ = false;
};

void AtomicFile::install_hashing() {
    // basic_ios::rdbuf(sb) clears the state; keep what the stream had.
    const auto state = stream_.rdstate();
    hashing_->retarget(stream_.rdbuf());  // std::ofstream::rdbuf(): its own filebuf
    stream_.std::ostream::rdbuf(hashing_.get());
    stream_.setstate(state);
}

AtomicFile::AtomicFile(fs::path target) : target_(std::move(target)), temporary_(temporary_name(target_)) {
    const fs::path folder = target_.parent_path().empty() ? fs::path(".") : target_.parent_path();
    std::error_code ec;
    if (!fs::is_directory(folder, ec))
        throw Error("cannot write " + target_.string() + ": folder " + folder.string() + " does not exist");
    stream_.open(temporary_, std::ios::binary | std::ios::trunc);
    if (!stream_) {
        const int err = errno;
        throw Error("cannot write " + target_.string() + ": cannot create a file in " + folder.string() + " (" +
                    errno_text(err) + "); check the folder's permissions and free space");
    }
    hashing_ = std::make_unique<Hashing>(stream_.rdbuf());
    install_hashing();
}

AtomicFile::AtomicFile(AtomicFile&& other) noexcept
    : target_(std::move(other.target_)), temporary_(std::move(other.temporary_)), hashing_(std::move(other.hashing_)),
      stream_(std::move(other.stream_)),  // now on its own filebuf again
      digest_(std::move(other.digest_)), committed_(other.committed_) {
    if (hashing_) install_hashing();
    other.committed_ = true;  // the moved-from object owns nothing
}

AtomicFile::~AtomicFile() {
    if (committed_) return;
    stream_.std::ostream::rdbuf(nullptr);  // drop what is buffered: the file is discarded
    if (stream_.is_open()) stream_.close();
    std::error_code ec;
    fs::remove(temporary_, ec);
}

std::ofstream& AtomicFile::stream() { return stream_; }

void AtomicFile::write(std::span<const std::uint8_t> bytes) {
    stream_.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

void AtomicFile::flush_checked() {
    std::ofstream& s = stream_;
    if (s.is_open()) {
        s.flush();
        const bool ok = bool(s);
        s.close();
        if (!ok || s.fail())
            throw Error("cannot write " + target_.string() +
                        ": writing failed (disk full?); the existing file, if any, is unchanged");
    }
    std::error_code ec;
    const auto size = fs::file_size(temporary_, ec);
    if (ec)
        throw Error("cannot write " + target_.string() + ": the temporary file " + temporary_.string() + " vanished");
    if (hashing_ && hashing_->covers(size)) digest_ = hashing_->hex();
    // Back onto its own (closed) filebuf before the buffer goes: a write after this fails, as before.
    const auto state = s.rdstate();
    s.std::ostream::rdbuf(s.rdbuf());
    s.setstate(state);
    hashing_.reset();
    fsync_path(temporary_);
}

void AtomicFile::commit() {
    AtomicFile* self = this;
    commit_all(std::span<AtomicFile*>(&self, 1));
}

void commit_all(std::span<AtomicFile*> files) {
    for (AtomicFile* f : files)
        if (!f->committed()) f->flush_checked();
    for (AtomicFile* f : files) {
        if (f->committed()) continue;
        if (std::rename(f->temporary().c_str(), f->target().c_str()) != 0) {
            const int err = errno;
            throw Error("cannot write " + f->target().string() + ": rename failed (" + errno_text(err) + ")");
        }
        f->committed_ = true;
        if (!f->digest_.empty()) detail::remember_sha256(f->target(), f->digest_);
    }
    if (!files.empty()) {
        fs::path folder = files[0]->target().parent_path();
        fsync_path(folder.empty() ? fs::path(".") : folder);
    }
}

void write_file_atomically(const fs::path& target, std::span<const std::uint8_t> bytes) {
    AtomicFile f(target);
    f.write(bytes);
    f.commit();
}

namespace {
std::string kind_problem(mode_t mode) {
    if (S_ISDIR(mode)) return "is a folder; give a file";
    const char* kind = S_ISFIFO(mode) ? "a FIFO (named pipe)"
        : S_ISCHR(mode)               ? "a character device"
        : S_ISBLK(mode)               ? "a block device"
        : S_ISSOCK(mode)              ? "a socket"
                                      : "not a regular file";
    return std::string("is ") + kind + ", not a regular file; give a file (orogen reads only regular files)";
}
}  // namespace

std::string regular_file_problem(const fs::path& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0)
        return errno == ENOENT ? "does not exist" : "cannot be read (" + errno_text(errno) + ")";
    if (S_ISREG(st.st_mode)) return "";
    return kind_problem(st.st_mode);
}

std::vector<std::uint8_t> read_file(const fs::path& path) {
    // O_NONBLOCK: opening a FIFO with no writer must not hang; the fstat below then refuses it.
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        const int err = errno;
        if (err == ENOENT) throw BadInput("cannot read " + path.string() + ": no such file");
        if (err == EISDIR) throw BadInput("cannot read " + path.string() + ": it is a folder, not a file");
        throw BadInput("cannot read " + path.string() + ": " + errno_text(err));
    }
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        const mode_t mode = st.st_mode;
        ::close(fd);
        if (S_ISDIR(mode)) throw BadInput("cannot read " + path.string() + ": it is a folder, not a file");
        throw BadInput("cannot read " + path.string() + ": it " + kind_problem(mode));
    }
    ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
    std::vector<std::uint8_t> bytes(std::size_t(st.st_size));
    std::size_t got = 0;
    while (got < bytes.size()) {
        const ssize_t n = ::read(fd, bytes.data() + got, bytes.size() - got);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) {
            const int err = errno;
            ::close(fd);
            throw BadInput("cannot read " + path.string() + ": " + errno_text(err));
        }
        if (n == 0) break;  // shrank while we read: keep what is there
        got += std::size_t(n);
    }
    bytes.resize(got);
    ::close(fd);
    return bytes;
}

std::uint64_t physical_memory() {
    const long pages = ::sysconf(_SC_PHYS_PAGES);
    const long page = ::sysconf(_SC_PAGE_SIZE);
    return pages > 0 && page > 0 ? std::uint64_t(pages) * std::uint64_t(page) : (std::uint64_t(8) << 30);
}

std::uint64_t heightmap_memory_limit() { return physical_memory() / 4; }

std::string heightmap_memory_problem(double width, double height, std::uint64_t limit) {
    if (limit == 0) limit = heightmap_memory_limit();
    const double bytes = width * height * 4.0;
    if (bytes <= double(limit)) return "";
    const auto side = std::uint64_t(std::sqrt(double(limit) / 4.0));
    return "needs " + human_bytes(bytes) + " for one heightmap (4 bytes a vertex), more than the " +
        human_bytes(double(limit)) + " allowed here (a quarter of this machine's " +
        human_bytes(double(physical_memory())) + " of memory); use at most about " + std::to_string(side) + "x" +
        std::to_string(side);
}

std::string human_bytes(double bytes) {
    static const char* units[] = {"bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
    int u = 0;
    while (bytes >= 1024.0 && u < 6) {
        bytes /= 1024.0;
        ++u;
    }
    char buf[64];
    std::snprintf(buf, sizeof buf, u == 0 ? "%.0f %s" : "%.1f %s", bytes, units[u]);
    return buf;
}

}  // namespace orogen
