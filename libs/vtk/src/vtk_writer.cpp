// The only translation unit of export:vtk that includes VTK.
#include <orogen/vtk/vtk_writer.hpp>

#include <orogen/mesh/terrain_mesh.hpp>

#include <orogen/error.hpp>
#include <orogen/io.hpp>

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkErrorCode.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkFieldData.h>
#include <vtkStringArray.h>
#include <vtkSmartPointer.h>
#include <vtkTypeInt32Array.h>
#include <vtkTypeInt64Array.h>
#include <vtkXMLImageDataWriter.h>
#include <vtkXMLPolyDataWriter.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <iomanip>
#include <limits>
#include <memory>
#include <numeric>
#include <sstream>

namespace fs = std::filesystem;

namespace orogen::vtk {

namespace {

/// VTK prints its own error blocks to stderr; ours (an orogen::Error) says it
/// better, so warnings are muted while a writer runs.
class QuietVtk {
public:
    QuietVtk() : was_(vtkObject::GetGlobalWarningDisplay()) { vtkObject::GlobalWarningDisplayOff(); }
    ~QuietVtk() { vtkObject::SetGlobalWarningDisplay(was_); }

private:
    int was_;
};

/// A float array over memory VTK must not free (the heightmap's own samples: no copy).
vtkSmartPointer<vtkFloatArray> wrap(const std::string& name, const float* data, std::size_t tuples, int components) {
    auto a = vtkSmartPointer<vtkFloatArray>::New();
    a->SetName(name.c_str());
    a->SetNumberOfComponents(components);
    a->SetArray(const_cast<float*>(data), vtkIdType(tuples) * components, 1);  // 1: VTK does not own it; read only
    return a;
}

template <typename Writer>
void write_with(vtkDataObject* data, AtomicFile& file, const Options& o) {
    vtkNew<Writer> w;
    w->SetInputData(data);
    w->SetFileName(file.temporary().c_str());
    w->SetDataModeToAppended();
    w->EncodeAppendedDataOff();  // raw binary, not base64
    w->SetHeaderTypeToUInt64();  // arrays over 4 GiB
    if (o.compress) w->SetCompressorTypeToZLib();
    else w->SetCompressorTypeToNone();
    file.stream().close();  // VTK writes the temporary file by name
    QuietVtk quiet;
    const int ok = w->Write();
    const unsigned long code = w->GetErrorCode();
    if (ok != 1 || code != 0)
        throw Error("cannot write " + file.target().string() + ": VTK's writer failed (" +
                    (code == vtkErrorCode::OutOfDiskSpaceError       ? std::string("out of disk space")
                         : code == vtkErrorCode::CannotOpenFileError ? std::string("cannot open the file")
                         : code != 0                                 ? "VTK error code " + std::to_string(code)
                                                                     : std::string("unknown error")) +
                    "; disk full or folder not writable?); the existing file, if any, is unchanged");
}

std::string number(double v) {
    std::ostringstream s;
    s << std::setprecision(std::numeric_limits<double>::max_digits10) << v;
    return s.str();
}

std::string frame_name(const fs::path& target, const std::string& what, std::size_t i) {
    char digits[32];
    std::snprintf(digits, sizeof digits, "%06zu", i);
    return target.stem().string() + what + "_" + digits + ".vtp";
}

void commit_series(std::vector<std::unique_ptr<AtomicFile>>& files) {
    std::vector<AtomicFile*> list;
    for (auto& f : files) list.push_back(f.get());
    commit_all(list);
}

/// Orogen's frame (x east, y up, z south) in the file's frame; `+ 0.0` keeps
/// −0 out of the files (a flat row at 0 m shows as 0, not −0, in ParaView).
std::array<double, 3> turned(double x, double y, double z, Up up) {
    if (up == Up::y) return {x, y, z};
    return {x, -z + 0.0, y};
}

/// Turns `count` xyz triples in place from orogen's frame into the file's.
void turn_in_place(float* xyz, std::size_t count, Up up) {
    if (up == Up::y) return;
    for (std::size_t i = 0; i < count; ++i) {
        float* p = xyz + 3 * i;
        const float y = p[1];
        p[1] = -p[2] + 0.0f;
        p[2] = y;
    }
}

/// Records the frame in the file (field data "orogen_up"), for orogen-view and for people.
void mark_frame(vtkDataObject* data, Up up) {
    vtkNew<vtkStringArray> a;
    a->SetName("orogen_up");
    a->InsertNextValue(up == Up::z ? "z" : "y");
    data->GetFieldData()->AddArray(a);
}

/// The grid with its rows in reverse order (z-up image data stores the south row first).
vtkSmartPointer<vtkFloatArray> flipped(const std::string& name, ConstGridView g) {
    auto a = vtkSmartPointer<vtkFloatArray>::New();
    a->SetName(name.c_str());
    a->SetNumberOfTuples(vtkIdType(g.size()));
    float* out = a->GetPointer(0);
    const std::size_t w = std::size_t(g.width);
    for (int y = 0; y < g.height; ++y)
        std::copy_n(g.data + std::size_t(g.height - 1 - y) * w, w, out + std::size_t(y) * w);
    return a;
}

void check_layers(ConstGridView heights, std::span<const NamedGrid> layers) {
    for (const auto& l : layers)
        if (l.grid.width != heights.width || l.grid.height != heights.height)
            throw Error("internal error: layer '" + l.name + "' is " + std::to_string(l.grid.width) + " x " +
                        std::to_string(l.grid.height) + ", the heightmap " + std::to_string(heights.width) + " x " +
                        std::to_string(heights.height));
}

}  // namespace

Up up_from_name(const std::string& name) {
    if (name == "z") return Up::z;
    if (name == "y") return Up::y;
    throw BadInput("up must be z (ParaView, GIS) or y (glTF), not '" + name + "'");
}

std::string pvd_text(std::span<const PvdEntry> entries) {
    std::ostringstream s;
    s << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "  <Collection>\n";
    for (const auto& e : entries)
        s << "    <DataSet timestep=\"" << number(e.time) << "\" group=\"\" part=\"" << e.part << "\" file=\"" << e.file
          << "\"/>\n";
    s << "  </Collection>\n"
      << "</VTKFile>\n";
    return s.str();
}

// ---------------------------------------------------------------- heightmap

void write_heightmap_piece(ConstGridView piece, std::span<const NamedGrid> layers, int x0, int y0, int whole_height,
                           const fs::path& target, const Options& o) {
    check_layers(piece, layers);
    AtomicFile file(target);
    vtkNew<vtkImageData> image;
    if (o.up == Up::z) {
        // X east, Y north, as export:vtk's up=z .vti: j counts rows from the south, so the piece's rows are
        // turned (a copy) and its extent counted from the whole grid's south edge.
        const int j0 = whole_height - y0 - piece.height;
        image->SetExtent(x0, x0 + piece.width - 1, j0, j0 + piece.height - 1, 0, 0);
        image->SetSpacing(piece.cell, piece.cell, 1.0);
        image->SetOrigin(0, -(whole_height - 1) * piece.cell + 0.0, 0);
        image->GetPointData()->AddArray(flipped("height", piece));
        for (const auto& l : layers) image->GetPointData()->AddArray(flipped(l.name, l.grid));
    } else {
        // X east, Z south: sample order as stored; the extent places the piece in the whole grid.
        image->SetExtent(x0, x0 + piece.width - 1, 0, 0, y0, y0 + piece.height - 1);
        image->SetSpacing(piece.cell, 1.0, piece.cell);
        image->SetOrigin(0, 0, 0);
        image->GetPointData()->AddArray(wrap("height", piece.data, piece.size(), 1));
        for (const auto& l : layers) image->GetPointData()->AddArray(wrap(l.name, l.grid.data, l.grid.size(), 1));
    }
    image->GetPointData()->SetActiveScalars("height");
    mark_frame(image, o.up);
    write_with<vtkXMLImageDataWriter>(image, file, o);
    file.commit();
}

std::string pvti_text(int width, int height, double cell, std::span<const std::string> layer_names,
                      std::span<const PvtiPiece> pieces, Up up) {
    std::ostringstream s;
    const bool z = up == Up::z;
    s << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"PImageData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
      << "  <PImageData WholeExtent=\"0 " << width - 1
      << (z ? " 0 " + std::to_string(height - 1) + " 0 0" : " 0 0 0 " + std::to_string(height - 1))
      << "\" GhostLevel=\"0\" Origin=\"0 " << (z ? number(-(height - 1) * cell + 0.0) : std::string("0"))
      << " 0\" Spacing=\"" << number(cell) << (z ? " " + number(cell) + " 1" : " 1 " + number(cell)) << "\">\n"
      << "    <PPointData Scalars=\"height\">\n"
      << "      <PDataArray type=\"Float32\" Name=\"height\"/>\n";
    for (const auto& n : layer_names) s << "      <PDataArray type=\"Float32\" Name=\"" << n << "\"/>\n";
    s << "    </PPointData>\n";
    for (const auto& p : pieces) {
        s << "    <Piece Extent=\"" << p.x0 << " " << p.x1;
        if (z) s << " " << height - 1 - p.y1 << " " << height - 1 - p.y0 << " 0 0";
        else s << " 0 0 " << p.y0 << " " << p.y1;
        s << "\" Source=\"" << p.file << "\"/>\n";
    }
    s << "  </PImageData>\n"
      << "</VTKFile>\n";
    return s.str();
}

void write_heightmap(ConstGridView heights, std::span<const NamedGrid> layers, const fs::path& target,
                     const Options& o) {
    const std::string ext = target.extension().string();
    if (ext != ".vti" && ext != ".vtp")
        throw BadInput("export:vtk writes a heightmap as .vti or .vtp; '" + target.filename().string() +
                       "' has another extension");
    check_layers(heights, layers);
    if (ext == ".vti") {
        if (o.decimate != 1) throw BadInput("decimate applies to .vtp meshes only; .vti keeps every sample");
        // the whole grid is the one piece that starts at (0, 0)
        write_heightmap_piece(heights, layers, 0, 0, heights.height, target, o);
        return;
    }
    AtomicFile file(target);

    const mesh::TerrainMesh mesh = mesh::plan_mesh(heights, o.decimate, 1, o.vertical_scale);
    const mesh::MeshChunk& chunk = mesh.chunks.at(0);
    const std::size_t n = chunk.vertex_count(), triangles = chunk.triangle_count();
    if (triangles * 3 > std::size_t(std::numeric_limits<std::int32_t>::max()))
        throw BadInput("the mesh has " + std::to_string(triangles) +
                       " triangles, too many for one .vtp; use decimate=2");
    vtkNew<vtkFloatArray> xyz;
    xyz->SetNumberOfComponents(3);
    xyz->SetNumberOfTuples(vtkIdType(n));
    mesh::chunk_positions(mesh, chunk, {xyz->GetPointer(0), n * 3});
    turn_in_place(xyz->GetPointer(0), n, o.up);
    vtkNew<vtkPoints> points;
    points->SetData(xyz);
    vtkNew<vtkFloatArray> normals;
    normals->SetName("Normals");
    normals->SetNumberOfComponents(3);
    normals->SetNumberOfTuples(vtkIdType(n));
    mesh::chunk_normals(mesh, chunk, {normals->GetPointer(0), n * 3});
    turn_in_place(normals->GetPointer(0), n, o.up);
    vtkNew<vtkTypeInt32Array> offsets, connectivity;
    offsets->SetNumberOfTuples(vtkIdType(triangles + 1));
    for (std::size_t t = 0; t <= triangles; ++t) offsets->SetValue(vtkIdType(t), std::int32_t(3 * t));
    connectivity->SetNumberOfTuples(vtkIdType(triangles * 3));
    mesh::chunk_indices(chunk, {reinterpret_cast<std::uint32_t*>(connectivity->GetPointer(0)), triangles * 3});
    vtkNew<vtkCellArray> polys;
    polys->SetData(offsets, connectivity);
    vtkNew<vtkPolyData> poly;
    poly->SetPoints(points);
    poly->SetPolys(polys);
    poly->GetPointData()->SetNormals(normals);

    auto add = [&](const std::string& name, ConstGridView g) {
        if (o.decimate == 1) {
            poly->GetPointData()->AddArray(wrap(name, g.data, g.size(), 1));
            return;
        }
        vtkNew<vtkFloatArray> a;
        a->SetName(name.c_str());
        a->SetNumberOfTuples(vtkIdType(n));
        std::size_t i = 0;
        for (int y : mesh.rows)
            for (int x : mesh.columns) a->SetValue(vtkIdType(i++), g.at(x, y));
        poly->GetPointData()->AddArray(a);
    };
    add("height", heights);
    for (const auto& l : layers) add(l.name, l.grid);
    poly->GetPointData()->SetActiveScalars("height");
    mark_frame(poly, o.up);
    write_with<vtkXMLPolyDataWriter>(poly, file, o);
    file.commit();
}

// ---------------------------------------------------------------- particles

namespace {

/// A particle attribute as a VTK array: the frame's own memory in the y frame,
/// a turned copy of a 3-component (vector) attribute in the z frame.
vtkSmartPointer<vtkFloatArray> attribute_array(const std::string& name, const ParticleAttribute& attr, std::size_t n,
                                               Up up) {
    if (up == Up::y || attr.components != 3) return wrap(name, attr.data.data(), n, attr.components);
    auto a = vtkSmartPointer<vtkFloatArray>::New();
    a->SetName(name.c_str());
    a->SetNumberOfComponents(3);
    a->SetNumberOfTuples(vtkIdType(n));
    std::copy_n(attr.data.data(), n * 3, a->GetPointer(0));
    turn_in_place(a->GetPointer(0), n, up);
    return a;
}

vtkSmartPointer<vtkPolyData> particle_poly(const ParticleFrame& frame, std::size_t index, Up up) {
    const auto pos = frame.attributes.find("position");
    if (pos == frame.attributes.end() || pos->second.components != 3)
        throw Error("particle frame " + std::to_string(index) + " has no 3-component 'position' attribute");
    const std::size_t n = frame.count();
    auto poly = vtkSmartPointer<vtkPolyData>::New();
    vtkNew<vtkPoints> points;
    points->SetData(attribute_array("position", pos->second, n, up));
    poly->SetPoints(points);
    vtkNew<vtkTypeInt64Array> connectivity;
    connectivity->SetNumberOfTuples(vtkIdType(n));
    std::iota(connectivity->GetPointer(0), connectivity->GetPointer(0) + n, std::int64_t(0));
    vtkNew<vtkCellArray> verts;  // one vertex cell per particle, so ParaView draws them as points
    verts->SetData(1, connectivity);
    poly->SetVerts(verts);
    for (const auto& [name, attr] : frame.attributes) {
        if (name == "position") continue;
        if (attr.components < 1 || attr.data.size() != n * std::size_t(attr.components))
            throw Error("particle frame " + std::to_string(index) + ": attribute '" + name + "' holds " +
                        std::to_string(attr.data.size()) + " values for " + std::to_string(n) + " particles of " +
                        std::to_string(attr.components) + " components");
        poly->GetPointData()->AddArray(attribute_array(name, attr, n, up));
    }
    mark_frame(poly, up);
    return poly;
}

}  // namespace

std::size_t write_particles(const ParticleSeries& series, const fs::path& target, const Options& o) {
    const std::string ext = target.extension().string();
    if (ext == ".vtp") {
        if (series.frames.size() != 1)
            throw BadInput("the particles have " + std::to_string(series.frames.size()) +
                           " frames; write a time series as .pvd (one .vtp per frame), or a single frame as .vtp");
        AtomicFile file(target);
        auto poly = particle_poly(series.frames[0], 0, o.up);
        write_with<vtkXMLPolyDataWriter>(poly, file, o);
        file.commit();
        return 1;
    }
    if (ext != ".pvd")
        throw BadInput("export:vtk-particles writes .pvd (a time series) or .vtp (one frame); '" +
                       target.filename().string() + "' has another extension");
    std::vector<std::unique_ptr<AtomicFile>> files;
    std::vector<PvdEntry> entries;
    for (std::size_t i = 0; i < series.frames.size(); ++i) {
        const std::string name = frame_name(target, "", i);
        files.push_back(std::make_unique<AtomicFile>(target.parent_path() / name));
        auto poly = particle_poly(series.frames[i], i, o.up);
        write_with<vtkXMLPolyDataWriter>(poly, *files.back(), o);
        entries.push_back({series.frames[i].time, 0, name});
    }
    files.push_back(std::make_unique<AtomicFile>(target));  // the collection last: it names the others
    const std::string pvd = pvd_text(entries);
    files.back()->write({reinterpret_cast<const std::uint8_t*>(pvd.data()), pvd.size()});
    commit_series(files);
    return files.size();
}

// ------------------------------------------------------------------- plates

std::size_t write_plates(const PlateHistory& history, const fs::path& target, const Options& o,
                         const fs::path& collisions_target) {
    if (target.extension() != ".pvd")
        throw BadInput("export:vtk-plates writes a .pvd time series; '" + target.filename().string() +
                       "' has another extension");
    const bool split = !collisions_target.empty();
    std::vector<std::unique_ptr<AtomicFile>> files;
    std::vector<PvdEntry> entries, collision_entries;
    std::int64_t previous_step = std::numeric_limits<std::int64_t>::min();
    for (std::size_t s = 0; s < history.snapshots.size(); ++s) {
        const PlateSnapshot& snap = history.snapshots[s];
        // Plates: one polygon cell each; heightmap (x, y) → orogen's (x, 0, y), turned.
        {
            vtkNew<vtkPoints> points;
            points->SetDataTypeToFloat();
            vtkNew<vtkCellArray> polys;
            vtkNew<vtkIntArray> id;
            id->SetName("plate");
            vtkNew<vtkFloatArray> velocity;
            velocity->SetName("velocity");
            velocity->SetNumberOfComponents(3);
            vtkNew<vtkFloatArray> density;
            density->SetName("density");
            for (const PlateState& p : snap.plates) {
                polys->InsertNextCell(vtkIdType(p.polygon.size()));
                for (const Point2& v : p.polygon)
                    polys->InsertCellPoint(points->InsertNextPoint(turned(v.x, 0.0, v.y, o.up).data()));
                id->InsertNextValue(p.id);
                velocity->InsertNextTuple(turned(p.velocity.x, 0.0, p.velocity.y, o.up).data());
                density->InsertNextValue(float(p.density));
            }
            vtkNew<vtkPolyData> poly;
            poly->SetPoints(points);
            poly->SetPolys(polys);
            poly->GetCellData()->AddArray(id);
            poly->GetCellData()->AddArray(velocity);
            poly->GetCellData()->AddArray(density);
            mark_frame(poly, o.up);
            const std::string name = frame_name(target, "_plates", s);
            files.push_back(std::make_unique<AtomicFile>(target.parent_path() / name));
            write_with<vtkXMLPolyDataWriter>(poly, *files.back(), o);
            entries.push_back({snap.time, 0, name});
        }
        // Collisions since the previous snapshot: one line cell a–b each.
        {
            vtkNew<vtkPoints> points;
            points->SetDataTypeToFloat();
            vtkNew<vtkCellArray> lines;
            vtkNew<vtkIntArray> a, b, kind;
            a->SetName("plate_a");
            b->SetName("plate_b");
            kind->SetName("kind");
            vtkNew<vtkFloatArray> impulse;
            impulse->SetName("impulse");
            vtkNew<vtkTypeInt64Array> step;
            step->SetName("step");
            for (const CollisionEvent& e : history.collisions) {
                if (e.step <= previous_step || e.step > snap.step) continue;
                lines->InsertNextCell(2);
                lines->InsertCellPoint(points->InsertNextPoint(turned(e.a.x, 0.0, e.a.y, o.up).data()));
                lines->InsertCellPoint(points->InsertNextPoint(turned(e.b.x, 0.0, e.b.y, o.up).data()));
                a->InsertNextValue(e.plate_a);
                b->InsertNextValue(e.plate_b);
                kind->InsertNextValue(int(e.kind));
                impulse->InsertNextValue(float(e.impulse));
                step->InsertNextValue(e.step);
            }
            vtkNew<vtkPolyData> poly;
            poly->SetPoints(points);
            poly->SetLines(lines);
            for (vtkDataArray* arr :
                 {static_cast<vtkDataArray*>(a), static_cast<vtkDataArray*>(b), static_cast<vtkDataArray*>(kind),
                  static_cast<vtkDataArray*>(impulse), static_cast<vtkDataArray*>(step)})
                poly->GetCellData()->AddArray(arr);
            mark_frame(poly, o.up);
            const std::string name = frame_name(target, "_collisions", s);
            files.push_back(std::make_unique<AtomicFile>(target.parent_path() / name));
            write_with<vtkXMLPolyDataWriter>(poly, *files.back(), o);
            if (split) collision_entries.push_back({snap.time, 0, name});
            else entries.push_back({snap.time, 1, name});
        }
        previous_step = snap.step;
    }
    auto collection = [&](const fs::path& file, const std::vector<PvdEntry>& list) {
        files.push_back(std::make_unique<AtomicFile>(file));
        const std::string pvd = pvd_text(list);
        files.back()->write({reinterpret_cast<const std::uint8_t*>(pvd.data()), pvd.size()});
    };
    if (split) collection(collisions_target, collision_entries);
    collection(target, entries);
    commit_series(files);
    return files.size();
}

}  // namespace orogen::vtk
