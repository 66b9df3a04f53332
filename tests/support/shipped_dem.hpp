// GeoTIFF DEMs for the tests, and the reference DEMs shipped in data/dems/ (data/dems/README.md: Float32 GeoTIFF, metres, square metric
// cells, north up), read through GDAL for the tests that measure against them. Needs OROGEN_SOURCE_DIR.
#pragma once

#include <gdal.h>

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace orogen::test {

struct ShippedDem {
    std::vector<float> z;  ///< heights, m, rows north to south
    int width = 0, height = 0;  ///< 0 wide: the file could not be read
    double cell = 0.0;  ///< m
};

/// A Float32 GeoTIFF's first band, its cell the geotransform's pixel width; an empty one (0 wide, no
/// heights) if it cannot be read.
inline ShippedDem read_geotiff_dem(const std::filesystem::path& path) {
    GDALAllRegister();
    ShippedDem dem;
    GDALDatasetH ds = GDALOpen(path.c_str(), GA_ReadOnly);
    if (!ds) return dem;
    dem.width = GDALGetRasterXSize(ds);
    dem.height = GDALGetRasterYSize(ds);
    double transform[6];
    GDALGetGeoTransform(ds, transform);
    dem.cell = transform[1];
    dem.z.resize(std::size_t(dem.width) * std::size_t(dem.height));
    if (GDALRasterIO(GDALGetRasterBand(ds, 1), GF_Read, 0, 0, dem.width, dem.height, dem.z.data(), dem.width,
                     dem.height, GDT_Float32, 0, 0) != CE_None) {
        dem.width = 0;
        dem.z.clear();
    }
    GDALClose(ds);
    return dem;
}

/// data/dems/NAME.tif.
inline ShippedDem read_shipped_dem(const std::string& name) {
    return read_geotiff_dem(std::filesystem::path(OROGEN_SOURCE_DIR) / "data" / "dems" / (name + ".tif"));
}

}  // namespace orogen::test
