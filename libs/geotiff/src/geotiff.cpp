#include <orogen/geotiff/geotiff.hpp>

#include <orogen/error.hpp>
#include <orogen/parallel.hpp>

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_string.h>
#include <gdal_alg.h>
#include <gdal_priv.h>
#include <gdalwarper.h>
#include <ogr_spatialref.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <mutex>
#include <numbers>
#include <thread>

namespace fs = std::filesystem;

namespace orogen::geotiff {

namespace {

void init_gdal() {
    static std::once_flag once;
    std::call_once(once, [] {
        GDALAllRegister();
        // No .aux.xml beside our temporary file: everything we write fits in the TIFF itself.
        CPLSetConfigOption("GDAL_PAM_ENABLED", "NO");
    });
}

/// GDAL's messages go to us, not to stderr; last_error() reads the latest.
class QuietErrors {
public:
    QuietErrors() {
        CPLPushErrorHandler(CPLQuietErrorHandler);
        CPLErrorReset();
    }
    ~QuietErrors() { CPLPopErrorHandler(); }
    QuietErrors(const QuietErrors&) = delete;
    QuietErrors& operator=(const QuietErrors&) = delete;
};

std::string last_error() {
    const char* m = CPLGetLastErrorMsg();
    return m && *m ? std::string(m) : std::string("GDAL gave no reason");
}

struct DatasetCloser {
    void operator()(GDALDataset* d) const { GDALClose(GDALDataset::ToHandle(d)); }
};
using Dataset = std::unique_ptr<GDALDataset, DatasetCloser>;

/// Options for SetFromUserInput: a CRS string may not read files or go on the network.
const char* const kCrsInputOptions[] = {"ALLOW_NETWORK_ACCESS=NO", "ALLOW_FILE_ACCESS=NO", nullptr};

bool make_crs(const std::string& crs, OGRSpatialReference& srs, std::string& message) {
    if (crs.empty()) {
        srs.SetLocalCS("orogen local metric");
        srs.SetLinearUnits(SRS_UL_METER, 1.0);
        return true;
    }
    QuietErrors quiet;
    if (srs.SetFromUserInput(crs.c_str(), kCrsInputOptions) != OGRERR_NONE) {
        message = "unknown CRS '" + crs + "' (GDAL: " + last_error() +
            "); give an EPSG code such as EPSG:32632, a WKT string or a PROJ string";
        return false;
    }
    return true;
}

std::string to_wkt(const OGRSpatialReference& srs) {
    char* text = nullptr;
    const char* options[] = {"FORMAT=WKT2_2019", nullptr};
    srs.exportToWkt(&text, options);
    std::string wkt = text ? text : "";
    CPLFree(text);
    return wkt;
}

}  // namespace

Compression parse_compression(const std::string& name) {
    if (name == "none") return Compression::none;
    if (name == "deflate") return Compression::deflate;
    if (name == "zstd") return Compression::zstd;
    if (name == "lzw") return Compression::lzw;
    throw BadInput("unknown compression '" + name + "' (use none, deflate, zstd or lzw)");
}

Resample parse_resample(const std::string& name) {
    if (name == "nearest") return Resample::nearest;
    if (name == "bilinear") return Resample::bilinear;
    if (name == "cubic") return Resample::cubic;
    throw BadInput("unknown resampling '" + name + "' (use nearest, bilinear or cubic)");
}

CrsCheck check_crs(const std::string& crs) {
    init_gdal();
    CrsCheck result;
    OGRSpatialReference srs;
    result.ok = make_crs(crs, srs, result.message);
    if (result.ok) result.wkt = to_wkt(srs);
    return result;
}

// ------------------------------------------------------------------ write

void write(const Heightmap& terrain, const fs::path& path, const WriteOptions& options) {
    init_gdal();
    QuietErrors quiet;
    const int w = terrain.width(), h = terrain.height();
    const double cell = terrain.cell();

    OGRSpatialReference srs;
    std::string message;
    if (!make_crs(options.crs, srs, message)) throw BadInput(message);
    for (const auto& name : options.layers)
        if (!terrain.has_layer(name)) terrain.layer(name);  // throws BadInput naming the layers there are

    // An in-memory dataset over the heightmap's own arrays (no copy), then
    // GTiff's or COG's CreateCopy streams it into the file block by block.
    GDALDriver* mem_driver = GetGDALDriverManager()->GetDriverByName("MEM");
    if (!mem_driver) throw Error("GDAL has no MEM driver");
    Dataset mem(mem_driver->Create("", w, h, 0, GDT_Float32, nullptr));
    if (!mem)
        throw Error("GDAL could not make an in-memory raster of " + std::to_string(w) + "×" + std::to_string(h) + ": " +
                    last_error());
    auto add_band = [&](const float* data, const std::string& description) {
        char pointer[64];
        std::snprintf(pointer, sizeof pointer, "DATAPOINTER=%p", static_cast<const void*>(data));
        const char* band_options[] = {pointer, nullptr};
        if (mem->AddBand(GDT_Float32, const_cast<char**>(band_options)) != CE_None)
            throw Error("GDAL could not add a band: " + last_error());
        GDALRasterBand* band = mem->GetRasterBand(mem->GetRasterCount());
        band->SetDescription(description.c_str());
        band->SetUnitType("m");
        if (options.nodata) band->SetNoDataValue(*options.nodata);
    };
    add_band(terrain.heights().data(), "height");
    for (const auto& name : options.layers) add_band(terrain.layer(name).data, name);

    // Samples are vertices: pixel centres on them (AREA_OR_POINT=Point), the
    // geotransform (always corner-based in GDAL) half a cell out.
    const double west = options.origin.x, north = options.origin.y + double(h - 1) * cell;
    double geotransform[6] = {west - 0.5 * cell, cell, 0.0, north + 0.5 * cell, 0.0, -cell};
    mem->SetGeoTransform(geotransform);
    mem->SetSpatialRef(&srs);
    mem->SetMetadataItem("AREA_OR_POINT", "Point");
    mem->SetMetadataItem("TIFFTAG_SOFTWARE", "orogen");

    CPLStringList creation;
    const int threads = options.threads > 0 ? options.threads : int(std::max(1u, std::thread::hardware_concurrency()));
    creation.SetNameValue("NUM_THREADS", std::to_string(threads).c_str());
    creation.SetNameValue("BIGTIFF", "IF_SAFER");
    const char* compress = options.compression == Compression::deflate ? "DEFLATE"
        : options.compression == Compression::zstd                     ? "ZSTD"
        : options.compression == Compression::lzw                      ? "LZW"
                                                                       : "NONE";
    creation.SetNameValue("COMPRESS", compress);
    const bool predictor = options.compression != Compression::none;
    const char* driver_name = options.cog ? "COG" : "GTiff";
    if (options.cog) {
        creation.SetNameValue("BLOCKSIZE", "256");
        creation.SetNameValue("OVERVIEWS", "AUTO");
        if (predictor) creation.SetNameValue("PREDICTOR", "FLOATING_POINT");
        if (options.compression == Compression::zstd) creation.SetNameValue("LEVEL", "3");
    } else {
        if (predictor) creation.SetNameValue("PREDICTOR", "3");  // floating-point predictor
        if (options.compression == Compression::zstd)
            creation.SetNameValue("ZSTD_LEVEL", "3");  // GDAL defaults to 9: 10× slower for 2 % less
        if (options.tiled) {
            creation.SetNameValue("TILED", "YES");
            creation.SetNameValue("BLOCKXSIZE", "256");
            creation.SetNameValue("BLOCKYSIZE", "256");
        }
    }
    GDALDriver* driver = GetGDALDriverManager()->GetDriverByName(driver_name);
    if (!driver) throw Error(std::string("this GDAL has no ") + driver_name + " driver");
    Dataset out(driver->CreateCopy(path.c_str(), mem.get(), FALSE, creation.List(), nullptr, nullptr));
    if (!out) throw Error("GDAL could not write " + path.string() + ": " + last_error());
    out.reset();  // flushes and closes
    if (CPLGetLastErrorType() == CE_Failure)
        throw Error("GDAL failed while writing " + path.string() + ": " + last_error());
}

// ------------------------------------------------------------------- read

namespace {

Dataset open_raster(const fs::path& path) {
    init_gdal();
    QuietErrors quiet;
    std::error_code ec;
    const auto status = fs::status(path, ec);
    if (ec || !fs::exists(status)) throw BadInput("no such file: " + path.string());
    if (!fs::is_regular_file(status))
        throw BadInput(path.string() + " is not a regular file (a device, FIFO or folder); give a raster file");
    Dataset ds(GDALDataset::Open(path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY));
    if (!ds)
        throw BadInput("GDAL cannot open " + path.string() + " as a raster (" + last_error() +
                       "); give a GeoTIFF, .hgt, .asc, .dem or another format `gdalinfo --formats` lists");
    if (ds->GetRasterCount() < 1) throw BadInput(path.string() + " holds no raster band");
    return ds;
}

/// Metres per degree of longitude and latitude at `latitude` (WGS 84 ellipsoid, to 0.01 %).
std::pair<double, double> metres_per_degree(double latitude) {
    const double phi = latitude * std::numbers::pi / 180.0;
    const double lon = 111412.84 * std::cos(phi) - 93.5 * std::cos(3 * phi) + 0.118 * std::cos(5 * phi);
    const double lat = 111132.92 - 559.82 * std::cos(2 * phi) + 1.175 * std::cos(4 * phi) - 0.0023 * std::cos(6 * phi);
    return {lon, lat};
}

RasterInfo describe(GDALDataset& ds, const fs::path& path, int band_index) {
    RasterInfo info;
    info.width = ds.GetRasterXSize();
    info.height = ds.GetRasterYSize();
    info.bands = ds.GetRasterCount();
    info.driver = ds.GetDriver() ? ds.GetDriver()->GetDescription() : "";
    if (band_index < 1 || band_index > info.bands)
        throw BadInput(path.string() + " has " + std::to_string(info.bands) + (info.bands == 1 ? " band" : " bands") +
                       "; band " + std::to_string(band_index) + " does not exist");
    double units = 1.0;  // metres per unit of a projected CRS (0.3048 for feet)
    if (const OGRSpatialReference* srs = ds.GetSpatialRef()) {
        info.crs_wkt = to_wkt(*srs);
        info.geographic = srs->IsGeographic();
        if (srs->IsProjected()) units = srs->GetLinearUnits();
        if (!(units > 0.0)) units = 1.0;
    }
    info.has_geotransform = ds.GetGeoTransform(info.geotransform) == CE_None;
    int has_nodata = 0;
    const double nodata = ds.GetRasterBand(band_index)->GetNoDataValue(&has_nodata);
    if (has_nodata) info.nodata = nodata;
    if (info.has_geotransform) {
        const double* g = info.geotransform;
        double px = std::abs(g[1]) * units, py = std::abs(g[5]) * units;
        if (info.geographic) {
            const double mid_lat = g[3] + g[5] * 0.5 * info.height;
            const auto [lon, lat] = metres_per_degree(mid_lat);
            px *= lon;
            py *= lat;
        }
        info.pixel_x_metres = px;
        info.pixel_y_metres = py;
        info.cell_metres = px;
    }
    return info;
}

/// Whether the raster's cells are not square metres: a geographic CRS (degrees, whose east–west metres
/// shrink with latitude), or projected pixel sides that differ by more than 0.1 %.
bool non_square(const RasterInfo& info) {
    if (!info.has_geotransform) return false;
    if (info.geographic) return true;
    const double px = info.pixel_x_metres, py = info.pixel_y_metres;
    return std::abs(px - py) > 1e-3 * std::max(px, py);
}

/// How a raster with non-square cells is warped to square ones: the target CRS and grid.
struct SquarePlan {
    RasterInfo::Warp warp;
    OGRSpatialReference target;
    bool has_target = false;  ///< false: a raster without a CRS, warped by its geotransform alone
    double geotransform[6] = {0, 1, 0, 0, 0, -1};
};

std::string fixed(double v, int decimals) {
    char text[48];
    std::snprintf(text, sizeof text, "%.*f", decimals, v);
    return text;
}

std::string latitude_text(double lat) { return fixed(std::abs(lat), 2) + "° " + (lat < 0 ? "S" : "N"); }
std::string longitude_text(double lon) { return fixed(std::abs(lon), 2) + "° " + (lon < 0 ? "W" : "E"); }

/// A pixel side in degrees as arc-seconds when it is a whole number of them ("1″"), else degrees.
std::string degrees_text(double d) {
    const double arcsec = d * 3600.0;
    if (std::abs(arcsec - std::round(arcsec)) < 1e-3 * std::max(1.0, arcsec)) return fixed(std::round(arcsec), 0) + "″";
    if (arcsec < 600.0) return fixed(arcsec, 3) + "″";
    return fixed(d, 6) + "°";
}

/// The plan for a raster with non-square cells; `cell` (m) the square cell, 0 = the pixel's longer side
/// (north–south for 1″ data): no axis is interpolated finer than the file resolves it.
SquarePlan plan_square(GDALDataset& ds, RasterInfo& info, double cell) {
    QuietErrors quiet;
    SquarePlan plan;
    const double* g = info.geotransform;
    const double px = info.pixel_x_metres, py = info.pixel_y_metres;
    plan.warp.cell = cell > 0.0 ? cell : std::max(px, py);
    const OGRSpatialReference* source = ds.GetSpatialRef();
    const std::string sides = fixed(px, 1) + " m east–west by " + fixed(py, 1) + " m north–south";
    if (info.geographic && source) {
        const double lat = g[3] + g[5] * 0.5 * info.height, lon = g[0] + g[1] * 0.5 * info.width;
        // A transverse Mercator on the raster's own datum, centred on it: true to scale along its central
        // meridian, 1 + x²/2R² = 1.00005 at 60 km east or west of it.
        plan.target.SetProjCS("orogen local transverse Mercator");
        plan.target.CopyGeogCSFrom(source);
        plan.target.SetTM(lat, lon, 1.0, 0.0, 0.0);
        plan.target.SetLinearUnits(SRS_UL_METER, 1.0);
        plan.target.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
        plan.has_target = true;
        const char* datum = source->GetName();
        plan.warp.why = degrees_text(std::abs(g[1])) + " × " + degrees_text(std::abs(g[5])) + " of " +
            (datum && *datum ? datum : "a geographic CRS") + ": " + sides + " at " + latitude_text(lat);
        plan.warp.target =
            "a local transverse Mercator projection centred at " + latitude_text(lat) + " " + longitude_text(lon);
        char* proj = nullptr;
        if (plan.target.exportToProj4(&proj) == OGRERR_NONE && proj) plan.warp.proj = proj;
        CPLFree(proj);
    } else {
        if (source) {
            plan.target = *source;
            plan.target.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
            plan.has_target = true;
        }
        plan.warp.why = "pixels of " + sides;
        plan.warp.target = "its own CRS";
    }
    // The footprint: the raster's own bounds, or in the local projection the bounds of its edges (64 points
    // along each) transformed; square cells cover it.
    double extent[4] = {g[0], g[3] + g[5] * info.height, g[0] + g[1] * info.width, g[3]};  // W, S, E, N
    if (info.geographic && source) {
        OGRSpatialReference from(*source);
        from.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
        std::unique_ptr<OGRCoordinateTransformation> to(OGRCreateCoordinateTransformation(&from, &plan.target));
        if (!to) throw BadInput("GDAL cannot project " + info.driver + " raster's CRS: " + last_error());
        std::vector<double> xs, ys;
        constexpr int steps = 64;
        for (int k = 0; k <= steps; ++k) {
            const double t = double(k) / steps;
            for (const auto& [fx, fy] : {std::pair{t, 0.0}, std::pair{t, 1.0}, std::pair{0.0, t}, std::pair{1.0, t}}) {
                xs.push_back(g[0] + g[1] * fx * info.width);
                ys.push_back(g[3] + g[5] * fy * info.height);
            }
        }
        if (!to->Transform(xs.size(), xs.data(), ys.data()))
            throw BadInput("GDAL cannot project the raster's corners to warp it: " + last_error());
        extent[0] = *std::min_element(xs.begin(), xs.end());
        extent[2] = *std::max_element(xs.begin(), xs.end());
        extent[1] = *std::min_element(ys.begin(), ys.end());
        extent[3] = *std::max_element(ys.begin(), ys.end());
    }
    const double c = plan.warp.cell;
    plan.warp.width = std::max(1, int(std::ceil((extent[2] - extent[0]) / c - 1e-6)));
    plan.warp.height = std::max(1, int(std::ceil(std::abs(extent[3] - extent[1]) / c - 1e-6)));
    const double west = 0.5 * (extent[0] + extent[2]) - 0.5 * c * plan.warp.width;
    const double north = 0.5 * (extent[1] + extent[3]) + 0.5 * c * plan.warp.height;
    const double gt[6] = {west, c, 0.0, north, 0.0, -c};
    std::copy(gt, gt + 6, plan.geotransform);
    info.warp = plan.warp;
    info.cell_metres = c;
    return plan;
}

GDALResampleAlg warp_kernel(Resample r) {
    switch (r) {
        case Resample::nearest: return GRA_NearestNeighbour;
        case Resample::cubic: return GRA_Cubic;
        case Resample::bilinear:
        default: return GRA_Bilinear;
    }
}

/// The band warped to the plan's square cells (GDAL's warper, gdalwarp's 0.125-pixel approximation):
/// an in-memory Float32 raster whose uncovered samples and holes are NaN.
Dataset warp_square(GDALDataset& src, int band, const RasterInfo& info, const SquarePlan& plan, Resample r) {
    QuietErrors quiet;
    GDALDriver* mem_driver = GetGDALDriverManager()->GetDriverByName("MEM");
    if (!mem_driver) throw Error("GDAL has no MEM driver");
    const int w = plan.warp.width, h = plan.warp.height;
    Dataset dst(mem_driver->Create("", w, h, 1, GDT_Float32, nullptr));
    if (!dst) throw Error("GDAL could not make an in-memory raster to warp into: " + last_error());
    double gt[6];
    std::copy(plan.geotransform, plan.geotransform + 6, gt);
    dst->SetGeoTransform(gt);
    if (plan.has_target) dst->SetSpatialRef(&plan.target);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    dst->GetRasterBand(1)->SetNoDataValue(nan);
    dst->GetRasterBand(1)->Fill(nan);

    GDALWarpOptions* wo = GDALCreateWarpOptions();
    wo->hSrcDS = GDALDataset::ToHandle(&src);
    wo->hDstDS = GDALDataset::ToHandle(dst.get());
    wo->nBandCount = 1;
    wo->panSrcBands = static_cast<int*>(CPLMalloc(sizeof(int)));
    wo->panSrcBands[0] = band;
    wo->panDstBands = static_cast<int*>(CPLMalloc(sizeof(int)));
    wo->panDstBands[0] = 1;
    wo->eResampleAlg = warp_kernel(r);
    wo->eWorkingDataType = GDT_Float64;
    wo->padfSrcNoDataReal = static_cast<double*>(CPLMalloc(sizeof(double)));
    wo->padfSrcNoDataReal[0] = info.nodata ? *info.nodata : nan;
    wo->padfDstNoDataReal = static_cast<double*>(CPLMalloc(sizeof(double)));
    wo->padfDstNoDataReal[0] = nan;
    wo->papszWarpOptions = CSLSetNameValue(wo->papszWarpOptions, "INIT_DEST", "NO_DATA");
    void* exact = GDALCreateGenImgProjTransformer2(wo->hSrcDS, wo->hDstDS, nullptr);
    if (!exact) {
        GDALDestroyWarpOptions(wo);
        throw BadInput("GDAL cannot transform the raster's grid to warp it: " + last_error());
    }
    void* approx = GDALCreateApproxTransformer(GDALGenImgProjTransform, exact, 0.125);
    GDALApproxTransformerOwnsSubtransformer(approx, TRUE);
    wo->pfnTransformer = GDALApproxTransform;
    wo->pTransformerArg = approx;
    CPLErr err;
    {
        GDALWarpOperation operation;
        err = operation.Initialize(wo);
        if (err == CE_None) err = operation.ChunkAndWarpImage(0, 0, w, h);
    }
    GDALDestroyApproxTransformer(approx);
    wo->pTransformerArg = nullptr;
    GDALDestroyWarpOptions(wo);
    if (err != CE_None) throw BadInput("GDAL could not warp the raster to square cells: " + last_error());
    return dst;
}

/// Fills holes layer by layer from the valid samples inward: each hole next to
/// valid ground takes the mean of its valid 8-neighbours (as they stood before
/// this layer), then counts as valid. Deterministic, and exact where no holes are.
std::size_t fill_holes(std::vector<float>& v, std::vector<std::uint8_t>& valid, int w, int h) {
    std::size_t filled = 0;
    std::vector<std::size_t> front;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = std::size_t(y) * w + x;
            if (valid[i]) continue;
            bool edge = false;
            for (int dy = -1; dy <= 1 && !edge; ++dy)
                for (int dx = -1; dx <= 1 && !edge; ++dx) {
                    const int xx = x + dx, yy = y + dy;
                    edge = xx >= 0 && yy >= 0 && xx < w && yy < h && valid[std::size_t(yy) * w + xx];
                }
            if (edge) front.push_back(i);
        }
    std::vector<float> values;
    std::vector<std::size_t> next;
    while (!front.empty()) {
        values.assign(front.size(), 0.0f);
        for (std::size_t k = 0; k < front.size(); ++k) {
            const int x = int(front[k] % w), y = int(front[k] / w);
            double sum = 0.0;
            int n = 0;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int xx = x + dx, yy = y + dy;
                    if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
                    const std::size_t j = std::size_t(yy) * w + xx;
                    if (valid[j] == 1) sum += v[j], ++n;
                }
            values[k] = float(sum / n);
        }
        for (std::size_t k = 0; k < front.size(); ++k) {
            v[front[k]] = values[k];
            valid[front[k]] = 2;  // valid from the next layer on
        }
        next.clear();
        for (std::size_t i : front) {
            const int x = int(i % w), y = int(i / w);
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int xx = x + dx, yy = y + dy;
                    if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
                    const std::size_t j = std::size_t(yy) * w + xx;
                    if (valid[j] == 0) {
                        valid[j] = 3;  // queued
                        next.push_back(j);
                    }
                }
        }
        for (std::size_t i : front) valid[i] = 1;
        filled += front.size();
        std::sort(next.begin(), next.end());
        front.swap(next);
    }
    return filled;
}

/// Catmull-Rom weights for a sample at fraction t past the second of four.
inline void cubic_weights(double t, double w[4]) {
    const double t2 = t * t, t3 = t2 * t;
    w[0] = 0.5 * (-t3 + 2 * t2 - t);
    w[1] = 0.5 * (3 * t3 - 5 * t2 + 2);
    w[2] = 0.5 * (-3 * t3 + 4 * t2 + t);
    w[3] = 0.5 * (t3 - t2);
}

}  // namespace

RasterInfo probe(const fs::path& path, int band, double cell) {
    Dataset ds = open_raster(path);
    RasterInfo info = describe(*ds, path, band);
    if (non_square(info)) plan_square(*ds, info, cell);
    return info;
}

std::string warp_note(const RasterInfo& info, const std::string& resample) {
    if (!info.warp) return {};
    const auto& w = *info.warp;
    return "note: its cells are not square (" + w.why + "); warped with GDAL's warper (" + resample + ") to square " +
        fixed(w.cell, 2) + " m cells in " + w.target + ": " + std::to_string(info.width) + "×" +
        std::to_string(info.height) + " samples became " + std::to_string(w.width) + "×" + std::to_string(w.height) +
        ", the corners outside the raster nodata";
}

std::string refuse_message(const RasterInfo& info, const fs::path& path) {
    if (!info.warp) return {};
    const auto& w = *info.warp;
    const std::string c = fixed(w.cell, 2);
    return path.string() + " has cells that are not square (" + w.why +
        "); taking them as square would stretch the terrain. Give square=warp to warp it here to square " + c +
        " m cells in " + w.target + ", or warp it first: gdalwarp" +
        (w.proj.empty() ? std::string() : " -t_srs '" + w.proj + "'") + " -tr " + c + " " + c +
        " -r cubic -dstnodata nan " + path.filename().string() + " square.tif";
}

ReadResult read(const fs::path& path, const ReadOptions& options) {
    Dataset ds = open_raster(path);
    RasterInfo info = describe(*ds, path, options.band);
    if (info.has_geotransform && (info.geotransform[2] != 0.0 || info.geotransform[4] != 0.0))
        throw BadInput(path.string() +
                       " is rotated (its geotransform has shear terms); warp it north-up first, e.g. "
                       "gdalwarp " +
                       path.filename().string() + " north-up.tif");
    int band_index = options.band;
    // The file's nodata value; the warped raster's holes are NaN.
    bool has_nodata = info.nodata.has_value();
    const float nodata = info.nodata ? float(*info.nodata) : 0.0f;
    if (non_square(info)) {
        const SquarePlan plan = plan_square(*ds, info, options.cell);
        if (options.square == Square::refuse) throw BadInput(refuse_message(info, path));
        // Read at its own size (analyze), the warp is the only resampling: Catmull-Rom, which keeps the slopes
        // (the 90th percentile within 0.3° where bilinear loses 0.8°); else the kernel asked for.
        ds = warp_square(*ds, options.band, info, plan, options.size ? options.resample : Resample::cubic);
        band_index = 1;
        has_nodata = false;
    }
    const int W = ds->GetRasterXSize(), H = ds->GetRasterYSize();
    double cell = options.cell;
    if (cell <= 0.0) {
        if (info.cell_metres <= 0.0)
            throw BadInput(path.string() + " has no georeference to take a cell size from; give cell=METRES");
        cell = info.cell_metres;
    }

    // The band at its own resolution (the caller checked its size against the memory budget).
    std::vector<float> src(std::size_t(W) * std::size_t(H));
    {
        QuietErrors quiet;
        GDALRasterBand* band = ds->GetRasterBand(band_index);
        if (band->RasterIO(GF_Read, 0, 0, W, H, src.data(), W, H, GDT_Float32, 0, 0, nullptr) != CE_None)
            throw BadInput("GDAL could not read " + path.string() + " (" + last_error() +
                           "); the file may be truncated");
    }
    std::vector<std::uint8_t> valid(src.size(), 1);
    std::size_t holes = 0;
    std::size_t first_hole = 0;
    for (std::size_t i = 0; i < src.size(); ++i) {
        const bool hole = !std::isfinite(src[i]) || (has_nodata && src[i] == nodata);
        if (hole) {
            if (holes == 0) first_hole = i;
            valid[i] = 0;
            ++holes;
        }
    }
    ReadResult result;
    std::vector<float> hole_layer;  // Holes::mask: 1 where the raster had no data
    if (holes == src.size()) throw BadInput(path.string() + " holds no data: every sample is nodata");
    if (holes > 0) {
        if (options.holes == Holes::refuse)
            throw BadInput(path.string() + " has " + std::to_string(holes) + " nodata samples (the first at column " +
                           std::to_string(first_hole % W) + ", row " + std::to_string(first_hole / W) +
                           "); use holes=fill to fill them from their surroundings" +
                           (info.warp ? std::string(" (the warp to square cells leaves the corners outside the "
                                                    "raster without data)")
                                      : std::string()));
        if (options.holes == Holes::mask) {
            if (options.size && (options.size->first != W || options.size->second != H))
                throw BadInput("holes=mask marks the raster's own samples; read " + path.string() +
                               " at its own size (resample=none)");
            hole_layer.resize(valid.size());
            for (std::size_t i = 0; i < valid.size(); ++i) hole_layer[i] = valid[i] ? 0.0f : 1.0f;
        }
        result.holes_filled = fill_holes(src, valid, W, H);
    }

    const int w = options.size ? options.size->first : W;
    const int h = options.size ? options.size->second : H;
    // First and last vertices stay on the raster's first and last sample centres.
    const double sx = w > 1 ? double(W - 1) / double(w - 1) : 0.0;
    const double sy = h > 1 ? double(H - 1) / double(h - 1) : 0.0;
    const double out_cell = options.cell > 0.0 ? options.cell : cell * (w > 1 ? sx : 1.0);
    auto terrain = std::make_shared<Heightmap>(w, h, out_cell);
    float* out = terrain->heights().data();
    if (w == W && h == H) {
        std::copy(src.begin(), src.end(), out);
    } else {
        auto at = [&](int x, int y) {
            x = std::clamp(x, 0, W - 1);
            y = std::clamp(y, 0, H - 1);
            return double(src[std::size_t(y) * W + x]);
        };
        parallel_for(0, h, 1, [&](std::int64_t y0, std::int64_t y1) {
            for (std::int64_t y = y0; y < y1; ++y) {
                const double fy = double(y) * sy;
                const int iy = std::min(int(fy), H - 1);
                const double ty = fy - iy;
                for (int x = 0; x < w; ++x) {
                    const double fx = double(x) * sx;
                    const int ix = std::min(int(fx), W - 1);
                    const double tx = fx - ix;
                    double v;
                    switch (options.resample) {
                        case Resample::nearest: v = at(int(std::lround(fx)), int(std::lround(fy))); break;
                        case Resample::bilinear:
                            v = (at(ix, iy) * (1 - tx) + at(ix + 1, iy) * tx) * (1 - ty) +
                                (at(ix, iy + 1) * (1 - tx) + at(ix + 1, iy + 1) * tx) * ty;
                            break;
                        case Resample::cubic:
                        default: {
                            double wx[4], wy[4];
                            cubic_weights(tx, wx);
                            cubic_weights(ty, wy);
                            v = 0.0;
                            for (int j = 0; j < 4; ++j) {
                                double row = 0.0;
                                for (int i = 0; i < 4; ++i) row += wx[i] * at(ix - 1 + i, iy - 1 + j);
                                v += wy[j] * row;
                            }
                        }
                    }
                    out[std::size_t(y) * w + x] = float(v);
                }
            }
        });
    }
    if (!hole_layer.empty()) terrain->set_layer("nodata", std::move(hole_layer));
    result.terrain = std::move(terrain);
    result.info = std::move(info);
    return result;
}

}  // namespace orogen::geotiff
