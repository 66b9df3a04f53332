// export:vdb — files read back with OpenVDB: grid classes, voxel sizes, sampled values.
#include "vdb_writer.hpp"

#include "export_test_support.hpp"
#include "orogen_test.hpp"

#include <orogen/error.hpp>

#include <gtest/gtest.h>
#include <openvdb/openvdb.h>
#include <openvdb/points/PointCount.h>
#include <openvdb/points/PointDataGrid.h>

#include <algorithm>

using namespace orogen;
namespace fs = std::filesystem;

namespace {

openvdb::GridPtrVecPtr read_all(const fs::path& p) {
    vdb::initialize_once();
    openvdb::io::File f(p.string());
    f.open();
    auto grids = f.getGrids();
    f.close();
    return grids;
}

openvdb::FloatGrid::Ptr float_grid(const openvdb::GridPtrVecPtr& grids, const std::string& name) {
    for (auto& g : *grids)
        if (g->getName() == name) return openvdb::gridPtrCast<openvdb::FloatGrid>(g);
    ADD_FAILURE() << "no grid " << name;
    return nullptr;
}

}  // namespace

TEST(Vdb, PlaneGivesExactSignedDistancesInTheBand) {
    test::TempDir dir;
    const int w = 65, h = 49;
    const double cell = 2.0, slope = 0.2;  // h = 0.2·X + 100: cos(slope) = 1/√1.04
    std::vector<float> heights(std::size_t(w * h));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) heights[std::size_t(y * w + x)] = float(slope * x * cell + 100.0);
    vdb::TerrainOptions exact;
    exact.half_float = false;
    const auto s = vdb::write_terrain({heights.data(), w, h, cell}, nullptr, dir / "t.vdb", exact);
    EXPECT_GT(s.surface_voxels, std::size_t(w * h * 5));
    vdb::write_terrain({heights.data(), w, h, cell}, nullptr, dir / "half.vdb");  // default: 16-bit level set

    const auto grids = read_all(dir / "t.vdb");
    ASSERT_EQ(grids->size(), 2u);
    auto surface = float_grid(grids, "surface");
    ASSERT_TRUE(surface);
    EXPECT_EQ(surface->getGridClass(), openvdb::GRID_LEVEL_SET);
    EXPECT_DOUBLE_EQ(surface->voxelSize()[0], cell);
    EXPECT_FLOAT_EQ(surface->background(), 6.0f);  // 3 voxels of 2 m
    const double c = 1.0 / std::sqrt(1.0 + slope * slope);
    auto acc = surface->getConstAccessor();
    for (int k = 1; k < h - 1; k += 7)
        for (int i = 1; i < w - 1; i += 5) {
            const double ground = slope * i * cell + 100.0;
            const int jg = int(std::floor(ground / cell));
            for (int j = jg - 2; j <= jg + 3; ++j) {
                const double expected = std::clamp((j * cell - ground) * c, -6.0, 6.0);
                ASSERT_NEAR(acc.getValue({i, j, k}), expected, 1e-4) << i << " " << j << " " << k;
            }
            EXPECT_FLOAT_EQ(acc.getValue({i, jg - 40, k}), -6.0f);  // deep ground: inside
            EXPECT_FLOAT_EQ(acc.getValue({i, jg + 40, k}), 6.0f);  // sky: outside
        }
    // The default half floats stay within 1/1000 of a voxel; the height grid stays exact.
    auto half = float_grid(read_all(dir / "half.vdb"), "surface");
    ASSERT_TRUE(half);
    openvdb::Index64 compared = 0;
    for (auto it = surface->cbeginValueOn(); it; ++it, ++compared)
        ASSERT_NEAR(half->tree().getValue(it.getCoord()), *it, cell / 1000) << it.getCoord();
    EXPECT_EQ(compared, surface->activeVoxelCount());
    EXPECT_EQ(float_grid(read_all(dir / "half.vdb"), "height")->tree().getValue({17, 0, 23}), heights[23 * w + 17]);
    auto height = float_grid(grids, "height");
    ASSERT_TRUE(height);
    EXPECT_EQ(height->getGridClass(), openvdb::GRID_UNKNOWN);
    EXPECT_EQ(height->activeVoxelCount(), openvdb::Index64(w * h));
    EXPECT_EQ(height->tree().getValue({17, 0, 23}), heights[23 * w + 17]);
}

TEST(Vdb, HillsAreNegativeBelowAndPositiveAboveEverywhere) {
    test::TempDir dir;
    const int w = 97, h = 65;
    auto heights = test::hills(w, h, 200.0);  // slopes up to ~1
    vdb::write_terrain({heights.data(), w, h, 5.0}, nullptr, dir / "t.vdb");
    auto surface = float_grid(read_all(dir / "t.vdb"), "surface");
    ASSERT_TRUE(surface);
    auto acc = surface->getConstAccessor();
    const auto [lo, hi] = std::minmax_element(heights.begin(), heights.end());
    int checked = 0;
    for (int k = 0; k < h; k += 3)
        for (int i = 0; i < w; i += 3) {
            const double ground = heights[std::size_t(k * w + i)];
            for (int j = int(*lo / 5.0) - 10; j <= int(*hi / 5.0) + 10; ++j) {
                const double y = j * 5.0;
                if (std::abs(y - ground) < 0.5) continue;
                const float d = acc.getValue({i, j, k});
                ASSERT_EQ(d < 0, y < ground) << "wrong side at " << i << " " << j << " " << k << ": " << d;
                ASSERT_LE(std::abs(d), std::abs(y - ground) + 1e-3);  // never further than the vertical distance
                ++checked;
            }
        }
    EXPECT_GT(checked, 10000);
}

TEST(Vdb, TheSameDataGivesTheSameBytesAndOpenVdbStillReadsThem) {
    // OpenVDB stamps each file with a random UUID; orogen replaces it with one made from the content.
    test::TempDir dir;
    const int w = 49, h = 33;
    auto heights = test::hills(w, h, 120.0);
    vdb::write_terrain({heights.data(), w, h, 5.0}, nullptr, dir / "a.vdb");
    vdb::write_terrain({heights.data(), w, h, 5.0}, nullptr, dir / "b.vdb");
    const std::string a = test::slurp(dir / "a.vdb"), b = test::slurp(dir / "b.vdb");
    ASSERT_GT(a.size(), 57u);
    EXPECT_TRUE(a == b) << "two exports of the same terrain differ";
    heights[std::size_t(w * 10 + 10)] += 30.0f;
    vdb::write_terrain({heights.data(), w, h, 5.0}, nullptr, dir / "c.vdb");
    const std::string c = test::slurp(dir / "c.vdb");
    EXPECT_NE(a.substr(21, 36), c.substr(21, 36)) << "other data should get another UUID";
    EXPECT_EQ(a[21 + 14], '8') << "a version 8 (custom) UUID: " << a.substr(21, 36);
    // OpenVDB reads the file and its UUID back.
    vdb::initialize_once();
    openvdb::io::File f((dir / "c.vdb").string());
    f.open();
    EXPECT_EQ(f.getUniqueTag(), c.substr(21, 36));
    EXPECT_TRUE(float_grid(f.getGrids(), "surface"));
    f.close();
}

TEST(Vdb, VoxelSizeResamplesTheColumns) {
    test::TempDir dir;
    const int w = 33, h = 33;
    auto heights = test::hills(w, h);
    vdb::TerrainOptions o;
    o.voxel_size = 4.0;  // cell 2: column i is sample 2i
    vdb::write_terrain({heights.data(), w, h, 2.0}, nullptr, dir / "t.vdb", o);
    const auto grids = read_all(dir / "t.vdb");
    auto height = float_grid(grids, "height");
    ASSERT_TRUE(height);
    EXPECT_DOUBLE_EQ(height->voxelSize()[0], 4.0);
    EXPECT_EQ(height->activeVoxelCount(), openvdb::Index64(17 * 17));
    EXPECT_FLOAT_EQ(height->tree().getValue({5, 0, 7}), heights[14 * w + 10]);
    EXPECT_DOUBLE_EQ(float_grid(grids, "surface")->voxelSize()[0], 4.0);
}

TEST(Vdb, WaterLayerBecomesALevelSetOfTheWaterBody) {
    test::TempDir dir;
    const int w = 41, h = 41;
    std::vector<float> ground(std::size_t(w * h), 100.0f), water(std::size_t(w * h), 0.0f);
    for (int k = 10; k < 30; ++k)
        for (int i = 10; i < 30; ++i) {
            ground[std::size_t(k * w + i)] = 80.0f;  // a basin 20 m deep, flat
            water[std::size_t(k * w + i)] = 15.0f;  // water surface at 95 m
        }
    const ConstGridView wv(water.data(), w, h, 1.0);
    const auto s = vdb::write_terrain({ground.data(), w, h, 1.0}, &wv, dir / "t.vdb");
    EXPECT_GT(s.water_voxels, 0u);
    const auto grids = read_all(dir / "t.vdb");
    ASSERT_EQ(grids->size(), 3u);
    auto wgrid = float_grid(grids, "water");
    ASSERT_TRUE(wgrid);
    EXPECT_EQ(wgrid->getGridClass(), openvdb::GRID_LEVEL_SET);
    auto acc = wgrid->getConstAccessor();
    EXPECT_FLOAT_EQ(acc.getValue({20, 87, 20}), -3.0f);  // mid-lake, 7 m down: deep inside (clamped, flood-filled)
    EXPECT_NEAR(acc.getValue({20, 94, 20}), -1.0f, 1e-5);  // 1 m under the surface
    EXPECT_NEAR(acc.getValue({20, 96, 20}), 1.0f, 1e-5);  // 1 m above it
    EXPECT_NEAR(acc.getValue({20, 81, 20}), -1.0f, 1e-5);  // 1 m above the lake bed
    EXPECT_GT(acc.getValue({20, 78, 20}), 0.0f);  // in the ground: not water
    EXPECT_GT(acc.getValue({2, 100, 2}), 0.0f);  // a dry corner
    EXPECT_GT(acc.getValue({2, 90, 2}), 0.0f);
}

TEST(Vdb, ParticlesArePointsGridsWithTheirAttributes) {
    test::TempDir dir;
    ParticleSeries s;
    for (int f = 0; f < 2; ++f) {
        ParticleFrame fr;
        fr.time = 0.002 * f;
        fr.step = f;
        auto& pos = fr.attributes["position"];
        pos.components = 3;
        auto& vel = fr.attributes["velocity"];
        vel.components = 3;
        auto& rho = fr.attributes["density"];
        for (int i = 0; i < 50 + f * 10; ++i) {
            pos.data.insert(pos.data.end(), {float(i % 7), float(i / 7), 0.5f * float(i)});
            vel.data.insert(vel.data.end(), {float(i), 0.0f, 1.0f});
            rho.data.push_back(1000.0f + float(i));
        }
        s.frames.push_back(fr);
    }
    EXPECT_EQ(vdb::write_particles(s, dir / "sph.vdb"), 2u);
    EXPECT_EQ(test::folder_entries(dir.path()), (std::vector<std::string>{"sph_000000.vdb", "sph_000001.vdb"}));
    const auto grids = read_all(dir / "sph_000001.vdb");
    ASSERT_EQ(grids->size(), 1u);
    auto points = openvdb::gridPtrCast<openvdb::points::PointDataGrid>((*grids)[0]);
    ASSERT_TRUE(points);
    EXPECT_EQ(points->getName(), "particles");
    EXPECT_EQ(openvdb::points::pointCount(points->tree()), 60u);
    EXPECT_DOUBLE_EQ(points->metaValue<double>("time"), 0.002);
    auto leaf = points->tree().cbeginLeaf();
    ASSERT_TRUE(leaf);
    const auto& desc = leaf->attributeSet().descriptor();
    EXPECT_NE(desc.find("velocity"), openvdb::points::AttributeSet::INVALID_POS);
    EXPECT_EQ(desc.valueType(desc.find("velocity")), "vec3s");
    EXPECT_EQ(desc.valueType(desc.find("density")), "float");
    // Every particle's density and velocity arrive, whatever order the leaves hold them in.
    std::vector<float> densities;
    for (auto l = points->tree().cbeginLeaf(); l; ++l) {
        openvdb::points::AttributeHandle<float> rho(l->constAttributeArray("density"));
        openvdb::points::AttributeHandle<openvdb::Vec3f> vel(l->constAttributeArray("velocity"));
        for (auto idx = l->beginIndexOn(); idx; ++idx) {
            densities.push_back(rho.get(*idx));
            EXPECT_FLOAT_EQ(vel.get(*idx).x(), rho.get(*idx) - 1000.0f);
        }
    }
    std::sort(densities.begin(), densities.end());
    ASSERT_EQ(densities.size(), 60u);
    EXPECT_EQ(densities.front(), 1000.0f);
    EXPECT_EQ(densities.back(), 1059.0f);
}

TEST(Vdb, BadInputAndFailingWrites) {
    test::TempDir dir;
    auto heights = test::hills(9, 9);
    try {
        vdb::write_terrain({heights.data(), 9, 9, 1.0}, nullptr, dir / "t.vdbx");
        FAIL();
    } catch (const BadInput& e) {
        EXPECT_STREQ(e.what(), "export:vdb writes .vdb files; 't.vdbx' has another extension");
    }
    EXPECT_THROW(vdb::write_terrain({heights.data(), 9, 9, 1.0}, nullptr, test::unwritable_folder() / "t.vdb"), Error);
    EXPECT_FALSE(fs::exists(test::unwritable_folder() / "t.vdb"));
}

TEST(Vdb, FullDiskKeepsTheGoodFileAndLeavesNoTemporary) {
    test::TempDir dir;
    test::TinyDisk disk(dir / "tiny");
    OROGEN_SKIP_WITHOUT_TINY_DISK(disk);
    std::ofstream(disk.path() / "t.vdb") << "good";
    auto heights = test::hills(129, 129);
    EXPECT_THROW(vdb::write_terrain({heights.data(), 129, 129, 1.0}, nullptr, disk.path() / "t.vdb"), Error);
    EXPECT_EQ(test::folder_entries(disk.path()), (std::vector<std::string>{"t.vdb"}));
    EXPECT_EQ(test::file_text(disk.path() / "t.vdb"), "good");
}
