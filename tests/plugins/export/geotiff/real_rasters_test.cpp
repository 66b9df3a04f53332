// Real-world rasters through import:geotiff and orogen_analysis: a geographic raster (1″ cells, 15 × 31 m at
// 60° N) is warped to square metric cells, never stretched, and gives the slopes of its metric twin; the
// nodata wedges a reprojection leaves at the corners do not move the figures (the Baspa DEM shipped in
// data/dems, warped to geographic 1″ and back); a raster with non-square cells is warped with a note or
// refused naming the fix. The geographic rasters are made here with GDAL's own warper (gdalwarp's API).
#include <orogen/analysis/figures.hpp>
#include <orogen/geotiff/geotiff.hpp>
#include "orogen_test.hpp"

#include <orogen/error.hpp>

#include <gdal_priv.h>
#include <gdal_utils.h>
#include <ogr_spatialref.h>

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

using namespace orogen;
using namespace orogen::test;
namespace fs = std::filesystem;
using analysis::FigureId;

namespace {

/// Writes `z` (n × n, rows north to south) as a Float32 GeoTIFF in `epsg` with its north-west corner at
/// (west, north) and square cells of `cell` metres (or `cell_y` north–south if given).
void write_metric(const fs::path& path, const std::vector<float>& z, int n, double cell, int epsg, double west,
                  double north, double cell_y = 0.0) {
    GDALAllRegister();
    GDALDriver* gtiff = GetGDALDriverManager()->GetDriverByName("GTiff");
    GDALDataset* ds = gtiff->Create(path.c_str(), n, n, 1, GDT_Float32, nullptr);
    ASSERT_NE(ds, nullptr);
    double g[6] = {west, cell, 0.0, north, 0.0, -(cell_y > 0.0 ? cell_y : cell)};
    ds->SetGeoTransform(g);
    OGRSpatialReference srs;
    srs.importFromEPSG(epsg);
    ds->SetSpatialRef(&srs);
    ASSERT_EQ(ds->GetRasterBand(1)->RasterIO(GF_Write, 0, 0, n, n, const_cast<float*>(z.data()), n, n, GDT_Float32, 0,
                                             0, nullptr),
              CE_None);
    GDALClose(GDALDataset::ToHandle(ds));
}

/// gdalwarp -t_srs EPSG:4326 -tr 1″ 1″ -r cubic -dstnodata -32768 (the corners outside the source nodata),
/// after giving the source `srs` if it has none.
void to_geographic(const fs::path& in, const fs::path& out, const char* srs = nullptr) {
    GDALAllRegister();
    std::vector<const char*> args = {"-t_srs", "EPSG:4326",  "-tr",   "0.000277777777778", "0.000277777777778", "-r",
                                     "cubic",  "-dstnodata", "-32768"};
    if (srs) args.insert(args.end(), {"-s_srs", srs});
    args.push_back(nullptr);
    GDALWarpAppOptions* options = GDALWarpAppOptionsNew(const_cast<char**>(args.data()), nullptr);
    ASSERT_NE(options, nullptr);
    GDALDatasetH src = GDALOpen(in.c_str(), GA_ReadOnly);
    ASSERT_NE(src, nullptr) << in;
    int usage_error = 0;
    GDALDatasetH dst = GDALWarp(out.c_str(), nullptr, 1, &src, options, &usage_error);
    GDALWarpAppOptionsFree(options);
    GDALClose(src);
    ASSERT_NE(dst, nullptr) << "GDALWarp failed";
    GDALClose(dst);
}

/// The figures of a raster as `orogen analyze` reads and measures it by default: its own samples, nodata
/// masked, the filled flats out of the slope–area fits.
analysis::Figures measure(const fs::path& path, geotiff::RasterInfo* info = nullptr) {
    geotiff::ReadOptions o;
    o.holes = geotiff::Holes::mask;
    const auto r = geotiff::read(path, o);
    if (info) *info = r.info;
    const Heightmap& hm = *r.terrain;
    std::vector<std::uint8_t> valid(hm.size(), 1);
    if (hm.has_layer("nodata")) {
        const ConstGridView holes = hm.layer("nodata");
        for (std::size_t i = 0; i < hm.size(); ++i) valid[i] = holes.data[i] == 0.0f;
    }
    return analysis::measure({hm.heights().data(), hm.width(), hm.height(), hm.cell(), valid.data()});
}

double figure(const analysis::Figures& f, FigureId id) {
    EXPECT_TRUE(f[id].ok()) << analysis::info(id).key << ": " << f[id].why_not;
    return f[id].value;
}

/// The Baspa DEM the repository ships (data/dems), or "" if this checkout has none.
fs::path baspa() {
    const fs::path p = fs::path(OROGEN_SOURCE_DIR) / "data/dems/himalaya_baspa_30m.tif";
    return fs::exists(p) ? p : fs::path();
}

}  // namespace

TEST(RealRasters, AGeographicRasterAt60NHasTheSlopesOfItsMetricTwin) {
    // Hills and valleys of 4 km with a tilt, 30 m cells, in UTM 33N around 60° N, 15° E; warped to 1″
    // (15.5 m east–west, 30.9 m north–south there).
    TempDir dir;
    const int n = 401;
    const double cell = 30.0, wave = 4000.0, two_pi = 2.0 * std::numbers::pi;
    std::vector<float> z(std::size_t(n) * n);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
            z[std::size_t(y) * n + x] =
                float(1500.0 + 450.0 * std::sin(two_pi * x * cell / wave) * std::sin(two_pi * y * cell / 2800.0) +
                      0.15 * x * cell + 200.0 * std::sin(two_pi * (x + 0.6 * y) * cell / 1700.0));
    write_metric(dir / "metric.tif", z, n, cell, 32633, 494000.0, 6657000.0);
    to_geographic(dir / "metric.tif", dir / "geographic.tif");

    geotiff::RasterInfo info;
    const auto metric = measure(dir / "metric.tif");
    const auto geographic = measure(dir / "geographic.tif", &info);
    ASSERT_TRUE(info.warp.has_value());
    EXPECT_NEAR(info.pixel_x_metres, 15.5, 0.1);
    EXPECT_NEAR(info.pixel_y_metres, 30.9, 0.1);
    EXPECT_DOUBLE_EQ(info.warp->cell, info.pixel_y_metres);  // the longer side
    EXPECT_NE(info.warp->target.find("local transverse Mercator projection centred at 60.0"), std::string::npos)
        << info.warp->target;
    for (FigureId id : {FigureId::slope_mean, FigureId::slope_median, FigureId::slope_p90})
        EXPECT_NEAR(figure(geographic, id), figure(metric, id), 0.5) << analysis::info(id).key;

    // Taken as square cells of the mean side (as before), the samples stood 50 % too far apart east–west and
    // 25 % too close north–south: the 90th percentile 1.6° off.
    GDALAllRegister();
    GDALDataset* ds = GDALDataset::Open((dir / "geographic.tif").c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY);
    ASSERT_NE(ds, nullptr);
    const int w = ds->GetRasterXSize(), h = ds->GetRasterYSize();
    std::vector<float> raw(std::size_t(w) * h);
    ASSERT_EQ(ds->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, w, h, raw.data(), w, h, GDT_Float32, 0, 0, nullptr),
              CE_None);
    GDALClose(GDALDataset::ToHandle(ds));
    std::vector<std::uint8_t> valid(raw.size());
    for (std::size_t i = 0; i < raw.size(); ++i) valid[i] = raw[i] != -32768.0f;
    const auto stretched =
        analysis::measure({raw.data(), w, h, 0.5 * (info.pixel_x_metres + info.pixel_y_metres), valid.data()});
    EXPECT_GT(std::abs(figure(stretched, FigureId::slope_p90) - figure(metric, FigureId::slope_p90)), 1.0);
}

TEST(RealRasters, TheReprojectedBaspaWithNodataCornersKeepsItsFigures) {
    const fs::path dem = baspa();
    if (dem.empty()) GTEST_SKIP() << "data/dems/himalaya_baspa_30m.tif is not in this checkout";
    // The Baspa's grid is UTM 44N without a CRS tag; placed at its place (31.3° N, 78.3° E) and at 60° N.
    struct Place {
        const char* srs;
        const char* name;
        double west, north;
    };
    for (const Place& p :
         {Place{"EPSG:32644", "31.3° N", 228000.0, 3481000.0}, Place{"EPSG:32633", "60° N", 485000.0, 6667000.0}}) {
        SCOPED_TRACE(p.name);
        TempDir dir;
        {
            GDALAllRegister();
            GDALDataset* src = GDALDataset::Open(dem.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY);
            ASSERT_NE(src, nullptr);
            GDALDriver* gtiff = GetGDALDriverManager()->GetDriverByName("GTiff");
            GDALDataset* placed =
                gtiff->CreateCopy((dir / "metric.tif").c_str(), src, FALSE, nullptr, nullptr, nullptr);
            GDALClose(GDALDataset::ToHandle(src));
            ASSERT_NE(placed, nullptr);
            double g[6] = {p.west, 30.0, 0.0, p.north, 0.0, -30.0};
            placed->SetGeoTransform(g);
            OGRSpatialReference srs;
            srs.SetFromUserInput(p.srs);
            placed->SetSpatialRef(&srs);
            GDALClose(GDALDataset::ToHandle(placed));
        }
        to_geographic(dir / "metric.tif", dir / "geographic.tif");
        geotiff::RasterInfo info;
        const auto metric = measure(dir / "metric.tif");
        const auto geographic = measure(dir / "geographic.tif", &info);
        ASSERT_TRUE(info.warp.has_value());
        EXPECT_GT(geographic.nodata, geographic.samples / 100);  // the wedges at the corners: 1 % or more
        for (FigureId id : {FigureId::slope_mean, FigureId::slope_median, FigureId::slope_p90})
            EXPECT_NEAR(figure(geographic, id), figure(metric, id), 0.5) << analysis::info(id).key;
        EXPECT_NEAR(figure(geographic, FigureId::hypsometric_integral), figure(metric, FigureId::hypsometric_integral),
                    0.01);
        EXPECT_NEAR(figure(geographic, FigureId::spectral_exponent), figure(metric, FigureId::spectral_exponent), 0.2);
        EXPECT_NEAR(figure(geographic, FigureId::pits), figure(metric, FigureId::pits), 0.05);
        // θ by default, without the filled flats (whose slope, the fill's 1e-4, passes S > 1e-4 or not by
        // rounding): within 0.05 of the metric original's (0.274 there, 0.272 and 0.273 here; with them
        // the reprojection at 31.3° N gave 0.272 or 0.249 against 0.491).
        EXPECT_NEAR(figure(geographic, FigureId::concavity), figure(metric, FigureId::concavity), 0.05);
        EXPECT_NEAR(figure(metric, FigureId::concavity), 0.274, 0.005);
    }
}

TEST(RealRasters, NonSquareCellsAreWarpedWithANoteOrRefusedNamingTheFix) {
    TempDir dir;
    const int n = 81;
    std::vector<float> z(std::size_t(n) * n);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) z[std::size_t(y) * n + x] = float(100.0 + 2.0 * x + 1.0 * y);
    // Geographic: the Baspa's 1″ at 31.3° N.
    write_metric(dir / "degrees.tif", z, n, 1.0 / 3600.0, 4326, 78.3, 31.3);
    // Projected with pixels of 20 × 30 m.
    write_metric(dir / "oblong.tif", z, n, 20.0, 32644, 240000.0, 3466000.0, 30.0);
    dir.write("warp.orogen",
              "orogen 1\ngrid 9\n"
              "d = import:geotiff(path=\"degrees.tif\", resample=none)\n"
              "o = import:geotiff(path=\"oblong.tif\", resample=none, holes=refuse)\n"
              "s = import:geotiff(path=\"oblong.tif\")\n"
              "export:raw(d, path=\"d.r32\")\nexport:raw(o, path=\"o.r32\")\nexport:raw(s, path=\"s.r32\")\n");
    RunResult r = run_orogen("run warp.orogen --out out", "", dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string log = r.out + r.err;
    EXPECT_NE(log.find("d: note: its cells are not square (1″ × 1″ of WGS 84: 26.4 m east–west by 30.8 m "
                       "north–south at 31.29° N); warped with GDAL's warper (cubic) to square 30.8"),
              std::string::npos)
        << log;
    EXPECT_NE(log.find("in a local transverse Mercator projection centred at 31.29° N 78.31° E"), std::string::npos)
        << log;
    EXPECT_NE(log.find("o: note: its cells are not square (pixels of 20.0 m east–west by 30.0 m north–south); "
                       "warped with GDAL's warper (cubic) to square 30.00 m cells in its own CRS: 81×81 samples "
                       "became 54×81"),
              std::string::npos)
        << log;
    EXPECT_NE(slurp(dir / "out/o.r32.json").find("\"cell_size\": 30,"), std::string::npos);
    // Warped to 54×81 square cells, then resampled to the grid's 9×9: that stretch is said too.
    EXPECT_NE(log.find("s: warning: resampling the raster's 54×81 samples to the grid's 9×9 stretches it: 0.662 "
                       "times as far apart east–west as north–south, taken as square; give the grid the raster's "
                       "proportions (grid 9x13) or resample=none"),
              std::string::npos)
        << log;

    // square=refuse: exit 2 at check time, the sides and the gdalwarp command that squares them.
    dir.write("refuse.orogen", "orogen 1\ngrid 9\nd = import:geotiff(path=\"degrees.tif\", square=refuse)\n");
    r = run_orogen("check refuse.orogen", "", dir.path());
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("error: import:geotiff: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("degrees.tif has cells that are not square (1″ × 1″ of WGS 84: 26.4 m east–west by 30.8 m "
                         "north–south at 31.29° N); taking them as square would stretch the terrain. Give "
                         "square=warp to warp it here"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("or warp it first: gdalwarp -t_srs '+proj=tmerc +lat_0=31.28875 +lon_0=78.31125 +k=1"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("-tr 30.80 30.80 -r cubic -dstnodata nan degrees.tif square.tif"), std::string::npos) << r.err;

    // The library says the same to a caller that asks it to refuse.
    geotiff::ReadOptions o;
    o.square = geotiff::Square::refuse;
    EXPECT_THROW(geotiff::read(dir / "degrees.tif", o), BadInput);
}
