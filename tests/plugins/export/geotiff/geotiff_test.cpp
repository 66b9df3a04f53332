// GeoTIFF out and DEMs in, checked with GDAL's API (what QGIS reads) and the
// real `orogen` binary: georeference, CRS, band values equal to the
// heightmap's, compression, COG layout, nodata filling, and the bad inputs.
#include <orogen/geotiff/geotiff.hpp>
#include "orogen_test.hpp"

#include <orogen/error.hpp>

#include <cpl_conv.h>
#include <gdal_priv.h>
#include <ogr_spatialref.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

using namespace orogen;
using namespace orogen::test;
namespace fs = std::filesystem;

namespace {

struct Closer {
    void operator()(GDALDataset* d) const { GDALClose(GDALDataset::ToHandle(d)); }
};
using Dataset = std::unique_ptr<GDALDataset, Closer>;

Dataset open(const fs::path& p) {
    GDALAllRegister();
    return Dataset(GDALDataset::Open(p.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY));
}

std::vector<float> band_values(GDALDataset& ds, int band) {
    const int w = ds.GetRasterXSize(), h = ds.GetRasterYSize();
    std::vector<float> v(std::size_t(w) * h);
    EXPECT_EQ(ds.GetRasterBand(band)->RasterIO(GF_Read, 0, 0, w, h, v.data(), w, h, GDT_Float32, 0, 0, nullptr),
              CE_None);
    return v;
}

/// A terrain with two layers whose values are easy to recognise.
Heightmap sample_terrain(int w, int h, double cell) {
    Heightmap t(w, h, cell);
    GridView water = t.layer("water"), eroded = t.layer("eroded");
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = std::size_t(y) * w + x;
            t.heights()[i] = float(100.0 + 3.0 * x - 2.0 * y + 10.0 * std::sin(0.3 * x * y));
            water.data[i] = float(0.01 * x);
            eroded.data[i] = float(-0.001 * y);
        }
    return t;
}

std::vector<float> read_r32(const fs::path& p) {
    const std::string bytes = slurp(p);
    std::vector<float> v(bytes.size() / 4);
    std::memcpy(v.data(), bytes.data(), bytes.size());
    return v;
}

}  // namespace

TEST(GeoTiff, HeightsAndLayersAreBandsWithVertexCentredGeoreference) {
    TempDir dir;
    const Heightmap t = sample_terrain(37, 23, 30.0);
    geotiff::WriteOptions o;
    o.crs = "EPSG:32632";
    o.origin = {500000.0, 5200000.0};
    o.layers = {"water", "eroded"};
    geotiff::write(t, dir / "t.tif", o);

    Dataset ds = open(dir / "t.tif");
    ASSERT_TRUE(ds);
    EXPECT_EQ(ds->GetRasterXSize(), 37);
    EXPECT_EQ(ds->GetRasterYSize(), 23);
    ASSERT_EQ(ds->GetRasterCount(), 3);
    EXPECT_STREQ(ds->GetRasterBand(1)->GetDescription(), "height");
    EXPECT_STREQ(ds->GetRasterBand(2)->GetDescription(), "water");
    EXPECT_STREQ(ds->GetRasterBand(3)->GetDescription(), "eroded");
    EXPECT_EQ(ds->GetRasterBand(1)->GetRasterDataType(), GDT_Float32);
    // Bit for bit the heightmap and its layers.
    EXPECT_EQ(band_values(*ds, 1), t.heights());
    const auto water = band_values(*ds, 2);
    EXPECT_EQ(std::memcmp(water.data(), t.layer("water").data, water.size() * 4), 0);
    // Pixel centres on the vertices: the south-west vertex at the origin.
    EXPECT_STREQ(ds->GetMetadataItem("AREA_OR_POINT"), "Point");
    double g[6];
    ASSERT_EQ(ds->GetGeoTransform(g), CE_None);
    EXPECT_DOUBLE_EQ(g[1], 30.0);
    EXPECT_DOUBLE_EQ(g[5], -30.0);
    const double sw_x = g[0] + 0.5 * g[1], sw_y = g[3] + (23 - 0.5) * g[5];
    EXPECT_NEAR(sw_x, 500000.0, 1e-6);
    EXPECT_NEAR(sw_y, 5200000.0, 1e-6);
    const OGRSpatialReference* srs = ds->GetSpatialRef();
    ASSERT_TRUE(srs);
    EXPECT_STREQ(srs->GetAuthorityCode(nullptr), "32632");
    EXPECT_STREQ(ds->GetMetadataItem("COMPRESSION", "IMAGE_STRUCTURE"), "DEFLATE");
    EXPECT_STREQ(ds->GetMetadataItem("PREDICTOR", "IMAGE_STRUCTURE"), "3");
}

TEST(GeoTiff, TheDefaultCrsIsLocalMetric) {
    TempDir dir;
    geotiff::write(sample_terrain(9, 9, 5.0), dir / "t.tif", {});
    Dataset ds = open(dir / "t.tif");
    ASSERT_TRUE(ds && ds->GetSpatialRef());
    EXPECT_TRUE(ds->GetSpatialRef()->IsLocal() || ds->GetSpatialRef()->IsProjected());
    EXPECT_DOUBLE_EQ(ds->GetSpatialRef()->GetLinearUnits(nullptr), 1.0);  // metres
}

TEST(GeoTiff, CogsAreTiledWithOverviewsAndTheBytesDoNotDependOnThreads) {
    TempDir dir;
    const Heightmap t = sample_terrain(700, 600, 10.0);
    geotiff::WriteOptions o;
    o.cog = true;
    o.compression = geotiff::Compression::zstd;
    o.threads = 1;
    geotiff::write(t, dir / "one.tif", o);
    o.threads = 2;
    geotiff::write(t, dir / "two.tif", o);
    EXPECT_EQ(slurp(dir / "one.tif"), slurp(dir / "two.tif"));
    Dataset ds = open(dir / "one.tif");
    ASSERT_TRUE(ds);
    EXPECT_STREQ(ds->GetMetadataItem("LAYOUT", "IMAGE_STRUCTURE"), "COG");
    int bx = 0, by = 0;
    ds->GetRasterBand(1)->GetBlockSize(&bx, &by);
    EXPECT_EQ(bx, 256);
    EXPECT_EQ(by, 256);
    EXPECT_GE(ds->GetRasterBand(1)->GetOverviewCount(), 1);
    EXPECT_EQ(band_values(*ds, 1), t.heights());
}

TEST(GeoTiff, AnUnknownCrsIsNamed) {
    const auto c = geotiff::check_crs("EPSG:999999");
    EXPECT_FALSE(c.ok);
    EXPECT_NE(c.message.find("unknown CRS 'EPSG:999999'"), std::string::npos) << c.message;
    EXPECT_NE(c.message.find("give an EPSG code such as EPSG:32632"), std::string::npos) << c.message;
    EXPECT_TRUE(geotiff::check_crs("EPSG:4326").ok);
    EXPECT_TRUE(geotiff::check_crs("").ok);
    // A CRS string may not read files.
    EXPECT_FALSE(geotiff::check_crs("/etc/passwd").ok);
}

TEST(GeoTiffImport, ARoundTripKeepsEveryBitAndTheCellSize) {
    TempDir dir;
    const Heightmap t = sample_terrain(41, 29, 12.5);
    geotiff::write(t, dir / "t.tif", {});
    geotiff::ReadOptions o;
    const auto r = geotiff::read(dir / "t.tif", o);
    EXPECT_EQ(r.terrain->width(), 41);
    EXPECT_EQ(r.terrain->height(), 29);
    EXPECT_DOUBLE_EQ(r.terrain->cell(), 12.5);
    EXPECT_EQ(r.terrain->heights(), t.heights());
    EXPECT_EQ(r.holes_filled, 0u);
}

TEST(GeoTiffImport, ResamplingKeepsTheCornersAndALinearSlopeExactly) {
    TempDir dir;
    Heightmap ramp(101, 51, 10.0);
    for (int y = 0; y < 51; ++y)
        for (int x = 0; x < 101; ++x) ramp.heights()[std::size_t(y) * 101 + x] = float(2 * x + 3 * y);
    geotiff::write(ramp, dir / "ramp.tif", {});
    for (auto method : {geotiff::Resample::bilinear, geotiff::Resample::cubic}) {
        geotiff::ReadOptions o;
        o.size = std::make_pair(26, 11);  // every 4th column, every 5th row
        o.resample = method;
        const auto r = geotiff::read(dir / "ramp.tif", o);
        ASSERT_EQ(r.terrain->width(), 26);
        EXPECT_DOUBLE_EQ(r.terrain->cell(), 40.0);  // the extent is kept: 100 cells of 10 m in 25 cells
        for (int y = 0; y < 11; ++y)
            for (int x = 0; x < 26; ++x)
                EXPECT_NEAR(r.terrain->heights()[std::size_t(y) * 26 + x], 2 * (4 * x) + 3 * (5 * y), 1e-3)
                    << x << "," << y;
    }
}

TEST(GeoTiffImport, NodataHolesAreFilledFromTheirSurroundingsOrRefused) {
    TempDir dir;
    // An SRTM-like Int16 tile of 30 m cells in UTM 32N, with a hole of nodata.
    GDALAllRegister();
    const int n = 61;
    {
        GDALDriver* gtiff = GetGDALDriverManager()->GetDriverByName("GTiff");
        Dataset ds(gtiff->Create((dir / "dem.tif").c_str(), n, n, 1, GDT_Int16, nullptr));
        double g[6] = {380000.0, 30.0, 0, 5100000.0, 0, -30.0};
        ds->SetGeoTransform(g);
        OGRSpatialReference utm;
        utm.importFromEPSG(32632);
        ds->SetSpatialRef(&utm);
        std::vector<std::int16_t> v(n * n, 1000);
        for (int y = 20; y < 30; ++y)
            for (int x = 20; x < 33; ++x) v[y * n + x] = -32768;
        ds->GetRasterBand(1)->SetNoDataValue(-32768);
        ASSERT_EQ(ds->GetRasterBand(1)->RasterIO(GF_Write, 0, 0, n, n, v.data(), n, n, GDT_Int16, 0, 0, nullptr),
                  CE_None);
    }
    geotiff::ReadOptions o;
    const auto r = geotiff::read(dir / "dem.tif", o);
    EXPECT_EQ(r.holes_filled, 130u);
    for (float h : r.terrain->heights()) EXPECT_EQ(h, 1000.0f);  // filled from flat ground: flat
    EXPECT_DOUBLE_EQ(r.terrain->cell(), 30.0);
    EXPECT_FALSE(r.info.warp.has_value());
    o.holes = geotiff::Holes::refuse;
    try {
        geotiff::read(dir / "dem.tif", o);
        FAIL() << "holes were not refused";
    } catch (const BadInput& e) {
        EXPECT_NE(std::string(e.what()).find("has 130 nodata samples (the first at column 20, row 20); use "
                                             "holes=fill to fill them from their surroundings"),
                  std::string::npos)
            << e.what();
    }
}

TEST(GeoTiffImport, AGeographicTileIsWarpedToSquareMetresNotStretched) {
    TempDir dir;
    // 1 arc-second at 46° N: 21.5 m east–west by 30.9 m north–south, a plane rising 1 m a sample eastward
    // (4.65 % east–west) and 2 m a sample southward (6.48 %).
    GDALAllRegister();
    const int n = 61;
    {
        GDALDriver* gtiff = GetGDALDriverManager()->GetDriverByName("GTiff");
        Dataset ds(gtiff->Create((dir / "dem.tif").c_str(), n, n, 1, GDT_Float32, nullptr));
        double g[6] = {7.0, 1.0 / 3600, 0, 46.0 + n / 3600.0, 0, -1.0 / 3600};
        ds->SetGeoTransform(g);
        OGRSpatialReference wgs;
        wgs.importFromEPSG(4326);
        ds->SetSpatialRef(&wgs);
        std::vector<float> v(n * n);
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) v[y * n + x] = float(1000 + x + 2 * y);
        ASSERT_EQ(ds->GetRasterBand(1)->RasterIO(GF_Write, 0, 0, n, n, v.data(), n, n, GDT_Float32, 0, 0, nullptr),
                  CE_None);
    }
    const auto info = geotiff::probe(dir / "dem.tif");
    EXPECT_NEAR(info.pixel_x_metres, 21.51, 0.02);  // at the tile's mid latitude, 46.008° N
    EXPECT_NEAR(info.pixel_y_metres, 30.87, 0.02);
    ASSERT_TRUE(info.warp.has_value());
    geotiff::ReadOptions o;
    o.holes = geotiff::Holes::mask;
    const auto r = geotiff::read(dir / "dem.tif", o);
    ASSERT_TRUE(r.info.warp.has_value());
    EXPECT_EQ(r.terrain->width(), info.warp->width);
    EXPECT_EQ(r.terrain->height(), info.warp->height);
    EXPECT_DOUBLE_EQ(r.terrain->cell(), info.pixel_y_metres);  // the longer side
    EXPECT_NEAR(r.terrain->width() * r.terrain->cell(), n * info.pixel_x_metres, 2 * r.terrain->cell());
    // The plane's gradients, in metres per metre, where the warp had data on all sides.
    const int w = r.terrain->width(), h = r.terrain->height();
    const auto& z = r.terrain->heights();
    const auto holes = r.terrain->has_layer("nodata") ? r.terrain->layer("nodata").data : nullptr;
    const double c = r.terrain->cell();
    int checked = 0;
    for (int y = 3; y + 3 < h; ++y)
        for (int x = 3; x + 3 < w; ++x) {
            bool inside = true;
            for (int dy = -3; dy <= 3 && holes; ++dy)
                for (int dx = -3; dx <= 3; ++dx) inside = inside && holes[(y + dy) * w + x + dx] == 0.0f;
            if (!inside) continue;
            const std::size_t i = std::size_t(y) * w + x;
            EXPECT_NEAR((z[i + 1] - z[i - 1]) / (2 * c), 1.0 / info.pixel_x_metres, 2e-3) << x << "," << y;
            EXPECT_NEAR((z[i + w] - z[i - w]) / (2 * c), 2.0 / info.pixel_y_metres, 2e-3) << x << "," << y;
            ++checked;
        }
    EXPECT_GT(checked, w * h / 2);
}

TEST(GeoTiffCli, ExportThenImportThroughTheBinaryAndGdalinfoReadsIt) {
    TempDir dir;
    dir.write("out.orogen",
              "orogen 1\nseed 5\ngrid 65 cell=20\nb = generate:fault(iterations=40, displacement=8)\n"
              "w = erode:hydraulic(b, iterations=5)\n"
              "export:geotiff(w, path=\"dem.tif\", crs=\"EPSG:32633\", origin=(400000, 5000000), "
              "layers=\"water, eroded\", nodata=\"-9999\")\n"
              "export:raw(w, path=\"w.r32\")\n");
    RunResult r = run_orogen("run out.orogen --out out --quiet", "", dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    // gdalinfo (Debian's gdal-bin, installed by tools/setup.sh) as a GIS user would check the file.
    dir.write("info.sh", "gdalinfo -json out/dem.tif > info.json\n");
    ASSERT_EQ(std::system(("cd '" + dir.path().string() + "' && bash info.sh").c_str()), 0);
    const std::string info = slurp(dir / "info.json");
    EXPECT_NE(info.find("WGS 84 / UTM zone 33N"), std::string::npos) << info.substr(0, 2000);
    EXPECT_NE(info.find("\"description\":\"eroded\""), std::string::npos);
    EXPECT_NE(info.find("\"noDataValue\":-9999"), std::string::npos);
    // Import it again, at its own size: the same floats as the RAW of the same terrain.
    dir.write("in.orogen",
              "orogen 1\ngrid 9\nd = import:geotiff(path=\"out/dem.tif\", resample=none)\n"
              "export:raw(d, path=\"d.r32\")\n");
    r = run_orogen("run in.orogen --out back --quiet", "", dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(read_r32(dir / "back/d.r32"), read_r32(dir / "out/w.r32"));
    EXPECT_NE(slurp(dir / "back/d.r32.json").find("\"cell_size\": 20,"), std::string::npos)
        << slurp(dir / "back/d.r32.json");
}

TEST(GeoTiffCli, BadInputIsRefusedAtCheckTimeNamingTheParameter) {
    TempDir dir;
    dir.write("not-a-raster.tif", "this is text");
    dir.write("s.orogen",
              "orogen 1\ngrid 33\nb = generate:fault()\n"
              "export:geotiff(b, path=\"a.tif\", crs=\"EPSG:999999\")\n"
              "export:geotiff(b, path=\"b.tif\", layers=\"snow\")\n"
              "export:geotiff(b, path=\"c.tif\", nodata=\"lots\")\n"
              "d = import:geotiff(path=\"not-a-raster.tif\")\n");
    const RunResult r = run_orogen("check s.orogen", "", dir.path());
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("s.orogen:4:37: error: export:geotiff: unknown CRS 'EPSG:999999'"), std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("s.orogen:5:40: error: export:geotiff: no layer 'snow' on the input"), std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("s.orogen:6:40: error: export:geotiff: nodata must be a number (e.g. -32768) or none, got "
                         "'lots'"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("s.orogen:7:25: error: import:geotiff: GDAL cannot open"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("as a raster"), std::string::npos) << r.err;
}
