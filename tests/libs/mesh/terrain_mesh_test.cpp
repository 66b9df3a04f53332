// The mesh layout and splat colours shared by export:gltf and export:vtk.
#include <orogen/mesh/terrain_mesh.hpp>

#include "export_test_support.hpp"

#include <orogen/error.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

using namespace orogen;
using namespace orogen::mesh;

TEST(TerrainMesh, KeptIndicesKeepEveryKthAndTheLast) {
    EXPECT_EQ(kept_indices(10, 3), (std::vector<int>{0, 3, 6, 9}));
    EXPECT_EQ(kept_indices(11, 3), (std::vector<int>{0, 3, 6, 9, 10}));
    EXPECT_EQ(kept_indices(4, 1), (std::vector<int>{0, 1, 2, 3}));
    EXPECT_EQ(kept_indices(5, 100), (std::vector<int>{0, 4}));
}

TEST(TerrainMesh, AutomaticChunksOf4097SquaredFit16BitIndicesAndCoverEveryTileOnce) {
    // plan_mesh does not read samples, so no 64 MB grid is needed here.
    const ConstGridView big(nullptr, 4097, 4097, 10.0);
    const TerrainMesh mesh = plan_mesh(big, 1, 0, 1.0);
    std::size_t tiles = 0;
    std::vector<int> covered(std::size_t(4096) * 4096, 0);
    for (const auto& c : mesh.chunks) {
        EXPECT_TRUE(c.fits_16bit());
        EXPECT_LE(c.vertex_count(), 65535u);
        tiles += c.triangle_count() / 2;
        for (int r = c.row_begin; r < c.row_end; ++r)
            for (int q = c.column_begin; q < c.column_end; ++q) ++covered[std::size_t(r) * 4096 + std::size_t(q)];
    }
    EXPECT_EQ(tiles, std::size_t(4096) * 4096);
    EXPECT_TRUE(std::all_of(covered.begin(), covered.end(), [](int n) { return n == 1; }));
    // The fewest per side: one fewer chunk per side would overflow 16 bits.
    const int per_side = int(std::lround(std::sqrt(double(mesh.chunks.size()))));
    EXPECT_EQ(std::size_t(per_side) * std::size_t(per_side), mesh.chunks.size());
    const TerrainMesh fewer = plan_mesh(big, 1, per_side - 1, 1.0);
    EXPECT_FALSE(std::all_of(fewer.chunks.begin(), fewer.chunks.end(), [](const auto& c) { return c.fits_16bit(); }));
}

TEST(TerrainMesh, BadOptionsAreBadInput) {
    std::vector<float> h(4, 0.0f);
    const ConstGridView g(h.data(), 2, 2, 1.0);
    EXPECT_THROW(plan_mesh(g, 0, 1, 1.0), BadInput);
    EXPECT_THROW(plan_mesh(g, 1, -1, 1.0), BadInput);
    const ConstGridView line(h.data(), 4, 1, 1.0);
    EXPECT_THROW(plan_mesh(line, 1, 1, 1.0), BadInput);
}

TEST(TerrainMesh, TrianglesAreCounterClockwiseSeenFromAbove) {
    const int w = 33, h = 17;
    auto heights = test::hills(w, h);
    const ConstGridView g(heights.data(), w, h, 5.0);
    const TerrainMesh mesh = plan_mesh(g, 2, 2, 3.0);
    for (const auto& c : mesh.chunks) {
        std::vector<float> p(c.vertex_count() * 3);
        std::vector<std::uint32_t> idx(c.triangle_count() * 3);
        chunk_positions(mesh, c, p);
        chunk_indices(c, std::span<std::uint32_t>(idx));
        for (std::size_t t = 0; t < idx.size(); t += 3) {
            const float* a = &p[3 * idx[t]];
            const float* b = &p[3 * idx[t + 1]];
            const float* d = &p[3 * idx[t + 2]];
            const double ux = b[0] - a[0], uy = b[1] - a[1], uz = b[2] - a[2];
            const double vx = d[0] - a[0], vy = d[1] - a[1], vz = d[2] - a[2];
            const double ny = uz * vx - ux * vz;  // y of (b − a) × (d − a)
            ASSERT_GT(ny, 0.0) << "triangle " << t / 3 << " is clockwise or degenerate seen from +Y";
            (void)uy;
            (void)vy;
        }
    }
}

TEST(TerrainMesh, PositionsAreMetresYUpAndBoundsAreExact) {
    const int w = 9, h = 7;
    auto heights = test::hills(w, h);
    const ConstGridView g(heights.data(), w, h, 2.5);
    const TerrainMesh mesh = plan_mesh(g, 3, 1, 2.0);
    ASSERT_EQ(mesh.chunks.size(), 1u);
    const auto& c = mesh.chunks[0];
    EXPECT_EQ(mesh.columns, (std::vector<int>{0, 3, 6, 8}));
    EXPECT_EQ(mesh.rows, (std::vector<int>{0, 3, 6}));
    std::vector<float> p(c.vertex_count() * 3);
    chunk_positions(mesh, c, p);
    Bounds actual{{p[0], p[1], p[2]}, {p[0], p[1], p[2]}};
    for (std::size_t r = 0; r < mesh.rows.size(); ++r)
        for (std::size_t q = 0; q < mesh.columns.size(); ++q) {
            const float* v = &p[3 * (r * mesh.columns.size() + q)];
            EXPECT_FLOAT_EQ(v[0], float(mesh.columns[q] * 2.5));
            EXPECT_FLOAT_EQ(v[1], g.at(mesh.columns[q], mesh.rows[r]) * 2.0f);
            EXPECT_FLOAT_EQ(v[2], float(mesh.rows[r] * 2.5));
            for (int k = 0; k < 3; ++k) {
                actual.min[std::size_t(k)] = std::min(actual.min[std::size_t(k)], v[k]);
                actual.max[std::size_t(k)] = std::max(actual.max[std::size_t(k)], v[k]);
            }
        }
    const Bounds b = chunk_bounds(mesh, c);
    EXPECT_EQ(b.min, actual.min);  // bit-exact: glTF validators compare accessor bounds exactly
    EXPECT_EQ(b.max, actual.max);
}

TEST(TerrainMesh, NormalsOfAPlaneAreItsUnitNormal) {
    // h = 0.5·X − 0.25·Z (metres): normal ∝ (−0.5·s, 1, 0.25·s) with s the vertical scale.
    const int w = 6, h = 5;
    const double cell = 4.0, s = 2.0;
    std::vector<float> heights(std::size_t(w * h));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) heights[std::size_t(y * w + x)] = float(0.5 * x * cell - 0.25 * y * cell);
    const ConstGridView g(heights.data(), w, h, cell);
    const double len = std::sqrt(1.0 + 1.0 * s * s * 0.25 + s * s * 0.0625);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const auto n = surface_normal(g, x, y, s);
            EXPECT_NEAR(n[0], -0.5 * s / len, 1e-6);
            EXPECT_NEAR(n[1], 1.0 / len, 1e-6);
            EXPECT_NEAR(n[2], 0.25 * s / len, 1e-6);
        }
}

TEST(TerrainMesh, TexcoordsSpanTheWholeTerrainAcrossChunks) {
    const int w = 11, h = 11;
    auto heights = test::hills(w, h);
    const ConstGridView g(heights.data(), w, h, 1.0);
    const TerrainMesh mesh = plan_mesh(g, 1, 2, 1.0);
    ASSERT_EQ(mesh.chunks.size(), 4u);
    const auto& last = mesh.chunks.back();  // bottom-right chunk ends at u = v = 1
    std::vector<float> f(last.vertex_count() * 2);
    std::vector<std::uint16_t> q(last.vertex_count() * 2);
    chunk_texcoords(mesh, last, std::span<float>(f));
    chunk_texcoords(mesh, last, std::span<std::uint16_t>(q));
    EXPECT_FLOAT_EQ(f[0], 0.5f);
    EXPECT_FLOAT_EQ(f.back(), 1.0f);
    EXPECT_EQ(q.back(), 65535);
    EXPECT_EQ(q[0], 32768);  // 0.5 · 65535 rounded
}

TEST(TerrainMesh, ChunksShareTheirBorderVertices) {
    const int w = 9, h = 9;
    auto heights = test::hills(w, h);
    const ConstGridView g(heights.data(), w, h, 1.0);
    const TerrainMesh mesh = plan_mesh(g, 1, 2, 1.0);
    ASSERT_EQ(mesh.chunks.size(), 4u);
    EXPECT_EQ(mesh.chunks[0].column_end, mesh.chunks[1].column_begin);
    EXPECT_EQ(mesh.chunks[0].row_end, mesh.chunks[2].row_begin);
    EXPECT_EQ(mesh.vertex_count(), std::size_t(4 * 5 * 5));
    EXPECT_EQ(mesh.triangle_count(), std::size_t(2 * 8 * 8));
}

// ------------------------------------------------------------------ colour

TEST(Splat, HeightBandsFollowTheThesisQuarters) {
    const float lo = 100, hi = 500;  // δ = 100 m
    auto w = splat_weights(150, lo, hi, 1.0f);  // first quarter: sand
    EXPECT_EQ(w.sand, 1.0f);
    w = splat_weights(225, lo, hi, 1.0f);  // quarter of the way into grass's blend: half-way sand → grass
    EXPECT_NEAR(w.sand, 0.5f, 1e-6);
    EXPECT_NEAR(w.grass, 0.5f, 1e-6);
    w = splat_weights(280, lo, hi, 1.0f);  // second band, past its blend: grass
    EXPECT_EQ(w.grass, 1.0f);
    w = splat_weights(380, lo, hi, 1.0f);  // third: rock
    EXPECT_EQ(w.rock, 1.0f);
    w = splat_weights(500, lo, hi, 1.0f);  // top: snow
    EXPECT_EQ(w.snow, 1.0f);
    w = splat_weights(7, 7, 7, 1.0f);  // flat terrain: all sand, no division by zero
    EXPECT_EQ(w.sand, 1.0f);
}

TEST(Splat, SteepSlopesTurnGrassAndSnowToRock) {
    const float lo = 0, hi = 400;
    auto w = splat_weights(400, lo, hi, 0.8f);  // gentle: snow stays
    EXPECT_EQ(w.snow, 1.0f);
    w = splat_weights(400, lo, hi, 0.625f);  // half-way through the 0.25 blend band
    EXPECT_NEAR(w.snow, 0.5f, 1e-6);
    EXPECT_NEAR(w.rock, 0.5f, 1e-6);
    w = splat_weights(400, lo, hi, 0.4f);  // steeper than n_y 0.5: bare rock
    EXPECT_EQ(w.rock, 1.0f);
    w = splat_weights(180, lo, hi, 0.4f);  // grass on a cliff: rock
    EXPECT_EQ(w.rock, 1.0f);
    w = splat_weights(50, lo, hi, 0.3f);  // sand is not overridden (the thesis names grass and snow)
    EXPECT_EQ(w.sand, 1.0f);
    for (float h = 0; h <= 400; h += 7)
        for (float n = 0.2f; n <= 1.0f; n += 0.05f) {
            const auto s = splat_weights(h, lo, hi, n);
            EXPECT_NEAR(s.sand + s.grass + s.rock + s.snow, 1.0f, 1e-6);
        }
}

TEST(Splat, BakedTextureOfALowFlatTerrainIsSandAndOfAPeakHasSnowOnTop) {
    std::vector<float> flat(16 * 16, 3.0f);
    auto tex = bake_splat_texture(ConstGridView(flat.data(), 16, 16, 1.0), 8, 8);
    ASSERT_EQ(tex.size(), 8u * 8u * 4u);
    for (std::size_t i = 0; i < tex.size(); i += 4) {
        EXPECT_EQ(tex[i], sand_colour[0]);
        EXPECT_EQ(tex[i + 1], sand_colour[1]);
        EXPECT_EQ(tex[i + 2], sand_colour[2]);
        EXPECT_EQ(tex[i + 3], 255);
    }
    // A broad gentle dome, 1 km wide and 60 m high: the top is snow, the rim sand.
    const int n = 65;
    std::vector<float> dome(std::size_t(n * n));
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const double r = std::hypot(x - 32.0, y - 32.0) / 32.0;
            dome[std::size_t(y * n + x)] = float(60.0 * std::max(0.0, 1.0 - r * r));
        }
    tex = bake_splat_texture(ConstGridView(dome.data(), n, n, 1000.0 / 64), 64, 64);
    const std::uint8_t* centre = &tex[(32u * 64u + 32u) * 4u];
    const std::uint8_t* corner = &tex[0];
    EXPECT_EQ(centre[0], snow_colour[0]);
    EXPECT_EQ(corner[0], sand_colour[0]);
}
