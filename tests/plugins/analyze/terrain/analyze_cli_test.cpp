// `orogen analyze` and analyze:terrain through the real binary: the table, analysis.json, the charts,
// the page and the renderings; --against and the nearest reference; every kind of file it reads (GeoTIFF
// with holes, .f32 + .json, .vti, RAW, 16-bit PNG) giving the same figures for the same heights; and bad
// input, one clear message each, exit 2 where nothing could be measured, nothing half-written.
#include "orogen_test.hpp"

#include <gdal.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <regex>
#include <vector>

namespace {

using namespace orogen::test;

const fs::path rif = fs::path(OROGEN_SOURCE_DIR) / "tests/libs/analysis/data/morocco_rif_27m.tif";

/// NAME.f32 + NAME.json in `dir` with heights f(x, y).
fs::path write_f32(const TempDir& dir, const std::string& name, int w, int h, double cell, auto&& f) {
    std::vector<float> z(std::size_t(w) * std::size_t(h));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) z[std::size_t(y) * w + x] = float(f(x, y));
    const fs::path path = dir / (name + ".f32");
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(z.data()), std::streamsize(z.size() * 4));
    dir.write(name + ".json",
              "{\"nx\": " + std::to_string(w) + ", \"ny\": " + std::to_string(h) +
                  ", \"dx_m\": " + std::to_string(cell) + "}");
    return path;
}

/// The value of figure `key` of terrain `name` in analysis.json (NaN if null or absent).
double figure(const std::string& json, const std::string& name, const std::string& key) {
    const auto at = json.find("\"name\": \"" + name + "\"");
    if (at == std::string::npos) return std::nan("");
    std::smatch m;
    const std::string rest = json.substr(at);
    if (!std::regex_search(rest, m, std::regex("\"" + key + "\": \\{\"value\": ([-0-9.e+]+|null)")))
        return std::nan("");
    return m[1] == "null" ? std::nan("") : std::stod(m[1]);
}

TEST(AnalyzeCli, MeasuresADemAndWritesTheReport) {
    TempDir dir;
    const auto r = run_orogen("analyze " + q(rif) + " --no-render --out " + q(dir / "report"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    // The table on stdout, one row per figure, as terrain_stats.py measures the Rif (reference-stats.txt), but
    // θ: without the filled flats, 0.44 (the script's 0.89 with them; --fit-filled-flats below).
    EXPECT_NE(r.out.find("median slope"), std::string::npos) << r.out;
    EXPECT_TRUE(std::regex_search(r.out, std::regex("median slope +° +19\\.2\\n"))) << r.out;
    EXPECT_TRUE(std::regex_search(r.out, std::regex("spectral β +4\\.73\\n"))) << r.out;
    EXPECT_TRUE(std::regex_search(r.out, std::regex("concavity θ +0\\.44\\n"))) << r.out;
    const std::string json = slurp(dir / "report/analysis.json");
    EXPECT_NEAR(figure(json, "morocco_rif_27m", "hypsometric_integral"), 0.444, 0.0006);
    EXPECT_NE(json.find("\"definition\": "), std::string::npos);
    EXPECT_NE(json.find("Perron, Kirchner & Dietrich 2008"), std::string::npos);
    const std::string page = slurp(dir / "report/README.md");
    EXPECT_NE(page.find("](analysis.json)"), std::string::npos);
    for (const char* chart : {"slopes", "hypsometry", "spectrum", "slope-area", "hack"}) {
        const fs::path png = dir / "report" / (std::string("analysis-") + chart + ".png");
        EXPECT_TRUE(fs::exists(png)) << png;
        EXPECT_NE(page.find(png.filename().string()), std::string::npos) << chart;
    }
    EXPECT_TRUE(fs::exists(dir / "report/manifest.json"));
    EXPECT_FALSE(fs::exists(dir / "report/renders")) << "--no-render";
}

TEST(AnalyzeCli, FitFilledFlatsTakesTheFilledCellsIntoTheFitsAsTerrainStatsPy) {
    // The Rif's θ is 0.44 without the filled flats (the default), 0.89 with those whose slope 1e-4 passes
    // S > 1e-4 by rounding, as terrain_stats.py (docs/analysis.md, "Real-world rasters"); the other figures do
    // not move.
    TempDir dir;
    const auto r = run_orogen("analyze " + q(rif) + " --fit-filled-flats --no-render --out " + q(dir / "report"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(std::regex_search(r.out, std::regex("concavity θ +0\\.89\\n"))) << r.out;
    EXPECT_TRUE(std::regex_search(r.out, std::regex("median slope +° +19\\.2\\n"))) << r.out;
    // --skip-filled-flats is the default spelled out.
    const auto s = run_orogen("analyze " + q(rif) + " --skip-filled-flats --no-render --out " + q(dir / "skip"));
    ASSERT_EQ(s.exit_code, 0) << s.err;
    EXPECT_TRUE(std::regex_search(s.out, std::regex("concavity θ +0\\.44\\n"))) << s.out;
    const auto both = run_orogen("analyze " + q(rif) + " --fit-filled-flats --skip-filled-flats --no-render");
    EXPECT_EQ(both.exit_code, 2);
    EXPECT_NE(both.err.find("--fit-filled-flats and --skip-filled-flats contradict each other"), std::string::npos)
        << both.err;
    const auto d = run_orogen("analyze " + q(rif) + " --discriminate --fit-filled-flats --against " + q(rif));
    EXPECT_EQ(d.exit_code, 2);
    EXPECT_NE(d.err.find("--fit-filled-flats changes the figures' table, which --discriminate does not print"),
              std::string::npos)
        << d.err;
}

TEST(AnalyzeCli, ComparesWithReferencesAndNamesTheNearest) {
    // A smooth dome is far from the Rif on slopes and spectrum, the Rif is inside its own band, and the
    // dome's nearest reference among the Rif and a rougher copy of it is named.
    TempDir dir;
    const fs::path dome = write_f32(dir, "dome", 300, 300, 27.0, [](int x, int y) {
        return 1500.0 * std::exp(-((x - 150.0) * (x - 150.0) + (y - 150.0) * (y - 150.0)) / (2 * 60.0 * 60.0));
    });
    const fs::path rough = write_f32(dir, "rough", 300, 300, 27.0, [](int x, int y) {
        return 800.0 * std::sin(x * 0.3) * std::cos(y * 0.21) + 3.0 * x;
    });
    const auto r = run_orogen("analyze " + q(dome) + " " + q(rif) + " --against " + q(rif) + " " + q(rough) +
                              " --no-render --out " + q(dir / "out"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("morocco_rif_27m-2*"), std::string::npos) << "a reference, named apart from the terrain\n"
                                                                   << r.out;
    EXPECT_NE(r.out.find("references"), std::string::npos);
    EXPECT_TRUE(std::regex_search(r.out, std::regex("median slope .* OUT +in\\n"))) << r.out;
    EXPECT_NE(r.out.find("resembles most"), std::string::npos);
    EXPECT_NE(r.out.find("  morocco_rif_27m: morocco_rif_27m-2 (0.00 over 20 figures)"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("  dome: morocco_rif_27m-2 ("), std::string::npos) << r.out;
    const std::string json = slurp(dir / "out/analysis.json");
    EXPECT_NE(json.find("\"inside_references\": false"), std::string::npos);
    EXPECT_NE(json.find("\"reference_bands\": {\n    \"slope_mean\""), std::string::npos);
}

TEST(AnalyzeCli, RendersTheTerrainsWithOneCamera) {
    TempDir dir;
    const fs::path small =
        write_f32(dir, "small", 120, 90, 30.0, [](int x, int y) { return 5.0 * x + 300 * std::sin(y * 0.1); });
    const auto r = run_orogen("analyze " + q(small) + " --against " + q(rif) + " --out " + q(dir / "out"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(fs::exists(dir / "out/renders/small.png"));
    EXPECT_TRUE(fs::exists(dir / "out/renders/morocco_rif_27m.png"));
    const std::string page = slurp(dir / "out/README.md");
    EXPECT_NE(page.find("![small](renders/small.png)"), std::string::npos) << page;
    EXPECT_NE(r.out.find("(one reference: no spread to measure the distance to it by; give two or more"),
              std::string::npos)
        << r.out;
}

TEST(AnalyzeCli, EveryFileKindGivesTheSameFigures) {
    // One terrain written by orogen itself as .vti (both up axes), .r32, GeoTIFF and OpenEXR, read back by analyze:
    // the figures must agree (and so the orientation and the cell size of each reader).
    TempDir dir;
    dir.write("t.orogen",
              "orogen 1\nseed 3\ngrid 97x81 cell=30\n"
              "t = generate:diamond-square(roughness=0.6, amplitude=900)\n"
              "export:vtk(t, path=\"t.vti\")\nexport:vtk(t, path=\"y.vti\", up=y)\n"
              "export:raw(t, path=\"t.r32\")\nexport:geotiff(t, path=\"t.tif\")\n"
              "export:exr(t, path=\"t.exr\")\n");
    const auto made = run_orogen("run " + q(dir / "t.orogen") + " --quiet --out " + q(dir / "in"));
    ASSERT_EQ(made.exit_code, 0) << made.err;
    const auto r =
        run_orogen("analyze " + q(dir / "in/t.vti") + " " + q(dir / "in/y.vti") + " " + q(dir / "in/t.r32") + " " +
                   q(dir / "in/t.tif") + " " + q(dir / "in/t.exr") + " --no-render --out " + q(dir / "out"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string json = slurp(dir / "out/analysis.json");
    for (const char* key : {"slope_median", "hypsometric_integral", "spectral_exponent", "pits", "local_relief"}) {
        const double expected = figure(json, "t", key);
        ASSERT_TRUE(std::isfinite(expected)) << key << "\n" << json;
        EXPECT_EQ(figure(json, "y", key), expected) << key;
        EXPECT_EQ(figure(json, "t-2", key), expected) << key << " (.r32)";
        EXPECT_EQ(figure(json, "t-3", key), expected) << key << " (GeoTIFF)";
        EXPECT_EQ(figure(json, "t-4", key), expected) << key << " (OpenEXR)";
    }
}

TEST(AnalyzeCli, HolesAreMaskedAndCounted) {
    // A GeoTIFF with a nodata square: the slopes of the plane stay exact, the holes are counted.
    TempDir dir;
    GDALAllRegister();
    const fs::path tif = dir / "holes.tif";
    GDALDatasetH ds = GDALCreate(GDALGetDriverByName("GTiff"), tif.c_str(), 64, 64, 1, GDT_Float32, nullptr);
    double gt[6] = {0, 10, 0, 640, 0, -10};
    GDALSetGeoTransform(ds, gt);
    GDALRasterBandH band = GDALGetRasterBand(ds, 1);
    GDALSetRasterNoDataValue(band, -9999);
    std::vector<float> z(64 * 64);
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x)
            z[std::size_t(y * 64 + x)] = (x >= 20 && x < 30 && y >= 20 && y < 26) ? -9999.0f : float(3 * x + 4 * y);
    ASSERT_EQ(GDALRasterIO(band, GF_Write, 0, 0, 64, 64, z.data(), 64, 64, GDT_Float32, 0, 0), CE_None);
    GDALClose(ds);
    const auto r = run_orogen("analyze " + q(tif) + " --no-render --out " + q(dir / "out"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("holes: 60 of 4096 samples (1.46 %)"), std::string::npos) << r.out;
    EXPECT_TRUE(std::regex_search(r.out, std::regex("p90 slope +° +26\\.6\\n"))) << r.out;
    EXPECT_NE(slurp(dir / "out/analysis.json").find("\"nodata\": 60"), std::string::npos);
}

TEST(AnalyzeCli, ATerrainTooSmallForAFigureSaysWhichAndReportsTheRest) {
    TempDir dir;
    const fs::path tiny = write_f32(dir, "tiny", 12, 10, 30.0, [](int x, int y) { return 10.0 * x + y * y; });
    const auto r = run_orogen("analyze " + q(tiny) + " --no-render --out " + q(dir / "out"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("tiny: spectral β: the terrain (12x10) is narrower than 32 samples: too few wavenumbers "
                         "in 4 … n/4 to fit"),
              std::string::npos)
        << r.out;
    EXPECT_TRUE(std::regex_search(r.out, std::regex("median slope +° +[0-9.]+\\n"))) << r.out;
}

TEST(AnalyzeCli, BadInputIsOneClearMessageAndWritesNothing) {
    TempDir dir;
    struct Case {
        std::string args, message;
    };
    const fs::path nan = write_f32(dir, "nan", 8, 8, 30.0, [](int, int) { return std::nan(""); });
    const fs::path huge = dir.write("huge.f32", "");
    dir.write("huge.json", "{\"nx\": 9000000, \"ny\": 9000000, \"dx_m\": 30}");
    const fs::path png = dir / "h.png";
    {
        orogen::AtomicFile f(png);
        orogen::write_gray_png(f.stream(), 4, 4, 16, std::vector<std::uint16_t>(16, 7));
        f.commit();
    }
    const fs::path plain = dir / "plain.tif";  // no georeference
    {
        GDALAllRegister();
        GDALDatasetH ds = GDALCreate(GDALGetDriverByName("GTiff"), plain.c_str(), 40, 40, 1, GDT_Float32, nullptr);
        GDALClose(ds);
    }
    fs::create_directories(dir / "folder");
    const std::vector<Case> cases = {
        {q(dir / "nope.tif"), "orogen: error: " + (dir / "nope.tif").string() + ": no such file\n"},
        {q(dir / "folder"), (dir / "folder").string() + " is a folder"},
        {q(png), "a PNG holds neither the cell size nor heights in metres; give --cell METRES and --heights LOW:HIGH"},
        {q(plain), "the raster has no georeference to take a cell size from; give cell=METRES"},
        {q(huge), "declares 9000000x9000000 samples, which needs"},
        {q(nan), "no figure could be measured on any terrain: the terrain has no measured sample (all nodata)"},
        {"--against " + q(rif), "analyze needs a terrain to measure before --against"},
        {q(rif) + " --cell -3", "--cell needs the distance between samples in metres, a number above 0, got '-3'"},
    };
    for (const auto& c : cases) {
        const auto r = run_orogen("analyze " + c.args + " --no-render --out " + q(dir / "out"));
        EXPECT_EQ(r.exit_code, 2) << c.args << "\n" << r.err;
        EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << "\n" << r.err;
        EXPECT_FALSE(fs::exists(dir / "out/analysis.json")) << c.args;
    }
    // The plain raster is measured once its cell size is given.
    EXPECT_EQ(run_orogen("analyze " + q(plain) + " --cell 25 --no-render --out " + q(dir / "out")).exit_code, 0);
}

TEST(AnalyzeCli, TheSameBytesOnOneThreadOrTwo) {
    TempDir dir;
    const fs::path bumps = write_f32(dir, "bumps", 200, 160, 30.0, [](int x, int y) {
        return 400.0 * std::sin(x * 0.05) * std::sin(y * 0.07) + 2.0 * x + 50.0 * std::sin(x * y * 0.001);
    });
    for (const char* threads : {"1", "2"})
        ASSERT_EQ(run_orogen("analyze " + q(bumps) + " " + q(rif) + " --threads " + threads + " --no-render --out " +
                             q(dir / (std::string("t") + threads)))
                      .exit_code,
                  0);
    for (const char* file :
         {"analysis.json", "analysis.txt", "README.md", "analysis-spectrum.png", "analysis-slope-area.png"})
        EXPECT_EQ(slurp(dir / "t1" / file), slurp(dir / "t2" / file)) << file;
}

TEST(AnalyzeCli, WithoutGnuplotTheReportComesWithoutCharts) {
    TempDir dir;
    const auto r = run_orogen("analyze " + q(rif) + " --no-render --out " + q(dir / "out"), "PATH=/nonexistent");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("no charts: gnuplot is not installed (apt-get install gnuplot-nox)"), std::string::npos)
        << r.err;
    EXPECT_TRUE(fs::exists(dir / "out/analysis.json"));
    EXPECT_FALSE(fs::exists(dir / "out/analysis-slopes.png"));
    EXPECT_EQ(slurp(dir / "out/README.md").find("## Charts"), std::string::npos);
    for (const auto& e : fs::directory_iterator(dir / "out"))
        EXPECT_NE(e.path().filename().string().rfind(".orogen-gnuplot", 0), 0u) << "left behind: " << e.path();
}

TEST(AnalyzeCli, HelpCitesEachFiguresSource) {
    const auto r = run_orogen("help analyze:terrain");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    for (const char* source : {"Strahler 1952", "Perron, Kirchner & Dietrich 2008", "Flint 1974", "Hack 1957",
                               "Wobus et al. 2006", "Horton 1945", "Roering, Perron & Kirchner 2007"})
        EXPECT_NE(r.out.find(source), std::string::npos) << source;
    EXPECT_NE(run_orogen("list analyze").out.find("analyze:terrain"), std::string::npos);
}

}  // namespace
