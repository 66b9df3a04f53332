#include "outputs.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <deque>
#include <fcntl.h>
#include <regex>
#include <sys/file.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace orogen {

namespace {

/// `p` (absolute) with every symbolic link along it replaced by its target, dangling ones included (so a link
/// to a folder that does not exist yet cannot smuggle a path out), and `.`/`..` applied after each link.
fs::path resolve_links(const fs::path& p) {
    std::deque<fs::path> todo(p.begin(), p.end());
    fs::path result = "/";
    if (!todo.empty() && todo.front() == "/") todo.pop_front();
    int hops = 0;
    while (!todo.empty()) {
        const fs::path c = todo.front();
        todo.pop_front();
        if (c.empty() || c == "." || c == "/") continue;
        if (c == "..") {
            result = result.parent_path();
            continue;
        }
        const fs::path next = result / c;
        std::error_code ec;
        const auto st = fs::symlink_status(next, ec);
        if (!ec && fs::is_symlink(st) && hops < 40) {
            ++hops;
            const fs::path target = fs::read_symlink(next, ec);
            if (ec) {
                result = next;
                continue;
            }
            std::vector<fs::path> parts(target.begin(), target.end());
            for (auto it = parts.rbegin(); it != parts.rend(); ++it) todo.push_front(*it);
            if (target.is_absolute()) result = "/";
            continue;
        }
        result = next;
    }
    return result;
}

/// `p` relative to `folder` if strictly inside it, else empty.
fs::path inside_of(const fs::path& p, const fs::path& folder) {
    const fs::path rel = p.lexically_relative(folder);
    if (rel.empty() || rel == "." || *rel.begin() == "..") return {};
    return rel;
}

fs::path real_folder(const fs::path& out_dir) { return resolve_links(fs::absolute(out_dir).lexically_normal()); }

void fsync_folder(const fs::path& folder) {
    const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) return;
    ::fsync(fd);
    ::close(fd);
}

/// Files under a staging folder, relative to it, sorted; its own .lock and .commit left out.
std::vector<fs::path> staged_files(const fs::path& folder) {
    std::vector<fs::path> files;
    std::error_code ec;
    for (fs::recursive_directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
        if (!it->is_regular_file(ec)) continue;
        fs::path rel = it->path().lexically_relative(folder);
        if (rel == ".lock" || rel == ".commit") continue;
        files.push_back(std::move(rel));
    }
    std::sort(files.begin(), files.end());
    return files;
}

/// Move staged files into `out_dir`, `last` after every other one. Folders must exist already.
void move_into_place(const fs::path& folder, const fs::path& out_dir, const std::vector<fs::path>& files,
                     const fs::path& last) {
    auto move = [&](const fs::path& rel) {
        const fs::path from = folder / rel, to = out_dir / rel;
        if (std::rename(from.c_str(), to.c_str()) != 0) {
            const int err = errno;
            throw Error("cannot move " + from.string() + " to " + to.string() + " (" + std::strerror(err) +
                        "); the next run into " + out_dir.string() + " will finish the move");
        }
    };
    for (const auto& f : files)
        if (f != last) move(f);
    if (std::find(files.begin(), files.end(), last) != files.end()) move(last);
    fsync_folder(out_dir);
}

/// Make every folder the staged files go to; none may be or lead outside `out_dir`.
void prepare_folders(const fs::path& out_dir, const std::vector<fs::path>& files) {
    const fs::path out_real = real_folder(out_dir);
    for (const auto& f : files) {
        const fs::path target = out_dir / f;
        std::error_code ec;
        if (f.has_parent_path()) {
            fs::create_directories(target.parent_path(), ec);
            if (ec || !fs::is_directory(target.parent_path(), ec))
                throw Error("cannot write " + target.string() + ": cannot make the folder " +
                            target.parent_path().string() + " (" + (ec ? ec.message() : "a file has that name") +
                            "); the previous outputs are unchanged");
        }
        if (inside_of(resolve_links(out_real / f.parent_path()) / f.filename(), out_real).empty())
            throw Error("cannot write " + target.string() +
                        ": a symbolic link now leads it out of the output folder; the previous outputs are unchanged");
        if (fs::is_directory(fs::symlink_status(target, ec)))
            throw Error("cannot write " + target.string() +
                        ": a folder has that name; the previous outputs are unchanged");
    }
}

std::string plural(std::size_t n, const char* word) { return std::to_string(n) + " " + word + (n == 1 ? "" : "s"); }

}  // namespace

OutputPlace place_output(const fs::path& out_dir, const std::string& path) {
    OutputPlace place;
    const fs::path p(path);
    const fs::path out_real = real_folder(out_dir);
    const fs::path lexical = (p.is_absolute() ? p : out_real / p).lexically_normal();
    place.resolved = resolve_links(lexical);
    place.relative = inside_of(place.resolved, out_real);
    place.inside = !place.relative.empty();
    if (!place.inside) {
        if (p.is_absolute()) place.escape = OutputPlace::Escape::absolute;
        else if (inside_of(lexical, out_real).empty()) place.escape = OutputPlace::Escape::dot_dot;
        else place.escape = OutputPlace::Escape::symlink;
    }
    return place;
}

std::string outside_out_message(const fs::path& out_dir, const std::string& path, const OutputPlace& place) {
    std::string why;
    switch (place.escape) {
        case OutputPlace::Escape::absolute:
            why = "is an absolute path, outside the output folder " + out_dir.string();
            break;
        case OutputPlace::Escape::dot_dot:
            why = "leads out of the output folder " + out_dir.string() + " (to " + place.resolved.string() + ")";
            break;
        default:
            why = "leads out of the output folder " + out_dir.string() + " through a symbolic link (to " +
                place.resolved.string() + ")";
    }
    return "'" + path + "' " + why + "; give a path inside --out, or pass --allow-outside-out to write there";
}

Staging::Staging(const fs::path& out_dir) : out_dir_(out_dir) {
    folder_ = out_dir / (std::string(staging_prefix) + std::to_string(::getpid()));
    std::error_code ec;
    fs::remove_all(folder_, ec);  // our own pid: a dead run's leftover
    fs::create_directories(folder_, ec);
    if (ec)
        throw Error("cannot stage the outputs: cannot make the folder " + folder_.string() + " (" + ec.message() +
                    "); check the permissions of " + out_dir.string());
    lock_fd_ = ::open((folder_ / ".lock").c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0600);
    if (lock_fd_ < 0 || ::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
        const int err = errno;
        fs::remove_all(folder_, ec);
        throw Error("cannot stage the outputs: cannot lock " + (folder_ / ".lock").string() + " (" +
                    std::strerror(err) + ")");
    }
}

Staging::~Staging() {
    // Once marked complete, a staging folder is only ever rolled forward: a failed move leaves it for the next run.
    if (!committed_ && !marked_) {
        std::error_code ec;
        fs::remove_all(folder_, ec);
    }
    if (lock_fd_ >= 0) ::close(lock_fd_);
}

std::vector<fs::path> Staging::files() const { return staged_files(folder_); }

void Staging::commit(const fs::path& last) {
    const auto files = staged_files(folder_);
    prepare_folders(out_dir_, files);
    // From here on the set is complete: a marker says so, and a run killed during the moves is rolled forward.
    {
        const fs::path marker = folder_ / ".commit";
        const int fd = ::open(marker.c_str(), O_CREAT | O_WRONLY | O_TRUNC | O_CLOEXEC, 0600);
        if (fd < 0 || ::fsync(fd) != 0) {
            const int err = errno;
            if (fd >= 0) ::close(fd);
            throw Error("cannot commit the outputs: cannot write " + marker.string() + " (" + std::strerror(err) + ")");
        }
        ::close(fd);
        fsync_folder(folder_);
        marked_ = true;
    }
    move_into_place(folder_, out_dir_, files, last);
    committed_ = true;
    std::error_code ec;
    fs::remove_all(folder_, ec);
}

std::vector<std::string> clean_debris(const fs::path& out_dir) {
    std::vector<std::string> done;
    std::error_code ec;
    if (!fs::is_directory(out_dir, ec)) return done;

    // Staging folders of runs that are gone.
    std::vector<fs::path> stagings;
    for (fs::directory_iterator it(out_dir, ec), end; !ec && it != end; it.increment(ec))
        if (it->path().filename().string().rfind(staging_prefix, 0) == 0 &&
            fs::is_directory(fs::symlink_status(it->path(), ec)))
            stagings.push_back(it->path());
    std::sort(stagings.begin(), stagings.end());
    for (const auto& folder : stagings) {
        const int fd = ::open((folder / ".lock").c_str(), O_RDWR | O_CLOEXEC);
        if (fd >= 0) {
            if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {  // its run is alive
                ::close(fd);
                continue;
            }
        } else {
            // No lock file: the run died between making the folder and locking it, or is just doing so.
            const std::string suffix = folder.filename().string().substr(std::strlen(staging_prefix));
            const long pid = std::strtol(suffix.c_str(), nullptr, 10);
            if (pid > 0 && (::kill(pid_t(pid), 0) == 0 || errno == EPERM)) continue;
        }
        const auto files = staged_files(folder);
        const fs::path name = folder.lexically_relative(out_dir);
        try {
            if (fs::exists(folder / ".commit", ec)) {
                prepare_folders(out_dir, files);
                move_into_place(folder, out_dir, files, "manifest.json");
                done.push_back("finished moving " + plural(files.size(), "file") + " from " + name.string() +
                               " into place: its run was killed while committing its outputs");
            } else {
                std::uintmax_t bytes = 0;
                for (const auto& f : files) bytes += fs::file_size(folder / f, ec);
                done.push_back("removed " + name.string() + ", left by a run that no longer exists (" +
                               plural(files.size(), "file") + ", " + human_bytes(double(bytes)) + ")");
            }
        } catch (const Error& e) {
            done.push_back(std::string("could not finish the commit of ") + name.string() + ": " + e.what());
            if (fd >= 0) ::close(fd);
            continue;
        }
        fs::remove_all(folder, ec);
        if (fd >= 0) ::close(fd);
    }

    // AtomicFile temporaries (".NAME.<pid>.<n>.tmp") of processes that are gone, e.g. from an output written
    // outside the staging folder by a run that was killed.
    static const std::regex temporary(R"(\..+\.([0-9]+)\.[0-9]+\.tmp)");
    std::vector<fs::path> stray;
    std::size_t seen = 0;
    for (fs::recursive_directory_iterator it(out_dir, fs::directory_options::skip_permission_denied, ec), end;
         !ec && it != end && ++seen < 100000; it.increment(ec)) {
        const std::string name = it->path().filename().string();
        if (it->is_directory(ec)) {
            if (name.rfind(staging_prefix, 0) == 0 || it.depth() >= 8 || it->is_symlink(ec))
                it.disable_recursion_pending();
            continue;
        }
        std::smatch m;
        if (!std::regex_match(name, m, temporary)) continue;
        const long pid = std::strtol(m[1].str().c_str(), nullptr, 10);
        if (pid > 0 && ::kill(pid_t(pid), 0) != 0 && errno == ESRCH) stray.push_back(it->path());
    }
    for (const auto& f : stray) {
        const auto bytes = fs::file_size(f, ec);
        if (fs::remove(f, ec))
            done.push_back("removed " + f.lexically_relative(out_dir).string() + " (" + human_bytes(double(bytes)) +
                           "), a temporary file left by a run that no longer exists");
    }
    return done;
}

}  // namespace orogen
