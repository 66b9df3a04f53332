// Where a run's outputs go, and how they get there all together.
//
// * Confinement: an output path resolves inside --out (after `..` and symbolic
//   links), unless the user allows otherwise (--allow-outside-out).
// * Staging: a run writes its outputs into a hidden folder inside --out,
//   `.orogen-staging-<pid>/`, and moves them into place only once every node has
//   finished, the manifest last. A run that fails or is interrupted removes its
//   staging folder; one that is killed leaves it behind, and the next run into
//   the same folder removes it (or, if the kill came in the middle of the final
//   moves, finishes them) and says so.
// * Liveness: the run holds an flock(2) on `<staging>/.lock` for as long as it
//   lives; the kernel drops the lock when the process dies, however it dies, so
//   a later run never mistakes a live run for a dead one (no pid-reuse guesses).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace orogen {

/// An output path as it lands on disk.
struct OutputPlace {
    std::filesystem::path resolved;  ///< absolute, `..` and existing symbolic links resolved
    std::filesystem::path relative;  ///< relative to the output folder (only if inside)
    bool inside = false;  ///< strictly inside the output folder
    enum class Escape { none, absolute, dot_dot, symlink } escape = Escape::none;
};

/// Resolve `path` (as written in a spec) against the output folder `out_dir`.
OutputPlace place_output(const std::filesystem::path& out_dir, const std::string& path);

/// The one-line reason an output path is refused, naming the path and the flag that allows it.
std::string outside_out_message(const std::filesystem::path& out_dir, const std::string& path,
                                const OutputPlace& place);

/// Prefix of every staging folder's name.
inline constexpr const char* staging_prefix = ".orogen-staging-";

class Staging {
public:
    /// Create `<out_dir>/.orogen-staging-<pid>/` and lock it. Throws orogen::Error naming the folder.
    explicit Staging(const std::filesystem::path& out_dir);
    ~Staging();  ///< removes the staging folder unless committed
    Staging(const Staging&) = delete;
    Staging& operator=(const Staging&) = delete;

    const std::filesystem::path& folder() const { return folder_; }
    /// Every file staged so far, relative to the staging folder (so to --out), sorted.
    std::vector<std::filesystem::path> files() const;
    /// Move every staged file into the output folder, `last` (relative, e.g. "manifest.json") after all the
    /// others, then remove the staging folder. Before the first move, every target folder is made and checked
    /// to be inside --out (a symbolic link planted since the check is refused), so a failure there changes
    /// nothing; a kill during the moves is finished by the next run. Throws orogen::Error.
    void commit(const std::filesystem::path& last);

private:
    std::filesystem::path out_dir_;
    std::filesystem::path folder_;
    int lock_fd_ = -1;
    bool committed_ = false;
    bool marked_ = false;  ///< `.commit` written: the set is complete and must not be thrown away
};

/// Remove the staging folders and stray temporaries of runs whose process no longer exists, or finish the
/// commit of a run killed during its final moves. Returns one human-readable line per thing done.
std::vector<std::string> clean_debris(const std::filesystem::path& out_dir);

}  // namespace orogen
