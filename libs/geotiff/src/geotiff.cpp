#include <orogen/geotiff/geotiff.hpp>

#include <orogen/error.hpp>
#include <orogen/parallel.hpp>

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_string.h>
#include <gdal_priv.h>
#include <ogr_spatialref.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
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
    if (const OGRSpatialReference* srs = ds.GetSpatialRef()) {
        info.crs_wkt = to_wkt(*srs);
        info.geographic = srs->IsGeographic();
    }
    info.has_geotransform = ds.GetGeoTransform(info.geotransform) == CE_None;
    int has_nodata = 0;
    const double nodata = ds.GetRasterBand(band_index)->GetNoDataValue(&has_nodata);
    if (has_nodata) info.nodata = nodata;
    if (info.has_geotransform) {
        const double* g = info.geotransform;
        double px = std::abs(g[1]), py = std::abs(g[5]);
        if (info.geographic) {
            const double mid_lat = g[3] + g[5] * 0.5 * info.height;
            const auto [lon, lat] = metres_per_degree(mid_lat);
            px *= lon;
            py *= lat;
        }
        info.cell_metres = 0.5 * (px + py);
    }
    return info;
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

RasterInfo probe(const fs::path& path, int band) {
    Dataset ds = open_raster(path);
    return describe(*ds, path, band);
}

ReadResult read(const fs::path& path, const ReadOptions& options) {
    Dataset ds = open_raster(path);
    const RasterInfo info = describe(*ds, path, options.band);
    const int W = info.width, H = info.height;
    if (info.has_geotransform && (info.geotransform[2] != 0.0 || info.geotransform[4] != 0.0))
        throw BadInput(path.string() +
                       " is rotated (its geotransform has shear terms); warp it north-up first, e.g. "
                       "gdalwarp " +
                       path.filename().string() + " north-up.tif");
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
        GDALRasterBand* band = ds->GetRasterBand(options.band);
        if (band->RasterIO(GF_Read, 0, 0, W, H, src.data(), W, H, GDT_Float32, 0, 0, nullptr) != CE_None)
            throw BadInput("GDAL could not read " + path.string() + " (" + last_error() +
                           "); the file may be truncated");
    }
    std::vector<std::uint8_t> valid(src.size(), 1);
    std::size_t holes = 0;
    std::size_t first_hole = 0;
    for (std::size_t i = 0; i < src.size(); ++i) {
        const bool hole = !std::isfinite(src[i]) || (info.nodata && src[i] == float(*info.nodata));
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
                           "); use holes=fill to fill them from their surroundings");
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
    return result;
}

}  // namespace orogen::geotiff
