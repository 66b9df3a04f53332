// erode:sph through the real binary: its particle series read back with
// VTK's XML readers (what ParaView uses) and as OpenVDB points; bad input at
// check time (exit 2 naming the parameter).
#include "orogen_test.hpp"

#include <gtest/gtest.h>
#include <algorithm>
#include <cstring>
#include <vector>
#include <openvdb/openvdb.h>
#include <openvdb/points/PointCount.h>
#include <openvdb/points/PointDataGrid.h>
#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataReader.h>

#include <regex>
#include <string>

using namespace orogen::test;
namespace fs = std::filesystem;

namespace {

const char* kAttributes[] = {"velocity", "density", "pressure", "sediment", "acidity", "age"};

std::string spec(const std::string& sph_args) {
    return "orogen 1\nseed 3\ngrid 33 cell=1\n"
           "hill = generate:shape(kind=pyramid, height=10)\n"
           "wet = erode:sph(hill, " +
        sph_args +
        ")\n"
        "export:vtk-particles(wet.particles, path=\"p.pvd\")\n"
        "export:vdb-particles(wet.particles, path=\"p.vdb\")\n"
        "export:raw(wet, path=\"wet.r32\")\n";
}

}  // namespace

TEST(SphNode, ParticleSeriesOpensWithVtksXmlReaderAndAsOpenVdbPoints) {
    TempDir dir;
    const fs::path s = dir.write("sph.orogen", spec("steps=20, rain=30, record_every=10, lifespan=100"));
    const RunResult r = run_orogen("run " + q(s) + " --out " + q(dir / "out") + " --quiet");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    // Three frames (steps 0, 10, 20), each a .vtp listed in the .pvd.
    const std::string pvd = slurp(dir / "out" / "p.pvd");
    const std::regex re(R"re(file="([^"]*)")re");
    std::vector<std::string> files;
    for (auto it = std::sregex_iterator(pvd.begin(), pvd.end(), re); it != std::sregex_iterator(); ++it)
        files.push_back((*it)[1]);
    ASSERT_EQ(files.size(), 3u);
    std::size_t last = 0;
    for (const std::string& f : files) {
        vtkNew<vtkXMLPolyDataReader> reader;
        reader->SetFileName((dir / "out" / f).c_str());
        reader->Update();
        ASSERT_EQ(reader->GetErrorCode(), 0u) << f;
        vtkPolyData* poly = reader->GetOutput();
        last = std::size_t(poly->GetNumberOfPoints());
        for (const char* a : kAttributes) {
            vtkDataArray* arr = poly->GetPointData()->GetArray(a);
            ASSERT_NE(arr, nullptr) << f << " lacks " << a;
            EXPECT_EQ(std::size_t(arr->GetNumberOfTuples()), last);
        }
        if (last > 0) {
            // Water near rest density, in the map.
            const double rho = poly->GetPointData()->GetArray("density")->GetTuple1(0);
            EXPECT_GT(rho, 100.0);
            EXPECT_LT(rho, 2000.0);
            for (vtkIdType k = 0; k < poly->GetNumberOfPoints(); ++k) {
                double p[3];
                poly->GetPoint(k, p);
                // export:vtk's default frame: X east, Y north (the map spans Y ∈ [−32, 0]), Z up.
                EXPECT_GE(p[0], 0.0);
                EXPECT_LE(p[0], 32.0);
                EXPECT_LE(p[1], 0.0);
                EXPECT_GE(p[1], -32.0);
            }
        }
    }
    // The last frame (step 20) is the state the eroded heightmap was written in: every particle is on or
    // above its triangulated surface (diagonal from (i, j) to (i+1, j+1), as the solver's), so Z is up and
    // the frame is the map's. (Erosion cuts below the pyramid's foot at 0 m, so 0 is no bound.) 1e-5 m: the
    // heights are written in float.
    {
        const std::string raw = slurp(dir / "out" / "wet.r32");
        ASSERT_EQ(raw.size(), 33u * 33u * 4u);
        std::vector<float> hm(33 * 33);
        std::memcpy(hm.data(), raw.data(), raw.size());
        const auto H = [&](int x, int z) { return double(hm[std::size_t(z) * 33 + std::size_t(x)]); };
        vtkNew<vtkXMLPolyDataReader> reader;
        reader->SetFileName((dir / "out" / files.back()).c_str());
        reader->Update();
        vtkPolyData* poly = reader->GetOutput();
        for (vtkIdType k = 0; k < poly->GetNumberOfPoints(); ++k) {
            double p[3];
            poly->GetPoint(k, p);
            const double x = std::clamp(p[0], 0.0, 32.0), z = std::clamp(-p[1], 0.0, 32.0);
            const int i = std::min(int(x), 31), j = std::min(int(z), 31);
            const double fx = x - i, fz = z - j;
            const double a = H(i, j), b = H(i + 1, j), c = H(i, j + 1), d = H(i + 1, j + 1);
            const double ys = fx >= fz ? a + fx * (b - a) + fz * (d - b) : a + fz * (c - a) + fx * (d - c);
            EXPECT_GE(p[2], ys - 1e-5) << "particle " << k << " at " << p[0] << ", " << p[1];
        }
    }
    EXPECT_EQ(last, 20u * 30u) << "20 steps of 30 rain particles, none evaporated yet";
    // OpenVDB: the last frame as a points grid with every attribute.
    openvdb::initialize();
    openvdb::io::File file((dir / "out" / "p_000002.vdb").string());
    file.open();
    auto grids = file.getGrids();
    file.close();
    ASSERT_EQ(grids->size(), 1u);
    auto points = openvdb::gridPtrCast<openvdb::points::PointDataGrid>((*grids)[0]);
    ASSERT_TRUE(points);
    EXPECT_EQ(openvdb::points::pointCount(points->tree()), 600u);
    auto leaf = points->tree().cbeginLeaf();
    ASSERT_TRUE(leaf);
    const auto& desc = leaf->attributeSet().descriptor();
    for (const char* a : kAttributes) EXPECT_NE(desc.find(a), openvdb::points::AttributeSet::INVALID_POS) << a;
    // The eroded heightmap was written too.
    EXPECT_EQ(fs::file_size(dir / "out" / "wet.r32"), 33u * 33u * 4u);
}

TEST(SphNode, BadInputIsRefusedAtCheckTimeNamingTheParameter) {
    struct Case {
        const char* args;
        const char* param;
        const char* says;
    };
    const Case cases[] = {
        {"particles=0", "particles", "particles"},
        {"particles=1000000000", "particles", "of memory"},
        {"radius=0", "radius", "radius"},
        {"radius=-1", "radius", "radius"},
        {"dt=0", "dt", "dt"},
        {"lifespan=0", "lifespan", "lifespan"},
        {"rain_height=-2", "rain_height", "rain_height"},
        {"springs=[(0.5, 0.5), (1.5, 0.2)]", "springs", "springs"},
        {"rain=0", "rain", "no water"},
    };
    TempDir dir;
    for (const Case& c : cases) {
        const fs::path s = dir.write("bad.orogen", spec(c.args));
        const RunResult r = run_orogen("check " + q(s));
        EXPECT_EQ(r.exit_code, 2) << c.args << "\n" << r.err;
        EXPECT_NE(r.err.find("bad.orogen:5:"), std::string::npos) << c.args << "\n" << r.err;
        EXPECT_NE(r.err.find(c.says), std::string::npos) << c.args << "\n" << r.err;
        EXPECT_NE(r.err.find(c.param), std::string::npos) << c.args << "\n" << r.err;
    }
    // Nothing was written for a refused spec.
    const RunResult r = run_orogen("run " + q(dir.write("bad.orogen", spec("dt=0"))) + " --out " + q(dir / "out"));
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_FALSE(fs::exists(dir / "out" / "p.pvd"));
}
