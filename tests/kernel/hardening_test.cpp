// Hostile and unlucky input, end to end: outputs confined to --out, inputs that
// are not regular files, files that declare more than memory holds, and runs
// that fail, are interrupted or are killed (all or nothing, debris cleaned).
#include <orogen/error.hpp>
#include <orogen/io.hpp>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "orogen_test.hpp"

#include <algorithm>
#include <chrono>
#include <csignal>
#include <map>
#include <set>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>
#include <zlib.h>

using namespace orogen;
using namespace orogen::test;
namespace fs = std::filesystem;

namespace {

const std::string fake_plugins = std::string("OROGEN_PLUGIN_PATH=") + OROGEN_FAKE_PLUGIN_DIR;

const char* small_spec = "orogen 1\ngrid 17\nt = generate:fault(iterations=3)\nexport:png(t, path=\"PATH\")\n";

std::string spec_writing(const std::string& path) {
    std::string s = small_spec;
    return s.replace(s.find("PATH"), 4, path);
}

/// Every file under `dir` (relative path → sha256), hidden staging folders included, so debris shows.
std::map<std::string, std::string> files_under(const fs::path& dir) {
    std::map<std::string, std::string> files;
    for (const auto& e : fs::recursive_directory_iterator(dir))
        if (e.is_regular_file()) files[e.path().lexically_relative(dir).string()] = sha256_file(e.path());
    return files;
}

/// The manifest's outputs: path → sha256.
std::map<std::string, std::string> manifest_outputs(const fs::path& dir) {
    std::map<std::string, std::string> out;
    const auto j = nlohmann::json::parse(slurp(dir / "manifest.json"));
    for (const auto& o : j.at("outputs")) out[o.at("path").get<std::string>()] = o.at("sha256").get<std::string>();
    return out;
}

/// The folder holds exactly one complete run: its manifest and the files it lists, hashes matching.
void expect_one_complete_run(const fs::path& dir) {
    auto files = files_under(dir);
    ASSERT_TRUE(files.count("manifest.json")) << dir;
    files.erase("manifest.json");
    EXPECT_EQ(files, manifest_outputs(dir));
}

// ---------------------------------------------------------------- PNG making

void put32(std::string& s, std::uint32_t v) {
    for (int i = 3; i >= 0; --i) s += char((v >> (8 * i)) & 0xff);
}
void chunk(std::string& png, const char* type, const std::string& data) {
    put32(png, std::uint32_t(data.size()));
    std::string body = std::string(type, 4) + data;
    png += body;
    put32(png, std::uint32_t(crc32(0, reinterpret_cast<const Bytef*>(body.data()), uInt(body.size()))));
}
/// A grayscale PNG whose header declares width × height (8 bits) over `idat` bytes of real deflate data.
std::string png_declaring(std::uint32_t width, std::uint32_t height, std::size_t idat) {
    std::string png = "\x89PNG\r\n\x1a\n";
    std::string ihdr;
    put32(ihdr, width);
    put32(ihdr, height);
    ihdr += std::string("\x08\x00\x00\x00\x00", 5);
    chunk(png, "IHDR", ihdr);
    std::vector<Bytef> raw(idat * 64, 0), packed(compressBound(uLong(raw.size())));
    uLongf n = uLongf(packed.size());
    compress(packed.data(), &n, raw.data(), uLong(raw.size()));
    std::string data(reinterpret_cast<const char*>(packed.data()), n);
    while (data.size() < idat) data += data;  // garbage after the stream: still "image data" to count
    chunk(png, "IDAT", data.substr(0, idat));
    chunk(png, "IEND", "");
    return png;
}

}  // namespace

// -------------------------------------------------------------- confinement

TEST(Confinement, DotDotOutOfTheOutputFolderIsRefusedAtCheckTime) {
    TempDir dir;
    dir.write("s.orogen", spec_writing("../escape.png"));
    for (const char* cmd : {"run s.orogen --out out", "check s.orogen --out out"}) {
        const RunResult r = run_orogen(cmd, "", dir.path());
        EXPECT_EQ(r.exit_code, 2) << cmd;
        EXPECT_EQ(r.err.substr(0, r.err.find('\n')),
                  "s.orogen:4:20: error: export:png: '../escape.png' leads out of the output folder out (to " +
                      fs::canonical(dir.path()).string() +
                      "/escape.png); give a path inside --out, or pass --allow-outside-out to write there")
            << r.err;
    }
    EXPECT_FALSE(fs::exists(dir / "escape.png"));
    EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(Confinement, AnAbsolutePathIsRefusedUnlessAllowed) {
    TempDir dir;
    const fs::path target = dir / "elsewhere/abs.png";
    fs::create_directories(target.parent_path());
    dir.write("s.orogen", spec_writing(target.string()));
    RunResult r = run_orogen("run s.orogen --out out --quiet", "", dir.path());
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("error: export:png: '" + target.string() +
                         "' is an absolute path, outside the output folder out; give a path inside --out, or pass "
                         "--allow-outside-out to write there\n"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(target));
    r = run_orogen("run s.orogen --out out --quiet --allow-outside-out", "", dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(read_gray_png(target).width, 17);
    EXPECT_EQ(manifest_outputs(dir / "out").at(target.string()), sha256_file(target));
}

TEST(Confinement, ASymbolicLinkInsideTheOutputFolderPointingOutIsRefused) {
    TempDir dir;
    fs::create_directories(dir / "out");
    fs::create_directories(dir / "outside");
    fs::create_directory_symlink("../outside", dir / "out/link");
    fs::create_symlink("../victim.png", dir / "out/victim.png");  // the file itself a link, dangling even
    dir.write("a.orogen", spec_writing("link/a.png"));
    dir.write("b.orogen", spec_writing("victim.png"));
    RunResult r = run_orogen("check a.orogen --out out", "", dir.path());
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("error: export:png: 'link/a.png' leads out of the output folder out through a symbolic "
                         "link (to " +
                         fs::canonical(dir.path()).string() +
                         "/outside/a.png); give a path inside "
                         "--out, or pass --allow-outside-out to write there\n"),
              std::string::npos)
        << r.err;
    r = run_orogen("run b.orogen --out out", "", dir.path());
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("'victim.png' leads out of the output folder out through a symbolic link (to " +
                         fs::canonical(dir.path()).string() + "/victim.png)"),
              std::string::npos)
        << r.err;
    EXPECT_TRUE(fs::is_empty(dir / "outside"));
    EXPECT_FALSE(fs::exists(dir / "victim.png"));
}

TEST(Confinement, TheOutputFolderItselfMayBeASymbolicLink) {
    TempDir dir;
    fs::create_directories(dir / "real");
    fs::create_directory_symlink("real", dir / "out");
    dir.write("s.orogen", spec_writing("t.png"));
    const RunResult r = run_orogen("run s.orogen --out out --quiet", "", dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(read_gray_png(dir / "real/t.png").width, 17);
    expect_one_complete_run(dir / "real");
}

TEST(Confinement, NamesWithFoldersThatStayInsideAreAllowed) {
    TempDir dir;
    dir.write("s.orogen", spec_writing("a/b/../c/t.png"));
    const RunResult r = run_orogen("run s.orogen --out out --quiet", "", dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(read_gray_png(dir / "out/a/c/t.png").width, 17);
    expect_one_complete_run(dir / "out");
    EXPECT_TRUE(manifest_outputs(dir / "out").count("a/c/t.png"));
}

// ------------------------------------------------------ inputs: files only

TEST(Inputs, AFifoOrADeviceIsRefusedAtOnceNotReadForever) {
    TempDir dir;
    ASSERT_EQ(::mkfifo((dir / "pipe.png").c_str(), 0600), 0);
    ASSERT_EQ(::mkfifo((dir / "pipe.orogen").c_str(), 0600), 0);
    dir.write("fifo.orogen", "orogen 1\nt = import:png(path=\"pipe.png\")\nexport:png(t, path=\"o.png\")\n");
    dir.write("dev.orogen", "orogen 1\nt = import:png(path=\"/dev/zero\")\nexport:png(t, path=\"o.png\")\n");
    // `timeout` turns a hang into a failure rather than a stuck suite.
    RunResult r = run_orogen("run fifo.orogen --out out", "timeout 20", dir.path());
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("fifo.orogen:2:21: error: pipe.png is a FIFO (named pipe), not a regular file; give a file "
                         "(orogen reads only regular files)\n"),
              std::string::npos)
        << r.err;
    r = run_orogen("check dev.orogen", "timeout 20", dir.path());
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("dev.orogen:2:21: error: /dev/zero is a character device, not a regular file"),
              std::string::npos)
        << r.err;
    r = run_orogen("check pipe.orogen", "timeout 20", dir.path());
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.err,
              "orogen: error: cannot read pipe.orogen: it is a FIFO (named pipe), not a regular file; give a "
              "file (orogen reads only regular files)\n");
    EXPECT_FALSE(fs::exists(dir / "out/o.png"));
}

// ------------------------------------------------------- bounded decoding

TEST(BoundedPng, AHugeDeclaredSizeFailsFastInLittleMemory) {
    TempDir dir;
    const std::string png = png_declaring(100000, 100000, 3000);
    ASSERT_LT(png.size(), 4000u);
    dir.write("huge.png", png);
    // Read it in a child, so its peak memory and CPU time are its own (getrusage of the child).
    int fds[2];
    ASSERT_EQ(::pipe(fds), 0);
    const pid_t pid = ::fork();
    if (pid == 0) {
        std::string message = "no error";
        try {
            read_gray_png(dir / "huge.png");
        } catch (const std::exception& e) { message = e.what(); }
        (void)!::write(fds[1], message.data(), message.size());
        ::_exit(0);
    }
    ::close(fds[1]);
    std::string message;
    char buf[512];
    for (ssize_t n; (n = ::read(fds[0], buf, sizeof buf)) > 0;) message.append(buf, std::size_t(n));
    ::close(fds[0]);
    int status = 0;
    struct rusage usage {};
    ASSERT_EQ(::wait4(pid, &status, 0, &usage), pid);
    EXPECT_EQ(message.substr(0, message.find(" more than")),
              "cannot read " + (dir / "huge.png").string() +
                  ": its header declares 100000x100000 pixels, which needs 37.3 GiB for one heightmap (4 bytes a "
                  "vertex),");
    EXPECT_NE(message.find("a quarter of this machine's"), std::string::npos) << message;
    const double cpu = double(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
        1e-6 * double(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
    std::printf("reading the 100000x100000 PNG: %.3f s of CPU, peak RSS %.1f MB\n", cpu, usage.ru_maxrss / 1024.0);
    EXPECT_LT(cpu, 1.0);  // seconds of CPU, not wall time: load cannot move it
    EXPECT_LT(usage.ru_maxrss, 100 * 1024);  // KiB: under 100 MB peak
}

TEST(BoundedPng, TheCliRefusesItAtCheckTime) {
    TempDir dir;
    dir.write("huge.png", png_declaring(100000, 100000, 3000));
    dir.write("i.orogen", "orogen 1\nt = import:png(path=\"huge.png\")\nexport:png(t, path=\"o.png\")\n");
    const RunResult r = run_orogen("run i.orogen --out out", "", dir.path());
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("i.orogen:2:21: error: import:png: cannot read huge.png: its header declares 100000x100000 "
                         "pixels, which needs 37.3 GiB for one heightmap (4 bytes a vertex), more than the "),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(BoundedPng, TooLittleImageDataForTheDeclaredSizeFailsBeforeDecoding) {
    TempDir dir;
    dir.write("thin.png", png_declaring(4000, 4000, 10));
    EXPECT_THROW(
        {
            try {
                read_gray_png_header(dir / "thin.png");
            } catch (const BadInput& e) {
                EXPECT_EQ(std::string(e.what()),
                          "cannot read " + (dir / "thin.png").string() +
                              ": damaged PNG (its 4000x4000 pixels need at least 15.1 KiB of "
                              "compressed image data, but it holds 10 bytes)");
                throw;
            }
        },
        BadInput);
}

TEST(BoundedPng, ACutFileIsRefusedFromItsChunksWithoutDecoding) {
    TempDir dir;
    std::vector<std::uint16_t> gray(128 * 128);
    for (std::size_t i = 0; i < gray.size(); ++i) gray[i] = std::uint16_t(i * 40503u);
    AtomicFile g(dir / "whole.png");
    write_gray_png(g.stream(), 128, 128, 16, gray);
    g.commit();
    std::string bytes = slurp(dir / "whole.png");
    const std::size_t cut = bytes.size() / 3;
    dir.write("cut.png", bytes.substr(0, cut));
    try {
        read_gray_png_header(dir / "cut.png");
        FAIL() << "a cut PNG was read";
    } catch (const BadInput& e) {
        const std::string m = e.what();
        EXPECT_EQ(m.substr(0, m.find(", inside")),
                  "cannot read " + (dir / "cut.png").string() + ": truncated PNG (the file ends at byte " +
                      std::to_string(cut));
        EXPECT_NE(m.find("; the end marker IEND is missing); it was cut short: copy it again"), std::string::npos) << m;
    }
}

// ------------------------------------------------------ all or nothing

namespace {

/// A run with several outputs (one of them two files) and a slow node between them.
const char* multi_spec =
    "orogen 1\ngrid 33\n"
    "a = generate:fault(iterations=5)\n"
    "export:png(a, path=\"a.png\", bits=16)\n"
    "export:raw(a, path=\"sub/a.r16\")\n"
    "s = generate:slow(seconds=0)\n"
    "export:png(a, path=\"b.png\")\n";

pid_t spawn_orogen(const fs::path& cwd, const std::vector<std::string>& args, const fs::path& err) {
    const pid_t pid = ::fork();
    if (pid == 0) {
        if (::chdir(cwd.c_str()) != 0) ::_exit(127);
        ::setenv("OROGEN_PLUGIN_PATH", OROGEN_FAKE_PLUGIN_DIR, 1);
        std::FILE* e = std::freopen(err.c_str(), "w", stderr);
        (void)e;
        std::vector<char*> argv{const_cast<char*>(OROGEN_CLI)};
        for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        ::execv(OROGEN_CLI, argv.data());
        ::_exit(127);
    }
    return pid;
}

/// Files in the run's staging folder (hidden, in `out`), or -1 while there is none.
int staged_count(const fs::path& out) {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(out, ec)) {
        if (e.path().filename().string().rfind(".orogen-staging-", 0) != 0) continue;
        int n = 0;
        for (const auto& f : fs::recursive_directory_iterator(e.path(), ec))
            if (f.is_regular_file() && f.path().filename() != ".lock" && f.path().extension() != ".tmp") ++n;
        return n;
    }
    return -1;
}

bool has_staging(const fs::path& out) { return staged_count(out) >= 0; }

}  // namespace

TEST(AllOrNothing, AFailedRunLeavesThePreviousCompleteRun) {
    TempDir dir;
    dir.write("m.orogen", multi_spec);
    ASSERT_EQ(run_orogen("run m.orogen --out out --quiet --seed 1", fake_plugins, dir.path()).exit_code, 0);
    const auto before = files_under(dir / "out");
    EXPECT_EQ(before.size(), 5u);  // a.png, sub/a.r16, sub/a.r16.json, b.png, manifest.json
    expect_one_complete_run(dir / "out");
    std::string failing = multi_spec;
    failing.replace(failing.find("generate:slow(seconds=0)"), 24, "generate:fails(a)");
    dir.write("f.orogen", failing);
    const RunResult r = run_orogen("run f.orogen --out out --quiet --seed 2", fake_plugins, dir.path());
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_EQ(files_under(dir / "out"), before);  // nothing of the failed run, no staging left
}

TEST(AllOrNothing, SigtermStopsLikeCtrlCWithExit143AndRemovesTheStaging) {
    TempDir dir;
    std::string spec = multi_spec;
    spec.replace(spec.find("seconds=0"), 9, "seconds=60");
    dir.write("m.orogen", spec);
    const pid_t pid = spawn_orogen(dir.path(), {"run", "m.orogen", "--out", "out", "--quiet"}, dir / "err.txt");
    while (staged_count(dir / "out") < 3) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    ::kill(pid, SIGTERM);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 143);
    EXPECT_NE(slurp(dir / "err.txt").find("error: node 's' (generate:slow) failed: stopped by SIGTERM\n"),
              std::string::npos)
        << slurp(dir / "err.txt");
    EXPECT_TRUE(files_under(dir / "out").empty());  // no output, no staging, no temporaries
}

TEST(AllOrNothing, ASecondCtrlCEndsAtOnceAndTheNextRunCleansUp) {
    TempDir dir;
    dir.write("m.orogen",
              "orogen 1\ngrid 9\na = generate:fault()\nexport:png(a, path=\"a.png\")\n"
              "s = generate:stubborn()\n");
    const auto start = std::chrono::steady_clock::now();
    const pid_t pid = spawn_orogen(dir.path(), {"run", "m.orogen", "--out", "out", "--quiet"}, dir / "err.txt");
    // Once the stubborn node runs (a Ctrl-C before it would be seen by the runner's check between nodes and
    // end the run politely with 130).
    while (!fs::exists(dir / "stubborn.started")) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    ::kill(pid, SIGINT);  // the stubborn node does not look
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    ::kill(pid, SIGINT);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(20));  // not the node's 30 s
    ASSERT_TRUE(WIFSIGNALED(status));
    EXPECT_EQ(WTERMSIG(status), SIGINT);
    EXPECT_TRUE(has_staging(dir / "out"));
    dir.write("ok.orogen", spec_writing("t.png"));
    const RunResult r = run_orogen("run ok.orogen --out out --quiet", "", dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string note =
        "orogen: removed .orogen-staging-" + std::to_string(pid) + ", left by a run that no longer exists (1 file, ";
    EXPECT_EQ(r.err.substr(0, note.size()), note) << r.err;
    EXPECT_EQ(r.err.back(), '\n');
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(has_staging(dir / "out"));
    expect_one_complete_run(dir / "out");
}

// A child run is killed (SIGKILL: no handler runs) at several points; each time the folder still holds the
// previous complete run, and the next run removes the debris, saying so.
TEST(AllOrNothing, SigkillAtAnyPointLeavesThePreviousCompleteRun) {
    TempDir dir;
    std::string spec = multi_spec;
    dir.write("quick.orogen", spec);
    spec.replace(spec.find("seconds=0"), 9, "seconds=60");
    dir.write("slow.orogen", spec);
    ASSERT_EQ(run_orogen("run quick.orogen --out out --quiet --seed 1", fake_plugins, dir.path()).exit_code, 0);
    const auto complete = files_under(dir / "out");
    expect_one_complete_run(dir / "out");

    pid_t previous = 0;
    for (int point : {0, 1, 3}) {  // staging made, first output staged, three outputs staged (slow node running)
        SCOPED_TRACE("killed with " + std::to_string(point) + " files staged");
        const pid_t pid =
            spawn_orogen(dir.path(), {"run", "slow.orogen", "--out", "out", "--quiet", "--seed", "2"}, dir / "err.txt");
        while (staged_count(dir / "out") < point ||
               (previous && fs::exists(dir / "out" / (".orogen-staging-" + std::to_string(previous)))))
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
        ::kill(pid, SIGKILL);
        int status = 0;
        ASSERT_EQ(::waitpid(pid, &status, 0), pid);
        ASSERT_TRUE(WIFSIGNALED(status));
        ASSERT_TRUE(fs::is_directory(dir / "out" / (".orogen-staging-" + std::to_string(pid))));
        auto now = files_under(dir / "out");
        std::erase_if(now, [](const auto& kv) { return kv.first.rfind(".orogen-staging-", 0) == 0; });
        EXPECT_EQ(now, complete);  // the previous run, whole; its manifest matches (checked above)
        if (previous)  // each run first removed the debris of the one killed before it, and said so
            EXPECT_NE(slurp(dir / "err.txt")
                          .find("orogen: removed .orogen-staging-" + std::to_string(previous) +
                                ", left by a run that no longer exists ("),
                      std::string::npos)
                << slurp(dir / "err.txt");
        previous = pid;
    }
    // The next run removes the last killed run's staging folder, says so, and leaves one complete run.
    const RunResult r = run_orogen("run quick.orogen --out out --quiet --seed 3", fake_plugins, dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("orogen: removed .orogen-staging-" + std::to_string(previous) +
                         ", left by a run that no longer exists (3 files, "),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(has_staging(dir / "out"));
    expect_one_complete_run(dir / "out");
    EXPECT_NE(files_under(dir / "out"), complete);  // seed 3's run, not seed 1's
}

// A run killed in the middle of its final moves leaves a staging folder marked as complete; the next run
// finishes the moves (the set is whole) rather than leaving a mixed folder.
TEST(AllOrNothing, AKillDuringTheFinalMovesIsRolledForward) {
    TempDir dir;
    dir.write("m.orogen", multi_spec);
    ASSERT_EQ(run_orogen("run m.orogen --out out --quiet --seed 1", fake_plugins, dir.path()).exit_code, 0);
    ASSERT_EQ(run_orogen("run m.orogen --out donor --quiet --seed 2", fake_plugins, dir.path()).exit_code, 0);
    // What a run killed after moving a.png (and before the rest) leaves: a.png moved, the rest staged + marker.
    const fs::path staging = dir / "out/.orogen-staging-999999999";
    for (const char* f : {"sub/a.r16", "sub/a.r16.json", "b.png", "manifest.json"}) {
        fs::create_directories((staging / f).parent_path());
        fs::copy_file(dir / "donor" / f, staging / f);
    }
    dir.write("out/.orogen-staging-999999999/.lock", "");
    dir.write("out/.orogen-staging-999999999/.commit", "");
    fs::copy_file(dir / "donor/a.png", dir / "out/a.png", fs::copy_options::overwrite_existing);
    // A run that fails still cleans up first: afterwards the folder is the killed run's set, whole.
    std::string failing = multi_spec;
    failing.replace(failing.find("generate:slow(seconds=0)"), 24, "generate:fails(a)");
    dir.write("f.orogen", failing);
    const RunResult r = run_orogen("run f.orogen --out out --quiet", fake_plugins, dir.path());
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("orogen: finished moving 4 files from .orogen-staging-999999999 into place: its run was "
                         "killed while committing its outputs\n"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(files_under(dir / "out"), files_under(dir / "donor"));
}

TEST(AllOrNothing, StrayTemporariesOfDeadProcessesAreRemovedAndNamed) {
    TempDir dir;
    dir.write("out/deep/.t.glb.999999999.0.tmp", std::string(3000, 'x'));
    dir.write("out/.keep.me.tmp", "not ours");
    dir.write("s.orogen", spec_writing("t.png"));
    const RunResult r = run_orogen("run s.orogen --out out --quiet", "", dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err,
              "orogen: removed deep/.t.glb.999999999.0.tmp (2.9 KiB), a temporary file left by a run that "
              "no longer exists\n");
    EXPECT_FALSE(fs::exists(dir / "out/deep/.t.glb.999999999.0.tmp"));
    EXPECT_TRUE(fs::exists(dir / "out/.keep.me.tmp"));
}

TEST(Inputs, ImportRawReadsWhatExportRawWroteAndRefusesACutFileAtCheckTime) {
    TempDir dir;
    dir.write("w.orogen",
              "orogen 1\ngrid 33 cell=7\nt = generate:fault(iterations=9)\nexport:raw(t, path=\"t.r32\")\n"
              "export:png(t, path=\"t.png\", bits=16)\n");
    ASSERT_EQ(run_orogen("run w.orogen --out . --quiet", "", dir.path()).exit_code, 0);
    dir.write("r.orogen", "orogen 1\nt = import:raw(path=\"t.r32\")\nexport:png(t, path=\"again.png\", bits=16)\n");
    RunResult r = run_orogen("run r.orogen --out . --quiet", "", dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(slurp(dir / "t.png"), slurp(dir / "again.png"));
    std::filesystem::resize_file(dir / "t.r32", 100);
    r = run_orogen("run r.orogen --out out --quiet", "", dir.path());
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("r.orogen:2:21: error: import:raw: cannot read t.r32: it holds 100 bytes, but its sidecar's "
                         "33x33 32-bit samples need exactly 4356; it is truncated\n"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(dir / "out"));
}

// The lock, not the pid number, tells a live run from a dead one: a staging folder whose lock is held is left
// alone even when no process has its pid (pids are reused, or belong to another pid namespace); once the lock
// is free, the next run removes it.
TEST(AllOrNothing, AStagingFolderWhoseLockIsHeldIsLeftAlone) {
    TempDir dir;
    dir.write("out/.orogen-staging-999999999/x.png", "staged by a live run");
    const fs::path lock = dir / "out/.orogen-staging-999999999/.lock";
    const int fd = ::open(lock.c_str(), O_CREAT | O_RDWR, 0600);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
    dir.write("s.orogen", spec_writing("t.png"));
    RunResult r = run_orogen("run s.orogen --out out --quiet", "", dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err, "");
    EXPECT_EQ(slurp(dir / "out/.orogen-staging-999999999/x.png"), "staged by a live run");
    ::close(fd);  // the "run" ends
    r = run_orogen("run s.orogen --out out --quiet", "", dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err,
              "orogen: removed .orogen-staging-999999999, left by a run that no longer exists (1 file, 20 bytes)\n");
    EXPECT_FALSE(fs::exists(dir / "out/.orogen-staging-999999999"));
}
