// tectonics:plates through the real orogen binary: check-time errors (exit 2,
// exact words) and identical bytes across thread counts and runs.
#include "orogen_test.hpp"

#include <gtest/gtest.h>

#include <string>

using namespace orogen::test;

namespace {

const char* kHeader = "orogen 1\nseed 5\ngrid 65 cell=10\ncrust = generate:diamond-square(amplitude=50)\n";

RunResult check(const TempDir& dir, const std::string& call) {
    const auto spec =
        dir.write("bad.orogen", std::string(kHeader) + "p = " + call + "\nexport:raw(p, path=\"p.r32\")\n");
    return run_orogen("check " + q(spec));
}

}  // namespace

TEST(PlatesCli, TooManyPlatesForTheGridIsACheckError) {
    TempDir dir;
    const auto r = check(dir, "tectonics:plates(crust, plates=17)");
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find("bad.orogen:5:36: error: tectonics:plates: a 65 × 65 heightmap holds at most 16 plates "
                         "(each needs 16 × 16 samples); ask for fewer plates or a larger grid"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(check(dir, "tectonics:plates(crust, plates=16)").exit_code, 0);
}

TEST(PlatesCli, BadStepsDtPlatesAndDriveAreCheckErrors) {
    TempDir dir;
    const struct {
        const char* call;
        const char* message;
    } cases[] = {
        {"tectonics:plates(crust, plates=1)", "error: 'plates' of tectonics:plates is 1, out of range [2, 256]"},
        {"tectonics:plates(crust, steps=0)", "error: 'steps' of tectonics:plates is 0, out of range [1, 10000000]"},
        {"tectonics:plates(crust, dt=0)", "error: 'dt' of tectonics:plates is 0, out of range (0, 10] s"},
        {"tectonics:plates(crust, dt=-0.5)", "error: 'dt' of tectonics:plates is -0.5, out of range (0, 10] s"},
        {"tectonics:plates(crust, drive=sideways)",
         "error: 'drive' of tectonics:plates is 'sideways', which is not one of still, converge, rotate, shear, "
         "thesis"},
    };
    for (const auto& c : cases) {
        const auto r = check(dir, c.call);
        EXPECT_EQ(r.exit_code, 2) << c.call << "\n" << r.err;
        EXPECT_NE(r.err.find(c.message), std::string::npos) << c.call << "\n" << r.err;
    }
}

TEST(PlatesCli, SameSeedGivesTheSameBytesOnOneAndTwoThreadsAndAcrossRuns) {
    TempDir dir;
    const auto spec = dir.write("p.orogen",
                                std::string(kHeader) +
                                    "p = tectonics:plates(crust, plates=8, steps=300, rift_threshold=5000)\n"
                                    "export:raw(p, path=\"p.r32\")\n"
                                    "export:vtk-plates(p.plates, path=\"plates.pvd\")\n");
    std::string first;
    for (const char* threads : {"1", "2", "2"}) {
        const fs::path out = dir / (std::string("out") + threads + std::to_string(first.size()));
        const auto r = run_orogen("run " + q(spec) + " --quiet --threads " + threads + " --out " + q(out));
        ASSERT_EQ(r.exit_code, 0) << r.err;
        const std::string bytes = slurp(out / "p.r32") + slurp(out / "plates.pvd");
        ASSERT_EQ(slurp(out / "p.r32").size(), 65u * 65u * 4u);
        if (first.empty()) first = bytes;
        else EXPECT_EQ(bytes, first) << "differs with --threads " << threads;
    }
}

// Golden hashes of the shipped plate pipelines' outputs (seed fixed in each
// spec). A change here means the terrain changed: update on purpose, never
// silently (regenerate the docs/images/tectonics-*.png pictures too).
TEST(PlatesCli, ShippedPipelinesKeepTheirGoldenOutputs) {
    struct Golden {
        const char* spec;
        const char* file;
        const char* sha256;
    };
    const Golden goldens[] = {
        {"plates-relief.orogen", "plates-relief.png",
         "ff2a10700a6965e8884a10123c9ac6db66a68ed800c0b69800577c68c767a6c0"},
        {"plates-tectonics.orogen", "plates-tectonics.png",
         "9b3a287fb52b70e96384475b8f9f53d5446fc48d4b205e22b453290daaaea554"},
        {"plates-thesis.orogen", "plates-thesis.png",
         "0b28de4f80cb0d410a92279f479a882412cdd968c6d86033abea38f7abde831e"},
    };
    for (const Golden& g : goldens) {
        TempDir dir;
        const fs::path spec = fs::path(OROGEN_SOURCE_DIR) / "pipelines" / g.spec;
        const auto r = run_orogen("run " + q(spec) + " --quiet --out " + q(dir.path()));
        ASSERT_EQ(r.exit_code, 0) << g.spec << ": " << r.err;
        EXPECT_EQ(orogen::sha256_file(dir / g.file), g.sha256) << g.spec << " → " << g.file;
    }
}
