// Helpers shared by the exporters' tests (raw, gltf, vtk, vdb): terrains to
// write and places where writing fails.
#pragma once

#include <orogen/grid.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/mount.h>
#include <unistd.h>
#include <vector>

namespace orogen::test {

/// A smooth, non-trivial terrain in metres: hills plus a slope, `w` × `h` samples.
inline std::vector<float> hills(int w, int h, double amplitude = 300.0) {
    std::vector<float> v(std::size_t(w) * std::size_t(h));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const double u = double(x) / (w - 1), t = double(y) / (h - 1);
            v[std::size_t(y) * std::size_t(w) + std::size_t(x)] =
                float(amplitude * (0.5 + 0.3 * std::sin(6.1 * u) * std::cos(4.3 * t) + 0.2 * u * t) - 40.0);
        }
    return v;
}

/// Names of the entries of a folder, sorted.
inline std::vector<std::string> folder_entries(const std::filesystem::path& dir) {
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(dir)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

inline std::string file_text(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

/// A folder no file can be created in, even by root: /proc refuses new files.
inline std::filesystem::path unwritable_folder() { return "/proc"; }

/// A tiny tmpfs (64 KiB) mounted on `dir` to simulate a full disk; unmounted
/// at the end. available() is false where mounting is not permitted (not
/// root, no CAP_SYS_ADMIN): the test then skips with a visible message.
class TinyDisk {
public:
    explicit TinyDisk(std::filesystem::path dir) : dir_(std::move(dir)) {
        std::filesystem::create_directories(dir_);
        mounted_ = ::mount("orogen-test", dir_.c_str(), "tmpfs", 0, "size=64k") == 0;
    }
    ~TinyDisk() {
        if (mounted_) ::umount2(dir_.c_str(), MNT_DETACH);
    }
    bool available() const { return mounted_; }
    const std::filesystem::path& path() const { return dir_; }

private:
    std::filesystem::path dir_;
    bool mounted_ = false;
};

#define OROGEN_SKIP_WITHOUT_TINY_DISK(disk)                                                            \
    if (!(disk).available())                                                                           \
    GTEST_SKIP() << "SKIPPED: cannot mount a 64 KiB tmpfs here (needs root or CAP_SYS_ADMIN), so the " \
                    "disk-full case is not tested"

}  // namespace orogen::test
