// The specs in the README and docs/*.md are what a reader copies: every block
// fenced as ```orogen must pass `orogen check` without an error or a warning,
// and a block that holds spec statements but is not fenced as ```orogen (so
// this test would skip it) is itself a failure. A docs change that shows
// syntax the parser rejects, a parameter that no longer exists or a value
// used before it is made fails here, naming the file and the block's line.
#include "orogen_test.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <regex>
#include <vector>

using namespace orogen::test;

namespace {

struct Block {
    std::string file;  ///< relative to the source tree
    int line = 0;  ///< of the opening fence
    std::string info;  ///< what follows the ``` ("orogen", "text", "")
    std::string text;
};

std::vector<std::string> documents() {
    std::vector<std::string> files = {"README.md"};
    std::vector<std::string> docs;
    for (const auto& e : fs::directory_iterator(fs::path(OROGEN_SOURCE_DIR) / "docs"))
        if (e.path().extension() == ".md") docs.push_back("docs/" + e.path().filename().string());
    std::sort(docs.begin(), docs.end());
    files.insert(files.end(), docs.begin(), docs.end());
    return files;
}

std::vector<Block> fenced_blocks(const std::string& file) {
    std::istringstream in(slurp(fs::path(OROGEN_SOURCE_DIR) / file));
    std::vector<Block> blocks;
    std::string line;
    int number = 0;
    bool inside = false;
    while (std::getline(in, line)) {
        ++number;
        if (line.rfind("```", 0) == 0) {
            if (inside) {
                inside = false;
            } else {
                inside = true;
                std::string info = line.substr(3);
                info.erase(0, info.find_first_not_of(' '));
                blocks.push_back({file, number, info, ""});
            }
            continue;
        }
        if (inside) blocks.back().text += line + "\n";
    }
    return blocks;
}

/// A line that starts a spec statement: `name = kind:node(` or `kind:node(`, at the start of the line.
bool has_statement(const std::string& text) {
    static const std::regex statement(R"(^([A-Za-z_][A-Za-z0-9_-]*\s*=\s*)?[a-z]+:[a-z][a-z0-9-]*\()");
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line))
        if (std::regex_search(line, statement)) return true;
    return false;
}

}  // namespace

TEST(Docs, EverySpecBlockInTheReadmeAndDocsPassesCheck) {
    TempDir dir;
    int checked = 0;
    for (const auto& file : documents()) {
        for (const Block& b : fenced_blocks(file)) {
            const std::string where = file + ":" + std::to_string(b.line);
            if (b.info != "orogen") {
                EXPECT_FALSE(b.info.empty() && has_statement(b.text))
                    << where
                    << ": this block holds spec statements but is not fenced as ```orogen, so nothing "
                       "checks it; fence it ```orogen (a whole spec), or ```text if it cannot be checked";
                continue;
            }
            std::string name = where;
            std::replace_if(
                name.begin(), name.end(), [](char c) { return c == '/' || c == ':'; }, '-');
            const fs::path spec = dir.write(name + ".orogen", b.text);
            const RunResult r = run_orogen("check " + q(spec) + " --out " + q(dir / "out"));
            EXPECT_EQ(r.exit_code, 0) << where << ": the spec block fails `orogen check`:\n" << r.err;
            EXPECT_EQ(r.err.find("warning:"), std::string::npos) << where << ": the spec block warns:\n" << r.err;
            ++checked;
        }
    }
    // The README's pipeline, the render, plates, landscape, export and benchmark specs at least.
    EXPECT_GE(checked, 15);
}

// The test's own rule, on a known case: the block docs/render.md once showed, `export:video(render:bloom(spin) ...)`,
// is what the parser must refuse, so a block like it cannot pass unnoticed.
TEST(Docs, ABlockWithSyntaxTheParserRejectsFailsCheck) {
    TempDir dir;
    const fs::path spec = dir.write("bad.orogen",
                                    "orogen 1\ngrid 33 cell=10\nrivers = generate:diamond-square(amplitude=100)\n"
                                    "spin = render:turntable(rivers, frames=2, width=32, height=32)\n"
                                    "export:video(render:bloom(spin) ...)\n");
    const RunResult r = run_orogen("check " + q(spec) + " --out " + q(dir / "out"));
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_TRUE(has_statement("export:video(x)\n"));
    EXPECT_TRUE(has_statement("# a comment\nglow = render:bloom(beauty)\n"));
    EXPECT_FALSE(has_statement("  cut  = generate:fault(bsae, iterations=200)\n"));  // an error message's source line
}

// The README's first spec of one's own is pipelines/starter.orogen as shipped (which the pipelines' tests
// check and run), so the two cannot drift apart.
TEST(Docs, TheReadmesStarterSpecIsTheShippedOne) {
    const std::string shipped = slurp(fs::path(OROGEN_SOURCE_DIR) / "pipelines" / "starter.orogen");
    int found = 0;
    for (const Block& b : fenced_blocks("README.md"))
        if (b.info == "orogen" && b.text.find("A first range of one's own") != std::string::npos) {
            EXPECT_EQ(b.text, shipped) << "README.md:" << b.line << " differs from pipelines/starter.orogen";
            ++found;
        }
    EXPECT_EQ(found, 1) << "README.md shows no (or more than one) starter spec";
}
