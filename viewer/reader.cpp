// reader.cpp — orogen's files into grids and frames (see reader.hpp).
#include "reader.hpp"

#include <orogen/error.hpp>
#include <orogen/formats/raw.hpp>
#include <orogen/io.hpp>

#include <gdal_priv.h>
#include <nlohmann/json.hpp>
#include <vtkCallbackCommand.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkFieldData.h>
#include <vtkStringArray.h>
#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLDataParser.h>
#include <vtkXMLImageDataReader.h>
#include <vtkXMLPolyDataReader.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <memory>

namespace fs = std::filesystem;

namespace orogen::view {

const char* const known_extensions =
    ".vti, .vtp, .pvd, .glb, .gltf, .png (16-bit heightmap), .r16, .r32 (with their .json sidecar), .tif/.tiff "
    "(GeoTIFF), .vrt and the .json index of export:tiles, and .orogen specs";

const float* Terrain::layer(const std::string& name) const {
    for (const auto& l : layers)
        if (l.name == name) return l.values->GetPointer(0);
    return nullptr;
}

namespace {

std::string quoted(const fs::path& p) { return "'" + p.string() + "'"; }

/// Notices the errors a VTK reader raises (its error code stays 0 for many of them).
struct ErrorFlag {
    bool raised = false;
    vtkNew<vtkCallbackCommand> command;
    explicit ErrorFlag(vtkObject* watched) {
        command->SetClientData(this);
        command->SetCallback(
            [](vtkObject*, unsigned long, void* self, void*) { static_cast<ErrorFlag*>(self)->raised = true; });
        watched->AddObserver(vtkCommand::ErrorEvent, command);
    }
};

/// A readable regular file, or one clear error saying which it is not.
void check_readable(const fs::path& file) {
    std::error_code ec;
    const auto status = fs::status(file, ec);
    if (!fs::exists(status)) throw BadInput("cannot open " + quoted(file) + ": no such file");
    if (fs::is_directory(status))
        throw BadInput("cannot open " + quoted(file) + ": it is a folder; give a file inside it");
    std::ifstream probe(file, std::ios::binary);
    char byte;
    if (!probe || (!probe.read(&byte, 1) && fs::file_size(file, ec) != 0))
        throw BadInput("cannot read " + quoted(file) + ": permission denied or unreadable (check its permissions)");
}

std::string extension(const fs::path& file) {
    std::string e = file.extension().string();
    std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return e;
}

vtkSmartPointer<vtkFloatArray> float_array(vtkDataArray* a, const std::string& name) {
    auto f = vtkSmartPointer<vtkFloatArray>::New();
    if (auto* same = vtkFloatArray::SafeDownCast(a)) {
        f = same;  // no copy: the reader's own array
    } else {
        f->DeepCopy(a);
    }
    f->SetName(name.c_str());
    return f;
}

/// True if export:vtk wrote `data` with Z up (field data "orogen_up" = "z");
/// files without the mark (written before up=z existed) are Y-up.
bool z_up(vtkDataObject* data) {
    auto* mark = vtkStringArray::SafeDownCast(data->GetFieldData()->GetAbstractArray("orogen_up"));
    return mark && mark->GetNumberOfValues() == 1 && mark->GetValue(0) == "z";
}

/// A z-up file's points and 3-component arrays back into the viewer's frame
/// (X east, Y up, Z south): (x, y, z) → (x, z, −y), the inverse of export:vtk's turn.
void turn_to_y_up(vtkPolyData* poly) {
    auto back = [](double* p) {
        const double y = p[1];
        p[1] = p[2];
        p[2] = -y + 0.0;
    };
    if (vtkPoints* points = poly->GetPoints())
        for (vtkIdType i = 0; i < points->GetNumberOfPoints(); ++i) {
            double p[3];
            points->GetPoint(i, p);
            back(p);
            points->SetPoint(i, p);
        }
    for (vtkFieldData* fd :
         {static_cast<vtkFieldData*>(poly->GetPointData()), static_cast<vtkFieldData*>(poly->GetCellData())})
        for (int a = 0; a < fd->GetNumberOfArrays(); ++a) {
            vtkDataArray* arr = fd->GetArray(a);
            if (!arr || arr->GetNumberOfComponents() != 3) continue;
            for (vtkIdType i = 0; i < arr->GetNumberOfTuples(); ++i) {
                double v[3];
                arr->GetTuple(i, v);
                back(v);
                arr->SetTuple(i, v);
            }
        }
    poly->Modified();
}

/// A z-up image's array (south row first) as the viewer's grid (north row first).
vtkSmartPointer<vtkFloatArray> north_first(vtkDataArray* a, const std::string& name, int width, int height) {
    auto f = vtkSmartPointer<vtkFloatArray>::New();
    f->SetName(name.c_str());
    f->SetNumberOfTuples(vtkIdType(width) * height);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            f->SetValue(vtkIdType(y) * width + x, float(a->GetTuple1(vtkIdType(height - 1 - y) * width + x)));
    return f;
}

/// Every 1-component point array except `height` and normals, as layers.
void take_layers(vtkPointData* pd, vtkIdType count, Terrain& t) {
    for (int i = 0; i < pd->GetNumberOfArrays(); ++i) {
        vtkDataArray* a = pd->GetArray(i);
        if (!a || !a->GetName() || a->GetNumberOfComponents() != 1 || a->GetNumberOfTuples() != count) continue;
        const std::string name = a->GetName();
        if (name == "height" || name == "Normals") continue;
        t.layers.push_back({name, float_array(a, name)});
    }
}

/// VTK's XML readers read a truncated raw appended block without a word:
/// check that every array's bytes are in the file (uncompressed files; a
/// compressed one fails in VTK's decompressor, which raises an error).
void check_appended_data(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    std::string head(1 << 16, '\0');
    in.read(head.data(), std::streamsize(head.size()));
    head.resize(std::size_t(in.gcount()));
    const auto appended = head.find("<AppendedData encoding=\"raw\"");
    if (appended == std::string::npos || head.find("compressor=") != std::string::npos) return;
    const auto start = head.find('_', appended);
    if (start == std::string::npos)
        throw BadInput("cannot read " + quoted(file) + ": the file is damaged (truncated?)");
    const bool wide = head.find("header_type=\"UInt64\"") != std::string::npos;
    std::error_code ec;
    const std::uintmax_t size = fs::file_size(file, ec);
    for (std::size_t at = head.find("offset=\""); at < appended; at = head.find("offset=\"", at + 1)) {
        const std::uint64_t offset = std::stoull(head.substr(at + 8, 24));
        const std::uint64_t begin = start + 1 + offset;
        std::uint64_t bytes = 0;
        in.clear();
        in.seekg(std::streamoff(begin));
        in.read(reinterpret_cast<char*>(&bytes), wide ? 8 : 4);  // little-endian, as the host
        if (!in || begin + (wide ? 8 : 4) + bytes > size)
            throw BadInput("cannot read " + quoted(file) + ": the file is damaged (truncated?)");
    }
}

Terrain read_vti(const fs::path& file) {
    check_appended_data(file);
    vtkNew<vtkXMLImageDataReader> reader;
    if (!reader->CanReadFile(file.c_str()))
        throw BadInput("cannot read " + quoted(file) + ": not a VTK image data (.vti) file, or truncated");
    reader->SetFileName(file.c_str());
    ErrorFlag error(reader);
    reader->Update();
    vtkImageData* image = reader->GetOutput();
    int dims[3] = {0, 0, 0};
    if (image) image->GetDimensions(dims);
    vtkDataArray* h = image ? image->GetPointData()->GetArray("height") : nullptr;
    if (error.raised || reader->GetErrorCode() != 0)
        throw BadInput("cannot read " + quoted(file) + ": the file is damaged (truncated?)");
    if (!h)
        throw BadInput("cannot read " + quoted(file) +
                       ": it has no 'height' point array; is it an export:vtk heightmap?");
    // export:vtk's layouts: up=z width × height × 1 (XY plane), up=y width × 1 × height (XZ plane).
    const bool z = dims[2] == 1 && dims[1] > 1;
    if (dims[0] < 2 || (z ? dims[1] < 2 : (dims[1] != 1 || dims[2] < 2)))
        throw BadInput("cannot show " + quoted(file) +
                       ": expected width × height × 1 or width × 1 × height points (export:vtk's layouts), got " +
                       std::to_string(dims[0]) + " × " + std::to_string(dims[1]) + " × " + std::to_string(dims[2]));
    Terrain t;
    t.file = file;
    t.width = dims[0];
    t.height = z ? dims[1] : dims[2];
    t.cell = image->GetSpacing()[0];
    const vtkIdType n = vtkIdType(t.width) * t.height;
    if (h->GetNumberOfTuples() != n || h->GetNumberOfComponents() != 1)
        throw BadInput("cannot read " + quoted(file) + ": its 'height' array does not hold one value per point");
    if (!z) {
        t.heights = float_array(h, "height");
        take_layers(image->GetPointData(), n, t);
        return t;
    }
    t.heights = north_first(h, "height", t.width, t.height);
    Terrain stored;  // the layers as stored, then turned north first
    take_layers(image->GetPointData(), n, stored);
    for (auto& l : stored.layers) t.layers.push_back({l.name, north_first(l.values, l.name, t.width, t.height)});
    return t;
}

vtkSmartPointer<vtkPolyData> read_polydata(const fs::path& file) {
    check_appended_data(file);
    vtkNew<vtkXMLPolyDataReader> reader;
    if (!reader->CanReadFile(file.c_str()))
        throw BadInput("cannot read " + quoted(file) + ": not a VTK polygonal data (.vtp) file, or truncated");
    reader->SetFileName(file.c_str());
    ErrorFlag error(reader);
    reader->Update();
    if (error.raised || reader->GetErrorCode() != 0 || !reader->GetOutput())
        throw BadInput("cannot read " + quoted(file) + ": the file is damaged (truncated?)");
    vtkSmartPointer<vtkPolyData> poly = reader->GetOutput();
    return poly;
}

/// export:vtk's .vtp mesh is its grid's kept rows of kept columns, row-major:
/// the grid is recovered from the points (width = points sharing the first
/// row coordinate: Z south when Y is up, Y north when Z is up).
Terrain terrain_from_mesh(const fs::path& file, vtkPolyData* poly) {
    const vtkIdType n = poly->GetNumberOfPoints();
    vtkIdType width = 1;
    const int row_axis = z_up(poly) ? 1 : 2;
    const double r0 = poly->GetPoint(0)[row_axis];
    while (width < n && poly->GetPoint(width)[row_axis] == r0) ++width;
    if (width < 2 || n % width != 0 || n / width < 2)
        throw BadInput("cannot show " + quoted(file) +
                       ": its points are not a grid of rows (export:vtk's .vtp mesh is)");
    Terrain t;
    t.file = file;
    t.width = int(width);
    t.height = int(n / width);
    t.cell = poly->GetPoint(1)[0] - poly->GetPoint(0)[0];
    t.heights = float_array(poly->GetPointData()->GetArray("height"), "height");
    take_layers(poly->GetPointData(), n, t);
    return t;
}

Terrain read_png(const fs::path& file) {
    const GrayImage image = read_gray_png(file);  // BadInput names the file for colour, palette, truncated
    if (image.width < 2 || image.height < 2)
        throw BadInput("cannot show " + quoted(file) + ": a heightmap needs at least 2 × 2 pixels");
    Terrain t;
    t.file = file;
    t.width = image.width;
    t.height = image.height;
    // A PNG has no units: 1 m per pixel, the full grey range spanning a
    // quarter of the width, so a heightmap looks like a landscape.
    t.cell = 1.0;
    const double top = (image.bits == 16 ? 65535.0 : 255.0), relief = 0.25 * (std::max(t.width, t.height) - 1);
    t.heights = vtkSmartPointer<vtkFloatArray>::New();
    t.heights->SetName("height");
    t.heights->SetNumberOfTuples(vtkIdType(image.samples.size()));
    for (std::size_t i = 0; i < image.samples.size(); ++i)
        t.heights->SetValue(vtkIdType(i), float(image.samples[i] / top * relief));
    return t;
}

/// RAW heightmaps through libs/formats, the same reader as import:raw: the sidecar checked field by field
/// and the file's size against it before anything is allocated.
Terrain read_raw(const fs::path& file) {
    const fs::path sidecar = file.string() + ".json";
    if (!fs::exists(sidecar))
        throw BadInput("cannot show " + quoted(file) + ": its sidecar " + quoted(sidecar.filename()) +
                       " is missing (a RAW file has no size or height range; export:raw writes both files: copy the "
                       ".json along)");
    formats::raw::Sidecar info;
    const std::vector<float> heights = formats::raw::read_raw(file, info);
    Terrain t;
    t.file = file;
    t.width = info.width;
    t.height = info.height;
    t.cell = info.cell;
    t.heights = vtkSmartPointer<vtkFloatArray>::New();
    t.heights->SetName("height");
    t.heights->SetNumberOfTuples(vtkIdType(heights.size()));
    std::copy(heights.begin(), heights.end(), t.heights->GetPointer(0));
    return t;
}

/// A raster GDAL reads (export:geotiff's GeoTIFF, export:tiles' VRT): band 1 the height in metres (its
/// scale and offset applied: a VRT of 16-bit tiles carries them), every further band a layer named by its
/// description (export:geotiff names them). The cell is the pixel size when the raster is in metres, else 1 m.
Terrain read_gdal(const fs::path& file) {
    GDALAllRegister();
    CPLPushErrorHandler(CPLQuietErrorHandler);  // GDAL's own messages never reach the user: ours do
    std::unique_ptr<GDALDataset> ds(GDALDataset::Open(file.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY));
    const std::string gdal_says = CPLGetLastErrorMsg();
    CPLPopErrorHandler();
    if (!ds)
        throw BadInput("cannot read " + quoted(file) + ": GDAL cannot open it as a raster" +
                       (gdal_says.empty() ? std::string() : " (" + gdal_says + ")"));
    const int w = ds->GetRasterXSize(), h = ds->GetRasterYSize(), bands = ds->GetRasterCount();
    if (bands < 1 || w < 2 || h < 2)
        throw BadInput("cannot show " + quoted(file) + ": a heightmap needs a band of at least 2 × 2 samples");
    if (const std::string problem = heightmap_memory_problem(double(w) * bands, h); !problem.empty())
        throw BadInput("cannot show " + quoted(file) + ": " + std::to_string(w) + " × " + std::to_string(h) + " × " +
                       std::to_string(bands) + " bands " + problem);
    double gt[6] = {0, 1, 0, 0, 0, -1};
    const bool georeferenced = ds->GetGeoTransform(gt) == CE_None;
    const OGRSpatialReference* srs = ds->GetSpatialRef();
    const bool metres =
        !srs || ((srs->IsProjected() || srs->IsLocal()) && std::fabs(srs->GetLinearUnits() - 1.0) < 1e-9);
    Terrain t;
    t.file = file;
    t.width = w;
    t.height = h;
    t.cell = georeferenced && metres && std::fabs(gt[1]) > 0 ? std::fabs(gt[1]) : 1.0;
    const bool south_up = georeferenced && gt[5] > 0;  // rows run south to north: turn them north to south
    auto read_band = [&](int index, const std::string& name) {
        GDALRasterBand* band = ds->GetRasterBand(index);
        auto values = vtkSmartPointer<vtkFloatArray>::New();
        values->SetName(name.c_str());
        values->SetNumberOfTuples(vtkIdType(w) * h);
        float* v = values->GetPointer(0);
        if (band->RasterIO(GF_Read, 0, 0, w, h, v, w, h, GDT_Float32, 0, 0, nullptr) != CE_None)
            throw BadInput("cannot read " + quoted(file) + ": band " + std::to_string(index) +
                           " is damaged or a file it refers to is missing (" + CPLGetLastErrorMsg() + ")");
        int has = 0;
        const double scale = band->GetScale(&has), offset = band->GetOffset();
        const double nodata = band->GetNoDataValue(&has);
        const bool holes = has != 0;
        float lowest = std::numeric_limits<float>::max();
        for (std::size_t i = 0; i < std::size_t(w) * h; ++i) {
            if (holes && v[i] == float(nodata)) {
                v[i] = std::numeric_limits<float>::quiet_NaN();
                continue;
            }
            v[i] = float(v[i] * (scale != 0 ? scale : 1.0) + offset);
            lowest = std::min(lowest, v[i]);
        }
        for (std::size_t i = 0; i < std::size_t(w) * h; ++i)  // holes (nodata) shown at the lowest height
            if (std::isnan(v[i])) v[i] = lowest == std::numeric_limits<float>::max() ? 0.f : lowest;
        if (south_up)
            for (int y = 0; y < h / 2; ++y)
                std::swap_ranges(v + std::size_t(y) * w, v + std::size_t(y + 1) * w, v + std::size_t(h - 1 - y) * w);
        return values;
    };
    t.heights = read_band(1, "height");
    for (int b = 2; b <= bands; ++b) {
        const char* description = ds->GetRasterBand(b)->GetDescription();
        const std::string name = description && *description ? description : "band " + std::to_string(b);
        t.layers.push_back({name, read_band(b, name)});
    }
    return t;
}

/// The .json index export:tiles writes: the tiles shown as one terrain through the VRT beside it.
Terrain read_tiles_index(const fs::path& file, const nlohmann::json& index) {
    const std::string format = index.value("format", "");
    if (format == "glb")
        throw BadInput("cannot show " + quoted(file) +
                       ": it indexes glTF chunks (a 3D Tiles tileset, for CesiumJS and "
                       "other streamers); open one chunk (.glb) or write raster tiles (format=png16, r16, r32)");
    fs::path vrt = file;
    vrt.replace_extension(".vrt");
    if (!fs::exists(vrt))
        throw BadInput(
            "cannot show " + quoted(file) + ": the tiles are shown through " + quoted(vrt.filename()) +
            ", the GDAL mosaic export:tiles writes beside the index (vrt=true, the default), which is missing");
    Terrain t = read_gdal(vrt);
    t.file = file;
    return t;
}

/// Which part of a frame a .vtp fills, by what it holds (turned into the viewer's frame).
void place(Frame& frame, vtkSmartPointer<vtkPolyData> poly) {
    if (z_up(poly)) turn_to_y_up(poly);
    if (poly->GetNumberOfPolys() > 0 || poly->GetCellData()->GetArray("plate")) frame.plates = poly;
    else if (poly->GetNumberOfLines() > 0 || poly->GetCellData()->GetArray("plate_a")) frame.collisions = poly;
    else frame.particles = poly;
}

Series read_pvd(const fs::path& file) {
    vtkNew<vtkXMLDataParser> parser;
    parser->SetFileName(file.c_str());
    vtkXMLDataElement* root = parser->Parse() ? parser->GetRootElement() : nullptr;
    vtkXMLDataElement* collection = root ? root->FindNestedElementWithName("Collection") : nullptr;
    if (!collection)
        throw BadInput("cannot read " + quoted(file) + ": not a ParaView collection (.pvd): no <Collection> element");
    struct Entry {
        double time;
        fs::path file;
    };
    std::vector<Entry> entries;
    std::vector<fs::path> missing;
    for (int i = 0; i < collection->GetNumberOfNestedElements(); ++i) {
        vtkXMLDataElement* e = collection->GetNestedElement(i);
        if (std::strcmp(e->GetName(), "DataSet") != 0 || !e->GetAttribute("file")) continue;
        double time = 0.0;
        e->GetScalarAttribute("timestep", time);
        const fs::path frame = file.parent_path() / e->GetAttribute("file");
        if (!fs::exists(frame)) missing.push_back(frame);
        entries.push_back({time, frame});
    }
    if (!missing.empty())
        throw BadInput(quoted(file) + " lists " + std::to_string(missing.size()) + " of its " +
                       std::to_string(entries.size()) + " frame files that are missing, the first " +
                       quoted(missing.front()) + "; copy the series' .vtp files along with the .pvd");
    if (entries.empty()) throw BadInput(quoted(file) + " lists no frames");
    std::map<double, Frame> frames;
    for (const auto& e : entries) {
        Frame& f = frames[e.time];
        f.time = e.time;
        place(f, read_polydata(e.file));
    }
    Series s;
    s.file = file;
    for (auto& [time, f] : frames) s.frames.push_back(std::move(f));
    return s;
}

}  // namespace

Content read_files(std::span<const fs::path> files) {
    Content c;
    for (const fs::path& file : files) {
        std::error_code ec;
        if (fs::is_directory(file, ec)) {  // an output folder: what a spec run there would show
            const auto inside = pick_outputs(file);
            if (inside.empty())
                throw BadInput("cannot open " + quoted(file) + ": the folder holds nothing orogen-view shows (" +
                               known_extensions + ")");
            Content more = read_files(inside);
            for (auto& t : more.terrains) c.terrains.push_back(std::move(t));
            for (auto& s : more.series) c.series.push_back(std::move(s));
            for (auto& g : more.gltf) c.gltf.push_back(std::move(g));
            continue;
        }
        const std::string ext = extension(file);
        const bool known = ext == ".vti" || ext == ".vtp" || ext == ".pvd" || ext == ".glb" || ext == ".gltf" ||
            ext == ".png" || ext == ".r16" || ext == ".r32" || ext == ".tif" || ext == ".tiff" || ext == ".vrt" ||
            ext == ".json";
        if (!known)
            throw BadInput("cannot open " + quoted(file) + ": unknown file type '" + ext + "'; orogen-view opens " +
                           known_extensions);
        check_readable(file);
        if (ext == ".vti") {
            c.terrains.push_back(read_vti(file));
        } else if (ext == ".vtp") {
            auto poly = read_polydata(file);
            if (poly->GetNumberOfPolys() > 0 && poly->GetPointData()->GetArray("height")) {
                c.terrains.push_back(terrain_from_mesh(file, poly));
            } else {
                Series s;
                s.file = file;
                s.frames.emplace_back();
                place(s.frames.back(), poly);
                c.series.push_back(std::move(s));
            }
        } else if (ext == ".pvd") {
            c.series.push_back(read_pvd(file));
        } else if (ext == ".glb" || ext == ".gltf") {
            c.gltf.push_back(file);
        } else if (ext == ".png") {
            c.terrains.push_back(read_png(file));
        } else if (ext == ".tif" || ext == ".tiff" || ext == ".vrt") {
            c.terrains.push_back(read_gdal(file));
        } else if (ext == ".json") {
            nlohmann::json index;
            try {
                std::ifstream in(file);
                index = nlohmann::json::parse(in);
            } catch (const std::exception&) { throw BadInput("cannot read " + quoted(file) + ": not valid JSON"); }
            if (!index.is_object() || !index.contains("tile_size"))
                throw BadInput("cannot show " + quoted(file) +
                               ": orogen-view opens the .json index of export:tiles; "
                               "for a RAW file's sidecar open the .r16 or .r32 beside it");
            c.terrains.push_back(read_tiles_index(file, index));
        } else {
            c.terrains.push_back(read_raw(file));
        }
    }
    return c;
}

std::vector<fs::path> pick_outputs(const fs::path& folder) {
    std::vector<fs::path> all;
    std::error_code ec;
    for (auto it = fs::recursive_directory_iterator(folder, ec); !ec && it != fs::recursive_directory_iterator();
         it.increment(ec))
        if (it->is_regular_file() && it->path().filename().string()[0] != '.') all.push_back(it->path());
    std::sort(all.begin(), all.end());
    std::vector<fs::path> picked;
    auto first = [&](auto&& accept) {
        for (const auto& p : all)
            if (accept(p)) {
                picked.push_back(p);
                return true;
            }
        return false;
    };
    auto ext_is = [](const char* e) { return [e](const fs::path& p) { return extension(p) == e; }; };
    auto gray16 = [](const fs::path& p) {
        if (extension(p) != ".png") return false;
        try {
            return read_gray_png_header(p).bits == 16;
        } catch (const std::exception&) {
            return false;  // colour pictures (relief, flow) are not heightmaps
        }
    };
    auto terrain_vtp = [](const fs::path& p) {
        if (extension(p) != ".vtp") return false;
        try {
            auto poly = read_polydata(p);
            return poly->GetNumberOfPolys() > 0 && poly->GetPointData()->GetArray("height") != nullptr;
        } catch (const std::exception&) { return false; }
    };
    first(ext_is(".vti")) || first(terrain_vtp) || first(ext_is(".r16")) || first(ext_is(".r32")) || first(gray16) ||
        first(ext_is(".tif")) || first(ext_is(".tiff")) || first(ext_is(".vrt")) || first(ext_is(".glb")) ||
        first(ext_is(".gltf"));
    for (const auto& p : all)
        if (extension(p) == ".pvd") picked.push_back(p);
    return picked;
}

}  // namespace orogen::view
