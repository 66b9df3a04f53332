#include <orogen/error.hpp>
#include <orogen/io.hpp>

#include <atomic>
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
    const auto name = "." + target.filename().string() + "." + std::to_string(::getpid()) + "." +
                      std::to_string(counter++) + ".tmp";
    return target.parent_path() / name;
}

void fsync_path(const fs::path& path) {
    int fd = ::open(path.c_str(), O_RDONLY);
    if (fd < 0) return;
    ::fsync(fd);
    ::close(fd);
}

}  // namespace

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
}

AtomicFile::AtomicFile(AtomicFile&& other) noexcept
    : target_(std::move(other.target_)),
      temporary_(std::move(other.temporary_)),
      stream_(std::move(other.stream_)),
      committed_(other.committed_) {
    other.committed_ = true;  // the moved-from object owns nothing
}

AtomicFile::~AtomicFile() {
    if (committed_) return;
    if (stream_.is_open()) stream_.close();
    std::error_code ec;
    fs::remove(temporary_, ec);
}

std::ofstream& AtomicFile::stream() { return stream_; }

void AtomicFile::write(std::span<const std::uint8_t> bytes) {
    stream_.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

namespace {
void flush_checked(AtomicFile& f, std::ofstream& s) {
    if (s.is_open()) {
        s.flush();
        const bool ok = bool(s);
        s.close();
        if (!ok || s.fail())
            throw Error("cannot write " + f.target().string() + ": writing failed (disk full?); the existing file, if any, is unchanged");
    }
    std::error_code ec;
    if (!fs::exists(f.temporary(), ec))
        throw Error("cannot write " + f.target().string() + ": the temporary file " + f.temporary().string() + " vanished");
    fsync_path(f.temporary());
}
}  // namespace

void AtomicFile::commit() {
    AtomicFile* self = this;
    commit_all(std::span<AtomicFile*>(&self, 1));
}

void commit_all(std::span<AtomicFile*> files) {
    for (AtomicFile* f : files)
        if (!f->committed()) flush_checked(*f, f->stream());
    for (AtomicFile* f : files) {
        if (f->committed()) continue;
        if (std::rename(f->temporary().c_str(), f->target().c_str()) != 0) {
            const int err = errno;
            throw Error("cannot write " + f->target().string() + ": rename failed (" + errno_text(err) + ")");
        }
        f->committed_ = true;
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

std::vector<std::uint8_t> read_file(const fs::path& path) {
    std::error_code ec;
    if (!fs::exists(path, ec)) throw BadInput("cannot read " + path.string() + ": no such file");
    if (fs::is_directory(path, ec)) throw BadInput("cannot read " + path.string() + ": it is a folder, not a file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw BadInput("cannot read " + path.string() + ": " + errno_text(errno));
    std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) throw BadInput("cannot read " + path.string() + ": read error");
    return bytes;
}

}  // namespace orogen
