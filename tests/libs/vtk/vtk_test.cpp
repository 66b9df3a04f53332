// export:vtk — every file read back with VTK's own XML readers.
#include <orogen/vtk/vtk_writer.hpp>

#include "export_test_support.hpp"
#include "orogen_test.hpp"

#include <orogen/error.hpp>

#include <gtest/gtest.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkXMLImageDataReader.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkFieldData.h>
#include <vtkStringArray.h>

#include <regex>

using namespace orogen;
namespace ov = orogen::vtk;
namespace fs = std::filesystem;

namespace {

struct PvdItem {
    double time;
    int part;
    std::string file;
};

std::vector<PvdItem> read_pvd(const fs::path& p) {
    const std::string text = test::file_text(p);
    std::vector<PvdItem> items;
    const std::regex re(R"re(<DataSet timestep="([^"]*)" group="" part="(\d+)" file="([^"]*)"/>)re");
    for (auto it = std::sregex_iterator(text.begin(), text.end(), re); it != std::sregex_iterator(); ++it)
        items.push_back({std::stod((*it)[1]), std::stoi((*it)[2]), (*it)[3]});
    EXPECT_NE(text.find("<VTKFile type=\"Collection\""), std::string::npos);
    return items;
}

vtkSmartPointer<vtkPolyData> read_vtp(const fs::path& p) {
    vtkNew<vtkXMLPolyDataReader> r;
    r->SetFileName(p.c_str());
    r->Update();
    EXPECT_EQ(r->GetErrorCode(), 0u) << p;
    return r->GetOutput();
}

ParticleFrame frame(std::size_t n, double time, float shift) {
    ParticleFrame f;
    f.time = time;
    f.step = std::int64_t(time * 500);
    auto& pos = f.attributes["position"];
    pos.components = 3;
    auto& vel = f.attributes["velocity"];
    vel.components = 3;
    auto& rho = f.attributes["density"];
    rho.components = 1;
    for (std::size_t i = 0; i < n; ++i) {
        pos.data.insert(pos.data.end(), {float(i) + shift, 2.0f * float(i), -float(i)});
        vel.data.insert(vel.data.end(), {1.0f, 0.0f, -0.5f * float(i)});
        rho.data.push_back(998.29f + float(i));
    }
    return f;
}

/// The frame a file says it is in (field data "orogen_up").
std::string frame_of(vtkDataObject* data) {
    auto* a = vtkStringArray::SafeDownCast(data->GetFieldData()->GetAbstractArray("orogen_up"));
    return a && a->GetNumberOfValues() == 1 ? a->GetValue(0) : std::string("(none)");
}

ov::Options up_y() {
    ov::Options o;
    o.up = ov::Up::y;
    return o;
}

}  // namespace

// ParaView's convention (the default): the image lies in the XY plane, Y north,
// so ParaView's default camera (looking down −Z) sees it from above, north up.
TEST(Vtk, ImageDataLiesInTheXYPlaneNorthUpByDefault) {
    test::TempDir dir;
    const int w = 33, h = 17;
    auto heights = test::hills(w, h);
    std::vector<float> plate(heights.size());
    for (std::size_t i = 0; i < heights.size(); ++i) plate[i] = float(i % 3);
    const std::vector<ov::NamedGrid> layers = {{"plate", {plate.data(), w, h, 25.0}}};
    ov::write_heightmap({heights.data(), w, h, 25.0}, layers, dir / "t.vti");

    vtkNew<vtkXMLImageDataReader> r;
    r->SetFileName((dir / "t.vti").c_str());
    r->Update();
    vtkImageData* img = r->GetOutput();
    EXPECT_EQ(frame_of(img), "z");
    int dims[3];
    img->GetDimensions(dims);
    EXPECT_EQ(dims[0], w);
    EXPECT_EQ(dims[1], h);
    EXPECT_EQ(dims[2], 1);
    double bounds[6];
    img->GetBounds(bounds);
    EXPECT_DOUBLE_EQ(bounds[0], 0.0);
    EXPECT_DOUBLE_EQ(bounds[1], 32 * 25.0);  // X east to (w−1)·cell
    EXPECT_DOUBLE_EQ(bounds[2], -16 * 25.0);  // Y north: the south row at −(h−1)·cell
    EXPECT_DOUBLE_EQ(bounds[3], 0.0);  // the north row (row 0) at 0
    EXPECT_DOUBLE_EQ(bounds[4], 0.0);
    EXPECT_DOUBLE_EQ(bounds[5], 0.0);
    for (const auto& [name, data] :
         {std::pair<const char*, const std::vector<float>*>{"height", &heights}, {"plate", &plate}}) {
        vtkDataArray* a = img->GetPointData()->GetArray(name);
        ASSERT_NE(a, nullptr) << name;
        // Sample (x, row) is the point at X = x·cell, Y = −row·cell.
        for (int y = 0; y < h; y += 4)
            for (int x = 0; x < w; x += 5) {
                double at[3] = {x * 25.0, -y * 25.0, 0.0};
                const vtkIdType id = img->FindPoint(at);
                ASSERT_GE(id, 0);
                EXPECT_EQ(float(a->GetTuple1(id)), (*data)[std::size_t(y * w + x)]) << name << " " << x << "," << y;
            }
    }
}

TEST(Vtk, ImageDataWithUpYHoldsHeightAndEveryLayerInTheXZPlane) {
    test::TempDir dir;
    const int w = 33, h = 17;
    auto heights = test::hills(w, h);
    std::vector<float> water(heights.size()), plate(heights.size());
    for (std::size_t i = 0; i < heights.size(); ++i) {
        water[i] = 0.01f * float(i % 7);
        plate[i] = float(i % 3);
    }
    const std::vector<ov::NamedGrid> layers = {{"water", {water.data(), w, h, 25.0}},
                                               {"plate", {plate.data(), w, h, 25.0}}};
    ov::write_heightmap({heights.data(), w, h, 25.0}, layers, dir / "t.vti", up_y());

    vtkNew<vtkXMLImageDataReader> r;
    r->SetFileName((dir / "t.vti").c_str());
    r->Update();
    vtkImageData* img = r->GetOutput();
    EXPECT_EQ(frame_of(img), "y");
    int dims[3];
    img->GetDimensions(dims);
    EXPECT_EQ(dims[0], w);
    EXPECT_EQ(dims[1], 1);
    EXPECT_EQ(dims[2], h);
    double bounds[6];
    img->GetBounds(bounds);
    EXPECT_DOUBLE_EQ(bounds[1], 32 * 25.0);  // X east to (w−1)·cell
    EXPECT_DOUBLE_EQ(bounds[5], 16 * 25.0);  // Z south to (h−1)·cell
    vtkPointData* pd = img->GetPointData();
    ASSERT_EQ(pd->GetNumberOfArrays(), 3);
    for (const auto& [name, data] : {std::pair<const char*, const std::vector<float>*>{"height", &heights},
                                     {"water", &water},
                                     {"plate", &plate}}) {
        vtkDataArray* a = pd->GetArray(name);
        ASSERT_NE(a, nullptr) << name;
        ASSERT_EQ(a->GetNumberOfTuples(), w * h);
        // Point (x, 0, y) of the image is sample (x, y).
        for (int y = 0; y < h; y += 5)
            for (int x = 0; x < w; x += 3) {
                const vtkIdType id = img->ComputePointId(std::array<int, 3>{x, 0, y}.data());
                EXPECT_EQ(float(a->GetTuple1(id)), (*data)[std::size_t(y * w + x)]) << name;
            }
    }
}

TEST(Vtk, PolyDataMeshHasTrianglesNormalsAndLayers) {
    test::TempDir dir;
    const int w = 21, h = 13;
    auto heights = test::hills(w, h);
    std::vector<float> sediment(heights.size(), 0.25f);
    const std::vector<ov::NamedGrid> layers = {{"sediment", {sediment.data(), w, h, 5.0}}};
    ov::Options o;
    o.vertical_scale = 3.0;
    ov::write_heightmap({heights.data(), w, h, 5.0}, layers, dir / "t.vtp", o);
    auto poly = read_vtp(dir / "t.vtp");
    EXPECT_EQ(poly->GetNumberOfPoints(), w * h);
    EXPECT_EQ(poly->GetNumberOfPolys(), 2 * (w - 1) * (h - 1));
    EXPECT_EQ(poly->GetPolys()->GetMaxCellSize(), 3);
    EXPECT_EQ(frame_of(poly), "z");
    double b[6];
    poly->GetBounds(b);
    const auto [lo, hi] = std::minmax_element(heights.begin(), heights.end());
    EXPECT_FLOAT_EQ(float(b[4]), *lo * 3.0f);  // heights along Z
    EXPECT_FLOAT_EQ(float(b[5]), *hi * 3.0f);
    EXPECT_DOUBLE_EQ(b[1], 20 * 5.0);
    EXPECT_DOUBLE_EQ(b[2], -12 * 5.0);  // Y north, row 0 at 0
    EXPECT_DOUBLE_EQ(b[3], 0.0);
    ASSERT_NE(poly->GetPointData()->GetNormals(), nullptr);
    EXPECT_GT(poly->GetPointData()->GetNormals()->GetComponent(0, 2), 0.0);  // facing up: +Z
    ASSERT_NE(poly->GetPointData()->GetArray("sediment"), nullptr);
    EXPECT_FLOAT_EQ(float(poly->GetPointData()->GetArray("sediment")->GetTuple1(17)), 0.25f);
    EXPECT_FLOAT_EQ(float(poly->GetPointData()->GetArray("height")->GetTuple1(w + 2)), heights[std::size_t(w + 2)]);
}

// The two frames hold the same mesh turned +90° about X: (x, y, z) → (x, −z, y),
// and its triangles keep their winding (the normals turn with the points).
TEST(Vtk, UpYMeshIsTheUpZMeshTurnedAboutX) {
    test::TempDir dir;
    const int w = 11, h = 7;
    auto heights = test::hills(w, h);
    ov::write_heightmap({heights.data(), w, h, 2.0}, {}, dir / "z.vtp");
    ov::write_heightmap({heights.data(), w, h, 2.0}, {}, dir / "y.vtp", up_y());
    auto z = read_vtp(dir / "z.vtp"), y = read_vtp(dir / "y.vtp");
    EXPECT_EQ(frame_of(y), "y");
    ASSERT_EQ(z->GetNumberOfPoints(), y->GetNumberOfPoints());
    for (vtkIdType i = 0; i < z->GetNumberOfPoints(); ++i) {
        double pz[3], py[3];
        z->GetPoint(i, pz);
        y->GetPoint(i, py);
        EXPECT_EQ(pz[0], py[0]);
        EXPECT_EQ(pz[1], -py[2]);
        EXPECT_EQ(pz[2], py[1]);
        EXPECT_FLOAT_EQ(float(z->GetPointData()->GetNormals()->GetComponent(i, 2)),
                        float(y->GetPointData()->GetNormals()->GetComponent(i, 1)));
    }
    EXPECT_GT(y->GetPointData()->GetNormals()->GetComponent(0, 1), 0.0);  // up is +Y there
    // Same triangles, same vertex order.
    vtkIdType nz = 0, ny = 0;
    const vtkIdType *cz = nullptr, *cy = nullptr;
    z->GetPolys()->InitTraversal();
    y->GetPolys()->InitTraversal();
    while (z->GetPolys()->GetNextCell(nz, cz) && y->GetPolys()->GetNextCell(ny, cy)) {
        ASSERT_EQ(nz, ny);
        for (vtkIdType k = 0; k < nz; ++k) EXPECT_EQ(cz[k], cy[k]);
    }
}

TEST(Vtk, DecimatedMeshKeepsEveryKthVertexAndItsLayerValues) {
    test::TempDir dir;
    auto heights = test::hills(9, 9);
    ov::Options o;
    o.decimate = 4;
    ov::write_heightmap({heights.data(), 9, 9, 1.0}, {}, dir / "t.vtp", o);
    auto poly = read_vtp(dir / "t.vtp");
    EXPECT_EQ(poly->GetNumberOfPoints(), 9);
    EXPECT_EQ(poly->GetNumberOfPolys(), 8);
    EXPECT_FLOAT_EQ(float(poly->GetPointData()->GetArray("height")->GetTuple1(4)), heights[4 * 9 + 4]);
}

TEST(Vtk, ParticleSeriesIsAPvdOfFramesWithEveryAttribute) {
    test::TempDir dir;
    ParticleSeries s;
    s.frames = {frame(5, 0.0, 0), frame(7, 0.002, 1), frame(3, 0.004, 2)};
    EXPECT_EQ(ov::write_particles(s, dir / "sph.pvd"), 4u);
    const auto items = read_pvd(dir / "sph.pvd");
    ASSERT_EQ(items.size(), 3u);
    EXPECT_EQ(items[1].file, "sph_000001.vtp");
    EXPECT_DOUBLE_EQ(items[1].time, 0.002);
    for (std::size_t i = 0; i < 3; ++i) {
        auto poly = read_vtp(dir / items[i].file);
        const std::size_t n = s.frames[i].count();
        EXPECT_EQ(std::size_t(poly->GetNumberOfPoints()), n);
        EXPECT_EQ(std::size_t(poly->GetNumberOfVerts()), n);
        EXPECT_EQ(frame_of(poly), "z");
        // orogen's (x, y up, z south) = (k + shift, 2k, −k) is (x, −z, y) = (k + shift, k, 2k) with Z up.
        double p[3];
        poly->GetPoint(vtkIdType(n - 1), p);
        EXPECT_DOUBLE_EQ(p[0], double(n - 1) + double(i));
        EXPECT_DOUBLE_EQ(p[1], double(n - 1));
        EXPECT_DOUBLE_EQ(p[2], 2.0 * double(n - 1));
        vtkDataArray* vel = poly->GetPointData()->GetArray("velocity");
        ASSERT_NE(vel, nullptr);
        EXPECT_EQ(vel->GetNumberOfComponents(), 3);
        EXPECT_DOUBLE_EQ(vel->GetComponent(2, 1), 1.0);  // (1, 0, −1) turned: (1, 1, 0)
        EXPECT_DOUBLE_EQ(vel->GetComponent(2, 2), 0.0);
        vtkDataArray* rho = poly->GetPointData()->GetArray("density");
        ASSERT_NE(rho, nullptr);
        EXPECT_FLOAT_EQ(float(rho->GetTuple1(1)), 999.29f);
    }
    EXPECT_EQ(test::folder_entries(dir.path()),
              (std::vector<std::string>{"sph.pvd", "sph_000000.vtp", "sph_000001.vtp", "sph_000002.vtp"}));
}

TEST(Vtk, ParticlesWithUpYKeepOrogensFrame) {
    test::TempDir dir;
    ParticleSeries s;
    s.frames = {frame(4, 0.0, 0)};
    ov::write_particles(s, dir / "p.vtp", up_y());
    auto poly = read_vtp(dir / "p.vtp");
    EXPECT_EQ(frame_of(poly), "y");
    double p[3];
    poly->GetPoint(3, p);
    EXPECT_DOUBLE_EQ(p[1], 6.0);
    EXPECT_DOUBLE_EQ(p[2], -3.0);
    EXPECT_DOUBLE_EQ(poly->GetPointData()->GetArray("velocity")->GetComponent(2, 2), -1.0);
}

TEST(Vtk, ParticleTimeSeriesAsASingleVtpIsBadInput) {
    test::TempDir dir;
    ParticleSeries s;
    s.frames = {frame(2, 0, 0), frame(2, 1, 0)};
    try {
        ov::write_particles(s, dir / "p.vtp");
        FAIL();
    } catch (const BadInput& e) {
        EXPECT_STREQ(e.what(),
                     "the particles have 2 frames; write a time series as .pvd (one .vtp per frame), or a "
                     "single frame as .vtp");
    }
    s.frames.resize(1);
    EXPECT_EQ(ov::write_particles(s, dir / "p.vtp"), 1u);
    EXPECT_EQ(read_vtp(dir / "p.vtp")->GetNumberOfPoints(), 2);
}

TEST(Vtk, PlatesArePolygonsAndCollisionsPerSnapshot) {
    test::TempDir dir;
    PlateHistory hist;
    hist.width = hist.height = 1000;
    for (int s = 0; s < 2; ++s) {
        PlateSnapshot snap;
        snap.step = s == 0 ? 5 : 12;
        snap.time = double(snap.step);
        snap.plates.push_back({1, {{0, 0}, {400, 0}, {400, 300}, {0, 300}}, {1.0 + s, 0.5}, 1.0});
        snap.plates.push_back({2, {{500, 0}, {900, 0}, {700, 600}}, {-1.0, 0.0}, 1.2});
        hist.snapshots.push_back(snap);
    }
    hist.collisions.push_back({1, 1, 2, {400, 10}, {400, 200}, BoundaryKind::convergent, 3.5});
    hist.collisions.push_back({5, 1, 2, {400, 20}, {420, 200}, BoundaryKind::transform, 1.0});
    hist.collisions.push_back({12, 2, 1, {450, 30}, {440, 250}, BoundaryKind::divergent, 0.5});
    EXPECT_EQ(ov::write_plates(hist, dir / "plates.pvd"), 5u);
    const auto items = read_pvd(dir / "plates.pvd");
    ASSERT_EQ(items.size(), 4u);
    EXPECT_EQ(items[0].part, 0);
    EXPECT_EQ(items[1].part, 1);
    EXPECT_EQ(items[2].file, "plates_plates_000001.vtp");
    EXPECT_DOUBLE_EQ(items[3].time, 12.0);

    auto plates = read_vtp(dir / items[2].file);
    EXPECT_EQ(plates->GetNumberOfPolys(), 2);
    EXPECT_EQ(plates->GetNumberOfPoints(), 7);
    EXPECT_EQ(plates->GetCellData()->GetArray("plate")->GetTuple1(1), 2.0);
    EXPECT_DOUBLE_EQ(plates->GetCellData()->GetArray("velocity")->GetComponent(0, 0), 2.0);
    EXPECT_DOUBLE_EQ(plates->GetCellData()->GetArray("velocity")->GetComponent(0, 1),
                     -0.5);  // (2, 0.5) south → north −0.5
    EXPECT_FLOAT_EQ(float(plates->GetCellData()->GetArray("density")->GetTuple1(1)), 1.2f);
    EXPECT_EQ(frame_of(plates), "z");
    double p[3];
    plates->GetPoint(6, p);  // (700, 600) in the plane → X 700, Y −600, Z 0
    EXPECT_DOUBLE_EQ(p[0], 700.0);
    EXPECT_DOUBLE_EQ(p[1], -600.0);
    EXPECT_DOUBLE_EQ(p[2], 0.0);

    auto first = read_vtp(dir / items[1].file);  // steps ≤ 5: two contacts
    EXPECT_EQ(first->GetNumberOfLines(), 2);
    EXPECT_EQ(first->GetCellData()->GetArray("kind")->GetTuple1(1), 3.0);
    EXPECT_FLOAT_EQ(float(first->GetCellData()->GetArray("impulse")->GetTuple1(0)), 3.5f);
    auto second = read_vtp(dir / items[3].file);  // steps 6..12: one
    EXPECT_EQ(second->GetNumberOfLines(), 1);
    EXPECT_EQ(second->GetCellData()->GetArray("plate_a")->GetTuple1(0), 2.0);
    EXPECT_EQ(second->GetCellData()->GetArray("step")->GetTuple1(0), 12.0);
}

PlateHistory two_snapshots() {
    PlateHistory hist;
    hist.width = hist.height = 1000;
    for (int s = 0; s < 2; ++s) {
        PlateSnapshot snap;
        snap.step = s == 0 ? 5 : 12;
        snap.time = double(snap.step);
        snap.plates.push_back({1, {{0, 0}, {400, 0}, {400, 300}}, {1.0, 0.5}, 1.0});
        hist.snapshots.push_back(snap);
    }
    hist.collisions.push_back({1, 1, 2, {400, 10}, {400, 200}, BoundaryKind::convergent, 3.5});
    return hist;
}

TEST(Vtk, PlatesWithUpYLieInTheXZPlane) {
    test::TempDir dir;
    ov::write_plates(two_snapshots(), dir / "plates.pvd", up_y());
    auto plates = read_vtp(dir / "plates_plates_000000.vtp");
    EXPECT_EQ(frame_of(plates), "y");
    double p[3];
    plates->GetPoint(2, p);
    EXPECT_DOUBLE_EQ(p[0], 400.0);
    EXPECT_DOUBLE_EQ(p[1], 0.0);
    EXPECT_DOUBLE_EQ(p[2], 300.0);
    EXPECT_DOUBLE_EQ(plates->GetCellData()->GetArray("velocity")->GetComponent(0, 2), 0.5);
}

// export:paraview-state's layout: polygons and collisions as two plain series.
TEST(Vtk, PlatesCanListTheirCollisionsInASecondCollection) {
    test::TempDir dir;
    EXPECT_EQ(ov::write_plates(two_snapshots(), dir / "p.pvd", {}, dir / "c.pvd"), 6u);
    const auto polygons = read_pvd(dir / "p.pvd"), collisions = read_pvd(dir / "c.pvd");
    ASSERT_EQ(polygons.size(), 2u);
    ASSERT_EQ(collisions.size(), 2u);
    for (std::size_t i = 0; i < 2; ++i) {
        EXPECT_EQ(polygons[i].part, 0);
        EXPECT_EQ(collisions[i].part, 0);
        EXPECT_EQ(polygons[i].time, collisions[i].time);
        EXPECT_EQ(read_vtp(dir / polygons[i].file)->GetNumberOfPolys(), 1);
        EXPECT_EQ(read_vtp(dir / collisions[i].file)->GetNumberOfPolys(), 0);
    }
    EXPECT_EQ(read_vtp(dir / collisions[0].file)->GetNumberOfLines(), 1);
    EXPECT_EQ(collisions[1].file, "p_collisions_000001.vtp");
}

TEST(Vtk, BadExtensionsAreBadInput) {
    test::TempDir dir;
    auto heights = test::hills(5, 5);
    try {
        ov::write_heightmap({heights.data(), 5, 5, 1.0}, {}, dir / "t.vtk");
        FAIL();
    } catch (const BadInput& e) {
        EXPECT_STREQ(e.what(), "export:vtk writes a heightmap as .vti or .vtp; 't.vtk' has another extension");
    }
    EXPECT_THROW(ov::write_plates({}, dir / "p.vtp"), BadInput);
    EXPECT_TRUE(test::folder_entries(dir.path()).empty());
}

TEST(Vtk, UnwritableFolderFailsWithoutLeavingAFile) {
    auto heights = test::hills(5, 5);
    EXPECT_THROW(ov::write_heightmap({heights.data(), 5, 5, 1.0}, {}, test::unwritable_folder() / "t.vti"), Error);
    EXPECT_FALSE(fs::exists(test::unwritable_folder() / "t.vti"));
}

TEST(Vtk, FullDiskKeepsTheGoodFilesAndLeavesNoTemporary) {
    test::TempDir dir;
    test::TinyDisk disk(dir / "tiny");
    OROGEN_SKIP_WITHOUT_TINY_DISK(disk);
    auto heights = test::hills(129, 129);  // 66 KB of heights: does not fit beside the good file
    std::ofstream(disk.path() / "t.vti") << "good";
    try {
        ov::write_heightmap({heights.data(), 129, 129, 1.0}, {}, disk.path() / "t.vti");
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("cannot write " + (disk.path() / "t.vti").string()), std::string::npos)
            << e.what();
    }
    EXPECT_EQ(test::folder_entries(disk.path()), (std::vector<std::string>{"t.vti"}));
    EXPECT_EQ(test::file_text(disk.path() / "t.vti"), "good");
    // A series: one frame fits, the next does not; nothing of the series lands.
    ParticleSeries s;
    s.frames = {frame(10, 0, 0), frame(3000, 1, 0)};
    EXPECT_THROW(ov::write_particles(s, disk.path() / "p.pvd"), Error);
    EXPECT_EQ(test::folder_entries(disk.path()), (std::vector<std::string>{"t.vti"}));
}
