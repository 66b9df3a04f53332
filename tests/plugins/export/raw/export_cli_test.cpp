// The exporters through the real `orogen` binary: files land, bad specs fail
// at check time with exit 2 and say where.
#include "export_test_support.hpp"
#include "orogen_test.hpp"

#include <gtest/gtest.h>

using namespace orogen::test;
namespace fs = std::filesystem;

namespace {

const std::string header = "orogen 1\nseed 7\ngrid 65 cell=10\nbase = generate:fault(iterations=50, displacement=5)\n";

}  // namespace

TEST(ExportCli, EveryFormatIsWritten) {
    TempDir dir;
    const auto spec = dir.write("all.orogen",
                                header +
                                    "worn = erode:thermal(base, iterations=5)\n"
                                    "export:gltf(worn, path=\"t.glb\", scale=2, chunks=2)\n"
                                    "export:gltf(worn, path=\"sub/t.gltf\", decimate=2)\n"
                                    "export:vtk(worn, path=\"t.vti\")\n"
                                    "export:vtk(worn, path=\"t.vtp\", decimate=2)\n"
                                    "export:vdb(worn, path=\"t.vdb\")\n"
                                    "export:raw(worn, path=\"t.r16\")\n"
                                    "export:raw(worn, path=\"t.r32\")\n"
                                    "export:png(worn, path=\"eroded.png\", layer=\"eroded\", bits=16)\n"
                                    "export:png(worn, path=\"shade.png\", hillshade=true)\n");
    const RunResult r = run_orogen("run " + q(spec) + " --out " + q(dir / "out"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    for (const char* f : {"t.glb", "sub/t.gltf", "sub/t.bin", "t.vti", "t.vtp", "t.vdb", "t.r16", "t.r16.json", "t.r32",
                          "t.r32.json", "eroded.png", "shade.png"})
        EXPECT_TRUE(fs::exists(dir / "out" / f)) << f;
    EXPECT_EQ(fs::file_size(dir / "out" / "t.r16"), 65u * 65u * 2u);
    // No temporary file is left anywhere.
    for (const auto& e : fs::recursive_directory_iterator(dir / "out"))
        EXPECT_EQ(e.path().extension() == ".tmp", false) << e.path();
}

TEST(ExportCli, BadExportsFailAtCheckTimeAndSayWhere) {
    TempDir dir;
    const auto spec = dir.write("bad.orogen",
                                header +
                                    "export:gltf(base, path=\"t.obj\")\n"
                                    "export:gltf(base, path=\"u.glb\", decimate=0)\n"
                                    "export:png(base, path=\"w.png\", layer=\"water\")\n"
                                    "export:vtk-particles(base, path=\"p.pvd\")\n"
                                    "export:vtk(base, path=\"v.vti\", decimate=2)\n"
                                    "export:raw(base, path=\"r.r16\", low=5)\n"
                                    "export:vdb(base, path=\"/no/such/folder/t.vdb\")\n");
    const RunResult r = run_orogen("check " + q(spec));
    EXPECT_EQ(r.exit_code, 2) << r.err;
    for (const char* want : {
             "bad.orogen:5:24: error: export:gltf writes .glb, .gltf files; 't.obj' has another extension",
             "bad.orogen:6:42: error: 'decimate' of export:gltf is 0, out of range [1, 4096]",
             "bad.orogen:7:38: error: export:png: no layer 'water' on the input (the input has no layers)",
             "bad.orogen:8:22: error: export:vtk-particles input 1 ('particles') must be a particles, but 'base' is a "
             "heightmap",
             "bad.orogen:9:41: error: export:vtk: decimate applies to .vtp meshes only; .vti keeps every sample",
             "bad.orogen:10:36: error: export:raw: give both low and high (the heights mapped to 0 and 65535), or "
             "neither to use the terrain's own lowest and highest point",
             "bad.orogen:11:23: error: export:vdb: '/no/such/folder/t.vdb' is an absolute path, outside the output "
             "folder out; give a path inside --out, or pass --allow-outside-out to write there",
             "7 errors in ",
         })
        EXPECT_NE(r.err.find(want), std::string::npos) << "missing: " << want << "\n" << r.err;
}

TEST(ExportCli, FailedWriteKeepsTheGoodFile) {
    TempDir dir;
    fs::create_directories(dir / "out");
    std::ofstream(dir / "out" / "t.glb") << "good";
    // A folder stands where the RAW file should go: the write fails (exit 1), names the file,
    // and leaves no temporary behind; other files in the folder are untouched.
    fs::create_directories(dir / "out" / "blocked.r16");
    const auto spec = dir.write("fail.orogen", header + "export:raw(base, path=\"blocked.r16\")\n");
    const RunResult r = run_orogen("run " + q(spec) + " --out " + q(dir / "out"));
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_NE(r.err.find("blocked.r16"), std::string::npos) << r.err;
    EXPECT_TRUE(fs::is_directory(dir / "out" / "blocked.r16"));
    EXPECT_EQ(file_text(dir / "out" / "t.glb"), "good");
    for (const auto& e : fs::directory_iterator(dir / "out")) EXPECT_NE(e.path().extension(), ".tmp") << e.path();
}
