// Test helpers: run the real `orogen` binary on a spec and look at what it did.
#pragma once

#include <orogen/io.hpp>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <sys/wait.h>

namespace orogen::test {

namespace fs = std::filesystem;

/// A fresh folder under the build's temp area, removed at the end of the test.
class TempDir {
public:
    TempDir() {
        static int counter = 0;
        path_ =
            fs::path(OROGEN_BINARY_DIR) / "test-tmp" / (std::to_string(::getpid()) + "-" + std::to_string(counter++));
        fs::remove_all(path_);
        fs::create_directories(path_);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path_, ec);
    }
    const fs::path& path() const { return path_; }
    fs::path operator/(const std::string& name) const { return path_ / name; }
    /// Write `text` to file `name` in this folder; returns its path.
    fs::path write(const std::string& name, const std::string& text) const {
        const fs::path p = path_ / name;
        fs::create_directories(p.parent_path());
        std::ofstream(p, std::ios::binary) << text;
        return p;
    }

private:
    fs::path path_;
};

struct RunResult {
    int exit_code = -1;
    std::string out;  ///< stdout
    std::string err;  ///< stderr
};

inline std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

/// Run `orogen ARGS` (a shell-quoted argument string) with optional extra
/// environment assignments ("OROGEN_PLUGIN_PATH=/x") in folder `cwd` (default:
/// the current one), capturing both streams. OROGEN_PLUGIN_PATH is cleared
/// unless `env` sets it, so the caller's environment cannot change a result;
/// the node cache is off (OROGEN_NO_CACHE=1) unless ARGS pass --cache DIR, so a
/// test neither writes to ~/.cache nor depends on what an earlier run left there.
inline RunResult run_orogen(const std::string& args, const std::string& env = "", const fs::path& cwd = {}) {
    static int counter = 0;
    const fs::path dir = fs::path(OROGEN_BINARY_DIR) / "test-tmp" / "cli";
    fs::create_directories(dir);
    const std::string stem = (dir / (std::to_string(::getpid()) + "-" + std::to_string(counter++))).string();
    const std::string cmd = (cwd.empty() ? "" : "cd '" + cwd.string() + "' && ") +
        "env OROGEN_PLUGIN_PATH= OROGEN_NO_CACHE=1 " + env + " " + std::string(OROGEN_CLI) + " " + args + " >" + stem +
        ".out 2>" + stem + ".err </dev/null";
    const int status = std::system(cmd.c_str());
    RunResult r;
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    r.out = slurp(stem + ".out");
    r.err = slurp(stem + ".err");
    fs::remove(stem + ".out");
    fs::remove(stem + ".err");
    return r;
}

/// Quote a path for the shell.
inline std::string q(const fs::path& p) { return "'" + p.string() + "'"; }

}  // namespace orogen::test
