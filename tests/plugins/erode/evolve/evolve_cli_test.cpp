// erode:evolve end to end through the real binary: a body of process plugins gives the bytes of
// erode:stream-power with the same settings (on one thread and two), --set reaches a process's
// parameter, a process's stability limit is a check-time error, `orogen list` and `orogen help` show
// the processes, and a process written outside the tree (tests/kernel/external_process) joins the loop.
#include "orogen_test.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

namespace {

using namespace orogen::test;

std::string bytes_of(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The default's terrain on a small grid, for a few steps: the plates' uplift layer, the rock's beds,
// folds, faults and facies, banks, floodplains and landslides all at work.
const char* kHead =
    "orogen 1\n"
    "seed 7\n"
    "grid 129 cell=30\n"
    "crust  = generate:diamond-square(roughness=0.6, amplitude=250)\n"
    "plates = tectonics:plates(crust, plates=6, steps=80, height=40, trench_depth=0, rift_depth=0)\n"
    "core   = generate:range(plates, from=(0.05, 0.6), to=(0.95, 0.4), iterations=30, cones=20, height=3,\n"
    "                        uplift=true)\n";

const char* kWhole =
    "range = erode:stream-power(core, years=4e5, dt=5e4, substeps=2, uplift=1, uplift_layer=\"uplift\",\n"
    "    uplift_layer_years=4.5e5, uplift_smoothing=2000, m=0.5, erodibility=1.25e-5, diffusivity=1.2,\n"
    "    channel_area=4e4, landslide_angle=35, landslide_block_spread=0.75, bed_thickness=150, bed_dip=20,\n"
    "    bed_dip_toward=30, bed_angle_spread=24, bed_erodibility_contrast=4, bed_fold_amplitude=700,\n"
    "    bed_fault_spacing=1000, bed_fault_throw=300, bed_facies_length=300, bed_facies_share=0.8,\n"
    "    bank_erosion=6, bank_area=3e4, bank_floor_slope=2, bank_wide_area=2e5, bank_wider_area=6e5,\n"
    "    bank_widest_floor=9, floodplain_area=2e5, floodplain_max_slope=4, floodplain_slope=6, open=\"ns\",\n"
    "    rain=orographic, wind_from=200, rain_resolution=300)\n";

const char* kLoop =
    "range = erode:evolve(core, years=4e5, dt=5e4, substeps=2, open=\"ns\") {\n"
    "    uplift(rate=1, layer=\"uplift\", layer_years=4.5e5, smoothing=2000)\n"
    "    rain(wind_from=200, resolution=300)\n"
    "    flow()\n"
    "    creep(diffusivity=1.2)\n"
    "    rock(thickness=150, dip=20, dip_toward=30, angle=35, angle_spread=24, block_spread=0.75,\n"
    "         erodibility_contrast=4, fold_amplitude=700, fault_spacing=1000, fault_throw=300,\n"
    "         facies_length=300, facies_share=0.8)\n"
    "    stream-power(m=0.5, erodibility=1.25e-5, channel_area=4e4)\n"
    "    banks(erosion=6, area=3e4, floor_slope=2, wide_area=2e5, wider_area=6e5, widest_floor=9)\n"
    "    floodplains(area=2e5, max_slope=4, slope=6)\n"
    "    landslides(angle=35)\n"
    "}\n";

const char* kTail =
    "export:raw(range, path=\"terrain.r32\")\n"
    "export:vtk(range, path=\"terrain.vti\")\n";

TEST(Evolve, AProcessListGivesTheBytesOfStreamPowerOnOneThreadAndTwo) {
    TempDir dir;
    const auto whole = dir.write("whole.orogen", std::string(kHead) + kWhole + kTail);
    const auto loop = dir.write("loop.orogen", std::string(kHead) + kLoop + kTail);
    std::string reference;
    for (const char* threads : {"1", "2"}) {
        const std::string a = (dir / ("whole" + std::string(threads))).string();
        const std::string b = (dir / ("loop" + std::string(threads))).string();
        ASSERT_EQ(run_orogen("run " + q(whole) + " --quiet --threads " + threads + " --out " + q(a)).exit_code, 0);
        const RunResult r = run_orogen("run " + q(loop) + " --threads " + threads + " --out " + q(b));
        ASSERT_EQ(r.exit_code, 0) << r.err;
        // The summary names each process's own figures.
        EXPECT_NE(r.err.find("flow: "), std::string::npos) << r.err;
        EXPECT_NE(r.err.find(" pits resolved"), std::string::npos) << r.err;
        for (const char* file : {"terrain.r32", "terrain.vti"}) {
            const std::string x = bytes_of(std::filesystem::path(a) / file),
                              y = bytes_of(std::filesystem::path(b) / file);
            ASSERT_GE(x.size(), 129u * 129u * 4u) << file;
            EXPECT_TRUE(x == y) << file << " differs between erode:stream-power and erode:evolve on " << threads
                                << " thread(s)";
        }
        if (reference.empty()) reference = bytes_of(std::filesystem::path(b) / "terrain.r32");
        else EXPECT_TRUE(reference == bytes_of(std::filesystem::path(b) / "terrain.r32")) << "1 and 2 threads differ";
    }
}

// Valley glaciers (ice routed down the valleys, eroding in stream power's sweep, then carving troughs) and
// the chi layer, against erode:stream-power(glaciers=true, chi=true): the same bytes.
TEST(Evolve, GlaciersTroughsAndChiGiveTheBytesOfStreamPower) {
    TempDir dir;
    const std::string head =
        "orogen 1\n"
        "seed 11\n"
        "grid 129 cell=60\n"
        "peak = generate:diamond-square(roughness=0.55, amplitude=3000)\n";
    const std::string whole =
        "ice = erode:stream-power(peak, years=1e5, dt=2e4, uplift=1, m=0.5, n=1.2, erodibility=6e-6,\n"
        "    diffusivity=0.1, landslide_angle=34, glaciers=true, ela=600, ice_erodibility=5e-7,\n"
        "    glacier_half_width=150, trough_wall_angle=35, bank_erosion=4, bank_area=3e4, chi=true)\n";
    const std::string loop =
        "ice = erode:evolve(peak, years=1e5, dt=2e4) {\n"
        "    uplift(rate=1)\n"
        "    flow()\n"
        "    creep(diffusivity=0.1)\n"
        "    glaciers(ela=600, erodibility=5e-7)\n"
        "    stream-power(m=0.5, n=1.2, erodibility=6e-6)\n"
        "    banks(erosion=4, area=3e4)\n"
        "    troughs(half_width=150, wall_angle=35)\n"
        "    landslides(angle=34)\n"
        "    chi(concavity=0.41666666666666669)\n"
        "}\n";
    const std::string tail = "export:raw(ice, path=\"ice.r32\")\nexport:vtk(ice, path=\"ice.vti\")\n";
    const auto a = dir.write("whole.orogen", head + whole + tail), b = dir.write("loop.orogen", head + loop + tail);
    ASSERT_EQ(run_orogen("run " + q(a) + " --quiet --out " + q(dir / "a")).exit_code, 0);
    const RunResult r = run_orogen("run " + q(b) + " --out " + q(dir / "b"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    // Glaciers there are, or the comparison would not test them.
    EXPECT_EQ(r.err.find("glaciers: 0 cells under glaciers"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("cells under glaciers at the end"), std::string::npos) << r.err;
    for (const char* file : {"ice.r32", "ice.vti"}) {
        const std::string x = bytes_of(dir / "a" / file), y = bytes_of(dir / "b" / file);
        ASSERT_GE(x.size(), 129u * 129u * 4u) << file;
        EXPECT_TRUE(x == y) << file << " differs between erode:stream-power and erode:evolve";
    }
    const std::string vti = bytes_of(dir / "b" / "ice.vti");
    for (const char* layer : {"Name=\"ice_flux\"", "Name=\"chi\"", "Name=\"drainage\""})
        EXPECT_NE(vti.find(layer), std::string::npos) << layer;
}

TEST(Evolve, SetReachesAProcessParameterAndNamesAWrongOne) {
    TempDir dir;
    const auto loop = dir.write("loop.orogen", std::string(kHead) + kLoop + kTail);
    const std::string a = (dir / "a").string(), b = (dir / "b").string();
    ASSERT_EQ(run_orogen("run " + q(loop) + " --quiet --out " + q(a)).exit_code, 0);
    ASSERT_EQ(run_orogen("run " + q(loop) + " --quiet --out " + q(b) + " --set range.stream-power.erodibility=4e-5")
                  .exit_code,
              0);
    EXPECT_FALSE(bytes_of(std::filesystem::path(a) / "terrain.r32") ==
                 bytes_of(std::filesystem::path(b) / "terrain.r32"));
    const RunResult bad = run_orogen("check " + q(loop) + " --set range.stream-powr.m=0.4 --set range.banks.erosin=2");
    EXPECT_EQ(bad.exit_code, 2);
    EXPECT_NE(bad.err.find("'range' has no process 'stream-powr'; did you mean 'stream-power'?"), std::string::npos)
        << bad.err;
    EXPECT_NE(bad.err.find("process banks has no parameter 'erosin'; did you mean 'erosion'?"), std::string::npos)
        << bad.err;
}

TEST(Evolve, ListAndHelpShowTheProcessesAndTheirFields) {
    const RunResult list = run_orogen("list process");
    ASSERT_EQ(list.exit_code, 0);
    for (const char* p :
         {"uplift", "rain", "flow", "creep", "rock", "stream-power", "banks", "floodplains", "landslides"})
        EXPECT_NE(list.out.find(std::string("  ") + p + " "), std::string::npos) << p << " missing:\n" << list.out;
    const RunResult help = run_orogen("help stream-power");
    ASSERT_EQ(help.exit_code, 0);
    EXPECT_NE(help.out.find("process stream-power"), std::string::npos) << help.out;
    EXPECT_NE(help.out.find("reads"), std::string::npos);
    EXPECT_NE(help.out.find("flow (the flow graph)"), std::string::npos) << help.out;
    EXPECT_NE(help.out.find("erodibility"), std::string::npos);
}

}  // namespace
