// The `orogen` command end to end: diagnostics word for word, the plugin
// seam's failure modes, the runner's error handling, determinism, outputs.
#include <orogen/io.hpp>
#include <orogen/plugin.hpp>

#include <gtest/gtest.h>

#include "orogen_test.hpp"

#include <algorithm>
#include <chrono>
#include <regex>
#include <sstream>

using namespace orogen;
using namespace orogen::test;
namespace fs = std::filesystem;

namespace {

const fs::path bad_specs = fs::path(OROGEN_SOURCE_DIR) / "tests" / "specs" / "bad";
const std::string fake_plugins = OROGEN_FAKE_PLUGIN_DIR;

const char* issue_spec =
    "orogen 1\n"
    "seed 7\n"
    "grid 513 cell=30\n"
    "\n"
    "base = generate:diamond-square(roughness=0.6, amplitude=800)\n"
    "cut  = generate:fault(base, iterations=200, displacement=4)\n"
    "export:png(cut, path=\"cut.png\", bits=16)\n"
    "export:png(base, path=\"base.png\")\n";

std::vector<fs::path> bad_spec_files() {
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(bad_specs))
        if (e.path().extension() == ".orogen") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    return files;
}

}  // namespace

// ------------------------------------------------------------ diagnostics

class BadSpec : public testing::TestWithParam<fs::path> {};

// Each tests/specs/bad/NAME.orogen must give exactly NAME.expected on stderr
// and exit code 2. (OROGEN_UPDATE_GOLDEN=1 rewrites the .expected files.)
TEST_P(BadSpec, GivesExactlyTheExpectedDiagnostics) {
    const fs::path spec = GetParam();
    const RunResult r = run_orogen("check " + spec.filename().string(), "", bad_specs);
    fs::path expected_file = spec;
    expected_file.replace_extension(".expected");
    if (std::getenv("OROGEN_UPDATE_GOLDEN")) std::ofstream(expected_file, std::ios::binary) << r.err;
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.out, "");
    EXPECT_EQ(r.err, slurp(expected_file));
}

INSTANTIATE_TEST_SUITE_P(Specs, BadSpec, testing::ValuesIn(bad_spec_files()),
                         [](const testing::TestParamInfo<fs::path>& info) { return info.param.stem().string(); });

TEST(Cli, AMissingSpecIsRefused) {
    const RunResult r = run_orogen("run no-such.orogen");
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.err, "orogen: error: cannot read spec no-such.orogen: no such file\n");
}

TEST(Cli, AHugeGridIsRefusedBeforeAllocatingWithTheMemoryItNeeds) {
    TempDir dir;
    dir.write("big.orogen", "orogen 1\ngrid 1000000x1000000\nb = generate:fault()\nexport:png(b, path=\"b.png\")\n");
    const RunResult r = run_orogen("run big.orogen --out out", "", dir.path());
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(
        r.err.find("big.orogen:2:6: error: grid 1000000x1000000 needs 3.6 TiB for one heightmap (4 bytes a vertex)"),
        std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(dir / "out"));  // nothing ran, nothing written
}

TEST(Cli, OverridesAreCheckedLikeTheSpec) {
    TempDir dir;
    dir.write("s.orogen", issue_spec);
    RunResult r = run_orogen("check s.orogen --set cut.iterations=-5 --set cut.displacment=3 --set cutt.iterations=3",
                             "", dir.path());
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.err,
              "--set cut.iterations=-5:1:16: error: 'iterations' of generate:fault is -5, out of range [1, 1000000]\n"
              "  cut.iterations=-5\n"
              "                 ^~\n"
              "--set cut.displacment=3:1:5: error: generate:fault ('cut') has no parameter 'displacment'; did you mean "
              "'displacement'?\n"
              "  cut.displacment=3\n"
              "      ^~~~~~~~~~~\n"
              "--set cutt.iterations=3:1:1: error: --set names 'cutt', but the spec has no value or node of that name; "
              "did you mean 'cut'?\n"
              "  cutt.iterations=3\n"
              "  ^~~~\n"
              "3 errors in s.orogen\n");
    r = run_orogen("run s.orogen --out a --quiet", "", dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = run_orogen("run s.orogen --out b --quiet --set cut.iterations=201", "", dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(slurp(dir / "a/base.png"), slurp(dir / "b/base.png"));  // untouched node: same output
    EXPECT_NE(slurp(dir / "a/cut.png"), slurp(dir / "b/cut.png"));
}

// Issue 32, item 3: an unnamed node (an exporter) is reached by its label, as the timing table prints it.
TEST(Cli, OverridesReachUnnamedNodesByTheirLabel) {
    TempDir dir;
    dir.write("s.orogen", issue_spec);  // export:png writes cut.png (16 bits), export:png#2 base.png (8 bits)
    RunResult r = run_orogen("run s.orogen --out a --quiet", "", dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = run_orogen("run s.orogen --out b --quiet --set export:png#2.bits=16 --set export:png.bits=8", "", dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto depth = [&](const std::string& file) { return int(std::uint8_t(slurp(dir / file)[24])); };  // IHDR
    EXPECT_EQ(depth("a/cut.png"), 16);
    EXPECT_EQ(depth("a/base.png"), 8);
    EXPECT_EQ(depth("b/cut.png"), 8);
    EXPECT_EQ(depth("b/base.png"), 16);
    const std::string manifest = slurp(dir / "b/manifest.json");
    EXPECT_NE(manifest.find("export:png#2.bits=16"), std::string::npos) << manifest;

    r = run_orogen("check s.orogen --set export:png#3.bits=8", "", dir.path());
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--set names 'export:png#3', but the spec has no value or node of that name; "
                         "did you mean 'export:png#2'?"),
              std::string::npos)
        << r.err;
}

// Issue 32, item 2: a call may stand where a value goes; it runs as the same node named would.
TEST(Cli, ACallWhereAValueGoesRunsAsTheNamedNodeWould) {
    TempDir dir;
    dir.write("s.orogen",
              "orogen 1\nseed 3\ngrid 65 cell=10\n"
              "base = generate:fault(iterations=20)\n"
              "worn = erode:thermal(base, iterations=5)\n"
              "export:png(worn, path=\"named.png\", bits=16)\n"
              "export:png(erode:thermal(base, iterations=5), path=\"nested.png\", bits=16)\n"
              "export:png(\n    erode:thermal(erode:thermal(base, iterations=2),\n                  iterations=3),\n"
              "    path=\"twice.png\", bits=16)\n");
    const RunResult r = run_orogen("run s.orogen --out out", "", dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string named = slurp(dir / "out/named.png");
    ASSERT_GT(named.size(), 100u);
    EXPECT_EQ(slurp(dir / "out/nested.png"), named);
    EXPECT_NE(slurp(dir / "out/twice.png"), "");
    // The timing table names the unnamed nodes by their labels, which --set takes.
    EXPECT_NE(r.out.find("erode:thermal#2"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("erode:thermal#3"), std::string::npos) << r.out;
    const RunResult set = run_orogen("check s.orogen --set erode:thermal#3.iterations=7", "", dir.path());
    EXPECT_EQ(set.exit_code, 0) << set.err;
    // A side value of a call in place needs a name.
    dir.write("side.orogen",
              "orogen 1\ngrid 65\nc = generate:fault()\nexport:vtk-plates(tectonics:plates(c).plates, "
              "path=\"p.pvd\")\n");
    const RunResult side = run_orogen("check side.orogen", "", dir.path());
    EXPECT_EQ(side.exit_code, 2);
    EXPECT_NE(
        side.err.find("to use a side value of tectonics:plates, name the value first: NAME = tectonics:plates(...) "
                      "on a line of its own, then NAME.plates"),
        std::string::npos)
        << side.err;
}

// The doc errors of issue 32: a value used before its line says where it is; --sed suggests --seed.
TEST(Cli, AValueUsedBeforeItsLineSaysWhereItIsDefined) {
    TempDir dir;
    dir.write("s.orogen",
              "orogen 1\ngrid 65\nlow = generate:fault()\nexport:png(glow2, path=\"g.png\")\n"
              "glow2 = erode:thermal(low)\n");
    const RunResult r = run_orogen("check s.orogen", "", dir.path());
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.err,
              "s.orogen:4:12: error: 'glow2' is not defined yet: it is defined later, on line 5; move that line above "
              "this one (a node reads only values made before it)\n"
              "  export:png(glow2, path=\"g.png\")\n"
              "             ^~~~~\n"
              "1 error in s.orogen\n");
    EXPECT_NE(run_orogen("run s.orogen --sed 3").err.find("unknown option '--sed'; did you mean '--seed'?"),
              std::string::npos);
    EXPECT_NE(run_orogen("run s.orogen --quite").err.find("did you mean '--quiet'?"), std::string::npos);
}

// Issue 32, item 6: the grid's defaults are said, and a spec that writes nothing is warned about.
TEST(Cli, CheckSaysTheGridDefaultsAndWarnsOnASpecThatWritesNothing) {
    TempDir dir;
    dir.write("none.orogen", "orogen 1\nbase = generate:fault()\nworn = erode:thermal(base)\n");
    RunResult r = run_orogen("check none.orogen", "", dir.path());
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.out,
              "none.orogen: ok (2 nodes, grid 513x513 (the default: no grid line), cell 1 m (the default: no "
              "cell=), seed 0)\n");
    EXPECT_EQ(r.err,
              "none.orogen:1:1: warning: this spec writes no files: a run would leave only manifest.json; add an "
              "exporter, e.g. export:png(worn, path=\"worn.png\")\n");
    dir.write("cell.orogen", "orogen 1\ngrid 65\nbase = generate:fault()\nexport:png(base, path=\"b.png\")\n");
    r = run_orogen("check cell.orogen", "", dir.path());
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err, "");
    EXPECT_EQ(r.out, "cell.orogen: ok (2 nodes, grid 65x65, cell 1 m (the default: no cell=), seed 0)\n");
    dir.write("s.orogen", issue_spec);
    EXPECT_EQ(run_orogen("check s.orogen", "", dir.path()).out,
              "s.orogen: ok (4 nodes, grid 513x513, cell 30 m, seed 7)\n");
}

TEST(Cli, UsageErrorsExitWithTwo) {
    EXPECT_EQ(run_orogen("frobnicate").exit_code, 2);
    EXPECT_NE(run_orogen("chek x").err.find("unknown command 'chek'; did you mean 'check'?"), std::string::npos);
    EXPECT_NE(run_orogen("run x.orogen --threads 0").err.find("--threads needs a number from 1 to 1024, got '0'"),
              std::string::npos);
    EXPECT_EQ(run_orogen("help generate:falt").err,
              "orogen: error: unknown node 'generate:falt'; did you mean 'generate:fault'?\n");
    EXPECT_EQ(run_orogen("list generat").exit_code, 2);
}

// --help and -h are help on every command, whatever else the line holds: the usage on stdout, exit 0.
TEST(Cli, HelpOptionWorksOnEveryCommand) {
    for (const char* line : {"run --help", "run spec.orogen -h", "check --help", "analyze --help", "analyze a.r32 -h",
                             "cache --help", "list -h", "--help", "-h"}) {
        const RunResult r = run_orogen(line);
        EXPECT_EQ(r.exit_code, 0) << line << "\n" << r.err;
        EXPECT_NE(r.out.find("orogen run SPEC"), std::string::npos) << line << "\n" << r.out;
        EXPECT_EQ(r.err, "") << line;
    }
}

// A node's own check blames one parameter for a clash; when another was set by --set, the override is shown
// too (the caret on the spec's relief=true alone did not say what the user had just changed).
TEST(Cli, ACrossParameterErrorPointsAtTheOverrideThatCausedIt) {
    TempDir dir;
    dir.write("r.orogen",
              "orogen 1\ngrid 65\nb = generate:fault()\nexport:png(b, path=\"a.png\")\n"
              "export:png(b, path=\"r.png\", relief=true)\n");
    const RunResult r = run_orogen("check r.orogen --set export:png#2.bits=8", "", dir.path());
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("r.orogen:5:36: error: export:png: relief=true writes"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("--set export:png#2.bits=8:1:19: note: 'bits' of export:png#2 is set here, on the command "
                         "line\n  export:png#2.bits=8\n                    ^"),
              std::string::npos)
        << r.err;
}

// A node no loaded plugin provides, nothing like it: the message says where plugins are looked for.
TEST(Cli, AnUnknownNodeSaysWherePluginsComeFrom) {
    TempDir dir;
    dir.write("island.orogen", "orogen 1\nbase = generate:island(size=3)\nexport:png(base, path=\"b.png\")\n");
    const RunResult r = run_orogen("check island.orogen", "", dir.path());
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("unknown node 'generate:island'; did you mean 'generate:shape'? (a plugin of your own: its "
                         "folder in OROGEN_PLUGIN_PATH; `orogen version` lists the folders searched)"),
              std::string::npos)
        << r.err;
}

TEST(Cli, ListHelpAndVersionDescribeThePlugins) {
    RunResult r = run_orogen("list generate");
    ASSERT_EQ(r.exit_code, 0);
    EXPECT_NE(r.out.find("generate:diamond-square"), std::string::npos);
    EXPECT_NE(r.out.find("generate:fault"), std::string::npos);
    EXPECT_EQ(r.out.find("export:png"), std::string::npos);  // filtered by kind

    r = run_orogen("help generate:fault");
    ASSERT_EQ(r.exit_code, 0);
    EXPECT_NE(r.out.find("  iterations       integer      default 200           range [1, 1000000]\n"
                         "      number of fault lines\n"),
              std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("  displacement     number       default 1             range [0, 100000]  unit m\n"),
              std::string::npos)
        << r.out;

    r = run_orogen("version");
    ASSERT_EQ(r.exit_code, 0);
    EXPECT_NE(r.out.find("(plugin API " + std::to_string(OROGEN_PLUGIN_API_VERSION) + ")"), std::string::npos);
    EXPECT_TRUE(std::regex_search(r.out, std::regex("\n  generate-fault +0\\.1\\.0 +.*orogen_generate_fault\\.so\n")));
}

// Every plugin's id is `kind-name` (a process plugin's `process-name`), the folder plugins/<kind>/<name> it is built
// from (its library is orogen_<kind>_<name>.so, with '_' for '-').
TEST(Cli, EveryPluginIdIsKindDashName) {
    auto r = run_orogen("version");
    ASSERT_EQ(r.exit_code, 0);
    const std::regex line("^  (\\S+) +\\S+ +\\S*/orogen_([a-z0-9_]+)\\.so$");
    const std::regex pattern(
        "^(generate|erode|tectonics|render|export|import|analyze|process)-[a-z0-9]+(-[a-z0-9]+)*$");
    std::istringstream in(r.out);
    std::string l;
    int plugins = 0;
    while (std::getline(in, l)) {
        std::smatch m;
        if (!std::regex_match(l, m, line)) continue;
        ++plugins;
        const std::string id = m[1], stem = m[2];
        EXPECT_TRUE(std::regex_match(id, pattern)) << id;
        std::string expected = stem;
        std::replace(expected.begin(), expected.end(), '_', '-');
        EXPECT_EQ(id, expected) << l;
    }
    EXPECT_GE(plugins, 20) << r.out;
}

// ------------------------------------------------------------- plugin seam

TEST(PluginSeam, BrokenPluginsAreRefusedOneByOneAndTheRestStillLoad) {
    TempDir dir;
    dir.write("not-a-library.so", "this is text, not ELF");
    const RunResult r =
        run_orogen("version", "OROGEN_PLUGIN_PATH=" + fake_plugins + ":" + (dir / "not-a-library.so").string());
    ASSERT_EQ(r.exit_code, 0);
    const std::string w = "orogen: warning: plugin ";
    EXPECT_NE(r.err.find(w + fake_plugins +
                         "/wrong_version.so: wrong plugin API version in plugin 'future-plugin': "
                         "got version " +
                         std::to_string(OROGEN_PLUGIN_API_VERSION + 1) + ", supported version is " +
                         std::to_string(OROGEN_PLUGIN_API_VERSION) +
                         "; rebuild the plugin against this orogen's headers; skipped\n"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find(w + fake_plugins +
                         "/no_entry.so: not an orogen plugin: it has no entry point "
                         "'orogen_plugin_info' (define one with OROGEN_PLUGIN(...)); skipped\n"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find(w + (dir / "not-a-library.so").string() + ": cannot load this library ("), std::string::npos)
        << r.err;
    EXPECT_TRUE(std::regex_search(
        r.err,
        std::regex(
            w +
            "node 'generate:fault' is registered twice: by plugin 'generate-fault' \\(.*/orogen_generate_fault\\.so\\) "
            "and by plugin 'fault-clone' \\(" +
            fake_plugins +
            "/duplicate_node\\.so\\); keeping the first\\. "
            "Duplicate library\\? Remove one of them from the plugin path\\.\n")))
        << r.err;
    EXPECT_NE(r.err.find(w + fake_plugins +
                         "/throwing_register.so: plugin 'test-register-throws' failed while "
                         "registering its nodes (cannot find my data files)"),
              std::string::npos)
        << r.err;
    // The good ones, real and fake, are all there.
    EXPECT_NE(r.out.find("  generate-fault "), std::string::npos);
    EXPECT_NE(r.out.find("  generate-diamond-square "), std::string::npos);
    EXPECT_NE(r.out.find("  test-throwing "), std::string::npos);
    EXPECT_EQ(r.out.find("future-plugin"), std::string::npos);
}

TEST(PluginSeam, TheFirstOfTwoDuplicateNodesIsTheOneThatRuns) {
    TempDir dir;
    dir.write("s.orogen", issue_spec);
    const RunResult a = run_orogen("run s.orogen --out a --quiet", "", dir.path());
    const RunResult b = run_orogen("run s.orogen --out b --quiet", "OROGEN_PLUGIN_PATH=" + fake_plugins, dir.path());
    ASSERT_EQ(a.exit_code, 0) << a.err;
    ASSERT_EQ(b.exit_code, 0) << b.err;
    EXPECT_EQ(slurp(dir / "a/cut.png"), slurp(dir / "b/cut.png"));
}

// ------------------------------------------------------------------ runner

namespace {
RunResult run_failing(const TempDir& dir, const std::string& node) {
    dir.write("f.orogen",
              "orogen 1\ngrid 33\nok = generate:fault(iterations=3)\nexport:png(ok, path=\"ok.png\")\n"
              "bad = generate:" +
                  node + "()\nexport:png(bad, path=\"bad.png\")\n");
    return run_orogen("run f.orogen --out out --quiet", "OROGEN_PLUGIN_PATH=" + fake_plugins, dir.path());
}
}  // namespace

TEST(Runner, ANodeErrorNamesTheNodeAndItsLineAndWritesNothing) {
    TempDir dir;
    RunResult r = run_failing(dir, "fails");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_EQ(r.err.substr(r.err.find("f.orogen:")),
              "f.orogen:5:7: error: node 'bad' (generate:fails) failed: the simulation diverged\n"
              "  bad = generate:fails()\n"
              "        ^~~~~~~~~~~~~~\n");
    // All or nothing: the output written before the failure was staged and is gone with the staging folder.
    EXPECT_TRUE(fs::is_empty(dir / "out"));
}

TEST(Runner, ExitCodesFollowTheKindOfFailure) {
    TempDir dir;
    RunResult r = run_failing(dir, "bad-file");
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("node 'bad' (generate:bad-file) failed: input.dat is not a heightmap\n"), std::string::npos);
    r = run_failing(dir, "foreign");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("node 'bad' (generate:foreign) failed: vector::at out of range\n"), std::string::npos);
    r = run_failing(dir, "nan");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("node 'bad' (generate:nan) failed: non-finite height (nan) at sample 5 after step 17; "
                         "the simulation became unstable\n"),
              std::string::npos)
        << r.err;
    r = run_failing(dir, "wrong-type");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("failed: internal error: it returned a nothing but declares a heightmap"), std::string::npos);
}

TEST(Runner, CtrlCStopsTheRunAtTheNextCheckWithExit130) {
    TempDir dir;
    dir.write("s.orogen",
              "orogen 1\ngrid 9\nok = generate:fault()\nexport:png(ok, path=\"ok.png\")\n"
              "s = generate:slow()\nexport:png(s, path=\"slow.png\")\n");
    dir.write("interrupt.sh",
              "cd '" + dir.path().string() +
                  "'\n"
                  "OROGEN_PLUGIN_PATH=" +
                  fake_plugins + " " + OROGEN_CLI +
                  " run s.orogen --out out --quiet 2>err.txt &\n"
                  "pid=$!\n"
                  // ok.png staged: the handler is in place and the slow node is next
                  "until ls out/.orogen-staging-*/ok.png >/dev/null 2>&1; do sleep 0.02; done\n"
                  "kill -INT $pid\nwait $pid\necho $? > rc.txt\n");
    const auto start = std::chrono::steady_clock::now();
    ASSERT_EQ(std::system(("bash '" + (dir / "interrupt.sh").string() + "'").c_str()), 0);
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(20));
    EXPECT_EQ(slurp(dir / "rc.txt"), "130\n");
    EXPECT_NE(slurp(dir / "err.txt").find("error: node 's' (generate:slow) failed: cancelled by the user"),
              std::string::npos)
        << slurp(dir / "err.txt");
    EXPECT_TRUE(fs::is_empty(dir / "out"));  // ok.png was staged only: a stopped run writes nothing
}

TEST(Runner, AnOutputFolderThatCannotBeMadeFailsWithExitOne) {
    TempDir dir;
    dir.write("s.orogen", issue_spec);
    dir.write("a-file", "x");
    const RunResult r = run_orogen("run s.orogen --out a-file/out", "", dir.path());
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("orogen: error: cannot create the output folder a-file/out"), std::string::npos) << r.err;
}

TEST(Runner, AnOutputThatCannotBeWrittenFailsTheRunAndChangesNothing) {
    TempDir dir;
    dir.write("s.orogen",
              "orogen 1\ngrid 33\nok = generate:fault(iterations=3)\n"
              "export:png(ok, path=\"first.png\")\nexport:png(ok, path=\"blocked/second.png\")\n");
    dir.write("out/blocked", "a file where a folder should be");
    const RunResult r = run_orogen("run s.orogen --out out --quiet", "", dir.path());
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(
        r.err.find("s.orogen:5:1: error: node 'export:png#2' (export:png) failed: cannot write "
                   "out/blocked/second.png: out/blocked is a file, not a folder; move it away or write elsewhere\n"),
        std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(dir / "out/first.png"));
    EXPECT_EQ(slurp(dir / "out/blocked"), "a file where a folder should be");
}

// ------------------------------------------------------------------ outputs

TEST(Outputs, TheIssueSpecWritesBothPngsAndAManifestWithTheirHashes) {
    TempDir dir;
    dir.write("s.orogen", issue_spec);
    const RunResult r = run_orogen("run s.orogen --out out", "", dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const GrayImage cut = read_gray_png(dir / "out/cut.png");
    const GrayImage base = read_gray_png(dir / "out/base.png");
    EXPECT_EQ(cut.bits, 16);
    EXPECT_EQ(base.bits, 8);
    EXPECT_EQ(cut.width, 513);
    EXPECT_EQ(cut.height, 513);
    // Min–max normalised: the full range is used, the top is white (the thesis's wrap-around is gone).
    EXPECT_EQ(*std::min_element(cut.samples.begin(), cut.samples.end()), 0);
    EXPECT_EQ(*std::max_element(cut.samples.begin(), cut.samples.end()), 65535);
    EXPECT_EQ(*std::max_element(base.samples.begin(), base.samples.end()), 255);
    const std::string manifest = slurp(dir / "out/manifest.json");
    EXPECT_NE(manifest.find("\"sha256\": \"" + sha256_file(dir / "out/cut.png") + "\""), std::string::npos);
    EXPECT_NE(manifest.find("\"sha256\": \"" + sha256_file(dir / "out/base.png") + "\""), std::string::npos);
    EXPECT_NE(manifest.find("\"seed\": 7,"), std::string::npos);
    EXPECT_NE(manifest.find("\"name\": \"generate-diamond-square\""), std::string::npos);
    // The per-node timing table.
    EXPECT_NE(r.out.find("cut              generate:fault                 6"), std::string::npos) << r.out;
}

TEST(Outputs, TheTimingTableWidensForLongLabels) {
    TempDir dir;
    dir.write("s.orogen",
              "orogen 1\ngrid 33\nthe_mountain_before_any_erosion = generate:fault()\n"
              "export:raw(the_mountain_before_any_erosion, path=\"x.r32\")\n");
    const RunResult r = run_orogen("run s.orogen --out o", "", dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    // Every row's kind:name starts in the header's column, and the line numbers end where "line" does.
    const auto header = r.out.find("node ");
    ASSERT_NE(header, std::string::npos) << r.out;
    const std::string head = r.out.substr(header, r.out.find('\n', header) - header);
    const auto column = head.find("kind:name"), line_end = head.find("line") + 4;
    for (const std::string row : {std::string("the_mountain_before_any_erosion "), std::string("export:raw ")}) {
        const auto at = r.out.find(row, header + head.size());
        ASSERT_NE(at, std::string::npos) << r.out;
        const std::string text = r.out.substr(at, r.out.find('\n', at) - at);
        EXPECT_EQ(text.find_first_not_of(' ', row.size()), column) << r.out;
        EXPECT_NE(text.find_first_of("0123456789", column + 14), std::string::npos);
        EXPECT_EQ(text.find(' ', text.find_first_of("0123456789", column + 14)), line_end) << r.out;
    }
}

TEST(Outputs, SameSpecAndSeedGiveIdenticalBytesWhateverTheThreadCount) {
    TempDir dir;
    dir.write("s.orogen", issue_spec);
    ASSERT_EQ(run_orogen("run s.orogen --out t1 --threads 1 --quiet", "", dir.path()).exit_code, 0);
    ASSERT_EQ(run_orogen("run s.orogen --out t2 --threads 2 --quiet", "", dir.path()).exit_code, 0);
    ASSERT_EQ(run_orogen("run s.orogen --out t2b --threads 2 --quiet", "", dir.path()).exit_code, 0);
    ASSERT_EQ(run_orogen("run s.orogen --out s8 --seed 8 --quiet", "", dir.path()).exit_code, 0);
    for (const char* f : {"cut.png", "base.png"}) {
        EXPECT_EQ(sha256_file(dir / "t1" / f), sha256_file(dir / "t2" / f)) << f;
        EXPECT_EQ(sha256_file(dir / "t2" / f), sha256_file(dir / "t2b" / f)) << f;
        EXPECT_NE(sha256_file(dir / "t1" / f), sha256_file(dir / "s8" / f)) << f;
    }
}

TEST(Outputs, AddingANodeDoesNotChangeTheOthers) {
    TempDir dir;
    dir.write("a.orogen", issue_spec);
    dir.write("b.orogen",
              std::string(issue_spec) +
                  "extra = generate:fault(iterations=9)\n"
                  "export:png(extra, path=\"extra.png\")\n");
    ASSERT_EQ(run_orogen("run a.orogen --out a --quiet", "", dir.path()).exit_code, 0);
    ASSERT_EQ(run_orogen("run b.orogen --out b --quiet", "", dir.path()).exit_code, 0);
    EXPECT_EQ(slurp(dir / "a/cut.png"), slurp(dir / "b/cut.png"));
}

TEST(Outputs, A16BitPngRoundTripsThroughImport) {
    TempDir dir;
    dir.write("make.orogen",
              "orogen 1\nseed 3\ngrid 65x40 cell=5\nt = generate:diamond-square(amplitude=50)\n"
              "export:png(t, path=\"t.png\", bits=16)\n");
    ASSERT_EQ(run_orogen("run make.orogen --out . --quiet", "", dir.path()).exit_code, 0);
    dir.write("again.orogen",
              "orogen 1\nt = import:png(path=\"t.png\", low=-20, high=80)\n"
              "export:png(t, path=\"again.png\", bits=16)\n");
    const RunResult r = run_orogen("run again.orogen --out . --quiet", "", dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(read_gray_png(dir / "t.png").samples, read_gray_png(dir / "again.png").samples);
}

TEST(Outputs, BadPngInputsAreRefusedWithExitTwo) {
    TempDir dir;
    dir.write("text.png", "hello");
    {
        std::vector<std::uint8_t> rgba(8 * 8 * 4, 9);
        AtomicFile f(dir / "colour.png");
        write_rgba_png(f.stream(), 8, 8, rgba);
        f.commit();
        std::vector<std::uint16_t> gray(128 * 128);
        for (std::size_t i = 0; i < gray.size(); ++i) gray[i] = std::uint16_t(i * 40503u);
        AtomicFile g(dir / "whole.png");
        write_gray_png(g.stream(), 128, 128, 16, gray);
        g.commit();
        const auto bytes = read_file(dir / "whole.png");
        std::ofstream(dir / "truncated.png", std::ios::binary)
            .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size() / 3));
    }
    auto import = [&](const std::string& file) {
        dir.write("i.orogen", "orogen 1\nt = import:png(path=\"" + file + "\")\nexport:png(t, path=\"o.png\")\n");
        return run_orogen("run i.orogen --out out --quiet", "", dir.path());
    };
    RunResult r = import("text.png");
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("i.orogen:2:21: error: import:png: cannot read text.png"
                         ": not a PNG file (it does not start with the PNG signature)"),
              std::string::npos)
        << r.err;
    r = import("colour.png");
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("it is an RGBA colour image, but a heightmap must be a grayscale PNG (8 or 16 bits)"),
              std::string::npos)
        << r.err;
    r = import("truncated.png");
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("i.orogen:2:21: error: import:png: cannot read truncated.png: truncated PNG (the file ends at "
                         "byte "),
              std::string::npos)
        << r.err;
    r = import("missing.png");
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("error: no such file: missing.png (looked for"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out/o.png"));
}
