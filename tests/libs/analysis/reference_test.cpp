// orogen_analysis agrees with shared/realism/terrain_stats.py on real DEMs: the Rif DEM bundled in
// data/ (always), and the eight of shared/realism/dems against reference-stats.txt, the script's own
// output (when shared/ sits beside the clone). The script prints slopes to 0.1°, HI to 0.001, β, θ and
// pits to 0.01: the tolerances are that rounding plus a little, well inside the issue's (median slope
// 0.5°, HI 0.01, β 0.15, θ 0.05), since both compute the same thing in double precision.
#include <orogen/analysis/figures.hpp>

#include <gdal.h>
#include <gtest/gtest.h>

#include "shipped_dem.hpp"

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace orogen::analysis;
using enum FigureId;
namespace fs = std::filesystem;

using Dem = orogen::test::ShippedDem;

/// What terrain_stats.py printed for one DEM.
struct Expected {
    std::map<FigureId, double> figures;
};

double field(const std::string& line, const std::string& key) {
    std::smatch m;
    if (!std::regex_search(line, m, std::regex(key + R"(\s*([-0-9.]+))"))) return std::nan("");
    return std::stod(m[1]);
}

Expected parse_stats_line(const std::string& line) {
    Expected e;
    e.figures[hypsometric_integral] = field(line, "HI=");
    e.figures[slope_mean] = field(line, "slope mean=");
    e.figures[slope_median] = field(line, "p50=");
    e.figures[slope_p90] = field(line, "p90=");
    e.figures[steeper_30] = field(line, ">30=");
    e.figures[steeper_40] = field(line, ">40=");
    e.figures[spectral_exponent] = field(line, "beta=");
    e.figures[pits] = field(line, "pits=");
    e.figures[concavity] = field(line, "theta=");
    e.figures[network_share] = field(line, "chan>0.1km2=");
    return e;
}

/// Half a unit of the last digit terrain_stats.py prints, plus room for summation order.
double tolerance(FigureId id) {
    switch (id) {
        case hypsometric_integral: return 0.0006;
        case spectral_exponent: return 0.006;
        case concavity: return 0.006;
        case pits: return 0.006;
        default: return 0.051;  // slopes (°) and shares (%) to 0.1
    }
}

void expect_agreement(const std::string& name, const Dem& dem, const Expected& expected) {
    // terrain_stats.py fits the filled flats whose slope passes S > 1e-4 by rounding: its definition is
    // fit_filled_cells = true (the default leaves them out; docs/analysis.md, "Real-world rasters").
    Options o;
    o.fit_filled_cells = true;
    const Figures f = measure({dem.z.data(), dem.width, dem.height, dem.cell}, o);
    for (const auto& [id, value] : expected.figures) {
        ASSERT_TRUE(f[id].ok()) << name << ": " << info(id).key << ": " << f[id].why_not;
        EXPECT_NEAR(f[id].value, value, tolerance(id)) << name << ": " << info(id).key;
    }
}

Dem read_geotiff(const fs::path& path) { return orogen::test::read_geotiff_dem(path); }

/// NAME.f32 (little-endian float32, rows north to south) with NAME.json's nx, ny, dx_m.
Dem read_f32(const fs::path& json) {
    std::ifstream in(json);
    std::stringstream text;
    text << in.rdbuf();
    const std::string s = text.str();
    Dem dem;
    dem.width = int(field(s, "\"nx\":"));
    dem.height = int(field(s, "\"ny\":"));
    dem.cell = field(s, "\"dx_m\":");
    dem.z.resize(std::size_t(dem.width) * std::size_t(dem.height));
    fs::path raw = json;
    raw.replace_extension(".f32");
    std::ifstream bytes(raw, std::ios::binary);
    bytes.read(reinterpret_cast<char*>(dem.z.data()), std::streamsize(dem.z.size() * sizeof(float)));
    if (!bytes) dem.z.clear();
    return dem;
}

TEST(Reference, TheBundledRifDemMeasuresAsTerrainStatsPy) {
    // morocco_rif_27m's line of shared/realism/reference-stats.txt (tests/libs/analysis/data/README.md).
    const Dem dem = read_geotiff(fs::path(ANALYSIS_TEST_DATA) / "morocco_rif_27m.tif");
    ASSERT_EQ(dem.z.size(), 500u * 500u);
    ASSERT_EQ(dem.cell, 27.0);
    expect_agreement("morocco_rif_27m", dem,
                     parse_stats_line("morocco_rif_27m   dx=  27.0 n=(500, 500) relief= 1415.0 HI=0.444 slope mean= "
                                      "19.3 p50= 19.2 p90= 29.2 >30=  8.1% >40=  0.2% beta=4.73 pits= 0.02% "
                                      "theta= 0.89 chan>0.1km2= 4.6%"));
}

TEST(Reference, EveryReferenceDemMeasuresAsTerrainStatsPy) {
    const fs::path realism = fs::path(OROGEN_SHARED_DIR) / "realism";
    if (!fs::exists(realism / "reference-stats.txt"))
        GTEST_SKIP() << "no " << (realism / "reference-stats.txt") << " (shared/ beside the clone)";
    std::ifstream lines(realism / "reference-stats.txt");
    int measured = 0;
    for (std::string line; std::getline(lines, line);) {
        const std::string name = line.substr(0, line.find(' '));
        if (name.empty()) continue;
        const fs::path json = realism / "dems" / (name + ".json");
        ASSERT_TRUE(fs::exists(json)) << json;
        const Dem dem = read_f32(json);
        ASSERT_FALSE(dem.z.empty()) << name;
        expect_agreement(name, dem, parse_stats_line(line));
        ++measured;
    }
    EXPECT_EQ(measured, 8);
}

}  // namespace
