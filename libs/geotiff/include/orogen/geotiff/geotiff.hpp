// geotiff.hpp — heightmaps to and from georeferenced rasters through GDAL.
//
// Writing: Float32 GeoTIFF, band 1 the heights in metres, one more band per
// chosen layer (band description = layer name). Samples are vertices, so the
// file says AREA_OR_POINT=Point and its geotransform puts pixel centres on
// the vertices: sample (x, y) lies at (origin.x + x·cell,
// origin.y + (height − 1 − y)·cell), origin being the south-west vertex
// (rows run north to south, as in the heightmap). The CRS is any GDAL
// accepts ("EPSG:32632", WKT, PROJ strings) or, by default, a local metric
// engineering CRS (metres east and north of an arbitrary origin).
//
// Reading: any raster GDAL opens (GeoTIFF, SRTM .hgt, ESRI .asc, USGS .dem,
// ...), one band, optionally resampled to another size; nodata holes are
// filled from their surroundings or refused. The cell size comes from the
// geotransform (metres, or degrees converted at the raster's mid latitude).
//
// Plain C++ over orogen::Heightmap; the only place GDAL's headers are included
// is geotiff.cpp.
#pragma once

#include <orogen/grid.hpp>
#include <orogen/values.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace orogen::geotiff {

enum class Compression { none, deflate, zstd, lzw };
/// "none" | "deflate" | "zstd" | "lzw".
Compression parse_compression(const std::string& name);

struct WriteOptions {
    std::string crs;  ///< anything GDAL's SetFromUserInput takes; "" = local metric CRS
    /// Easting/northing of the south-west vertex, sample (0, height − 1), in
    /// the CRS's units (as ESRI grids' xllcorner/yllcorner): (0, 0) puts the
    /// map in the positive quadrant.
    Point2 origin{0.0, 0.0};
    std::optional<double> nodata;  ///< written as the bands' nodata value
    Compression compression = Compression::deflate;
    bool tiled = false;  ///< 256 × 256 tiles instead of strips
    bool cog = false;  ///< Cloud-Optimized GeoTIFF (tiled, with overviews)
    std::vector<std::string> layers;  ///< written as extra bands, in this order
    int threads = 0;  ///< compression threads (0 = all cores); the bytes do not depend on it
};

/// A CRS given as text, as WKT, or an error message naming it (for check time).
struct CrsCheck {
    bool ok = false;
    std::string wkt;
    std::string message;
};
CrsCheck check_crs(const std::string& crs);

/// Writes `terrain` to `path` (a temporary name: the caller renames it).
/// Throws orogen::BadInput for a missing layer or an unusable CRS,
/// orogen::Error for I/O failures (with GDAL's message).
void write(const Heightmap& terrain, const std::filesystem::path& path, const WriteOptions& options);

/// What a raster file declares, read without its samples.
struct RasterInfo {
    int width = 0, height = 0;
    int bands = 0;
    std::string driver;  ///< GDAL's short name: GTiff, SRTMHGT, AAIGrid, USGSDEM...
    std::string crs_wkt;  ///< "" if none
    bool geographic = false;  ///< CRS in degrees
    double geotransform[6] = {0, 1, 0, 0, 0, 1};
    bool has_geotransform = false;
    std::optional<double> nodata;  ///< of the band asked for
    /// Vertex spacing in metres: the pixel size, converted from degrees at
    /// the mid latitude for a geographic CRS; 0 if the file has no geotransform.
    double cell_metres = 0.0;
};
/// Throws orogen::BadInput naming the file if GDAL cannot open it as a
/// raster, or `band` does not exist.
RasterInfo probe(const std::filesystem::path& path, int band = 1);

enum class Resample { nearest, bilinear, cubic };
Resample parse_resample(const std::string& name);
/// What to do with nodata samples: fill them from their surroundings; refuse the file; or fill them and
/// mark them in a layer `nodata` (1 a hole, 0 data; at the raster's own size only), for analyze:terrain.
enum class Holes { fill, refuse, mask };

struct ReadOptions {
    int band = 1;
    /// Output size in vertices; unset = the raster's own size (no resampling).
    std::optional<std::pair<int, int>> size;
    Resample resample = Resample::bilinear;
    Holes holes = Holes::fill;
    double cell = 0.0;  ///< metres; 0 = from the file (scaled by the resampling)
};

struct ReadResult {
    std::shared_ptr<Heightmap> terrain;
    std::size_t holes_filled = 0;
};
/// Reads one band as heights in metres. Throws orogen::BadInput for a file
/// GDAL cannot read, holes with Holes::refuse (saying how many and where the
/// first is), or a raster without a cell size when `cell` is 0.
ReadResult read(const std::filesystem::path& path, const ReadOptions& options);

}  // namespace orogen::geotiff
