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
// geotransform. A raster whose cells are not square in metres (a geographic
// CRS in degrees, or unequal pixel sides) is first warped through GDAL's
// warper to square cells — in a local transverse Mercator projection centred
// on it for a geographic CRS — or refused (Square::refuse); it is never
// stretched.
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
    /// The pixel's sides in metres, east–west and north–south (a geographic CRS's degrees converted at the
    /// raster's centre); 0 if the file has no geotransform.
    double pixel_x_metres = 0.0, pixel_y_metres = 0.0;
    /// Vertex spacing in metres as read: the pixel size, or for a raster that is warped to square cells
    /// (`warp`), the warped cell; 0 if the file has no geotransform.
    double cell_metres = 0.0;
    /// Set when the cells are not square metres: how read() warps the raster to square cells.
    struct Warp {
        int width = 0, height = 0;  ///< the warped raster's samples
        double cell = 0.0;  ///< m, square
        std::string why;  ///< "1″ × 1″ of WGS 84: 26.4 m east–west by 30.9 m north–south at 31.30° N"
        std::string target;  ///< "a local transverse Mercator projection centred at 31.30° N 78.30° E"
        std::string proj;  ///< the target CRS as a PROJ string (for a gdalwarp command); "" = the raster's own
    };
    std::optional<Warp> warp;
};
/// Throws orogen::BadInput naming the file if GDAL cannot open it as a
/// raster, or `band` does not exist. `cell` (m, 0 = the longer side of the pixel) is the square cell a
/// raster with non-square cells would be warped to.
RasterInfo probe(const std::filesystem::path& path, int band = 1, double cell = 0.0);

/// What read() did to a raster with non-square cells, as one sentence for the log ("" for square cells).
std::string warp_note(const RasterInfo& info, const std::string& resample);
/// Why a raster with non-square cells is refused (Square::refuse), and how to proceed.
std::string refuse_message(const RasterInfo& info, const std::filesystem::path& path);

enum class Resample { nearest, bilinear, cubic };
Resample parse_resample(const std::string& name);
/// What to do with nodata samples: fill them from their surroundings; refuse the file; or fill them and
/// mark them in a layer `nodata` (1 a hole, 0 data; at the raster's own size only), for analyze:terrain.
enum class Holes { fill, refuse, mask };
/// What to do with a raster whose cells are not square in metres: warp it to square cells, or refuse it.
enum class Square { warp, refuse };

struct ReadOptions {
    int band = 1;
    /// Output size in vertices; unset = the raster's own size (no resampling).
    std::optional<std::pair<int, int>> size;
    Resample resample = Resample::bilinear;
    Holes holes = Holes::fill;
    /// metres; 0 = from the file (scaled by the resampling). For a raster warped to square cells, their size
    /// (0 = the longer side of the raster's pixel).
    double cell = 0.0;
    Square square = Square::warp;
};

struct ReadResult {
    std::shared_ptr<Heightmap> terrain;
    std::size_t holes_filled = 0;
    RasterInfo info;  ///< what the file declared (with `warp` set if it was warped to square cells)
};
/// Reads one band as heights in metres. Throws orogen::BadInput for a file
/// GDAL cannot read, holes with Holes::refuse (saying how many and where the
/// first is), a raster without a cell size when `cell` is 0, or non-square cells with Square::refuse.
/// The samples a warp leaves uncovered (the corners of a rotated footprint) are holes like the file's own.
ReadResult read(const std::filesystem::path& path, const ReadOptions& options);

}  // namespace orogen::geotiff
