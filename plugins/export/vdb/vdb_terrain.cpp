// The terrain as OpenVDB level sets (one of the two translation units that include OpenVDB).
//
// Speed: a 4097² terrain has ~10⁸ voxels in its narrow band, too many to set
// one by one through an accessor. Columns are taken in 8 × 8 blocks (one leaf
// node's footprint), each block fills its leaf nodes directly, and every row
// of blocks builds its leaves in parallel; the leaves are disjoint and go
// into the tree in a fixed order, so the result does not
// depend on the thread count. The file is written with OpenVDB's active-mask
// compression only: Blosc/LZ4 on signed distances saved little and cost ~1 s.
#include "vdb_writer.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/parallel.hpp>

#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <mutex>

namespace fs = std::filesystem;

namespace orogen::vdb {

void initialize_once() {
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
}

namespace {

using openvdb::Coord;
using openvdb::FloatGrid;
using openvdb::FloatTree;
using Leaf = FloatTree::LeafNodeType;
using openvdb::Index;

/// Heights at voxel columns: the heightmap itself when voxel = cell, else bilinear resampling.
struct Columns {
    ConstGridView grid;  ///< one sample per column, `cell` = voxel size
    std::vector<float> storage;

    float at(int i, int k) const {
        return grid.at(std::clamp(i, 0, grid.width - 1), std::clamp(k, 0, grid.height - 1));
    }
    /// Slopes (m/m) along X and Z, central differences (one-sided at the edges).
    std::pair<double, double> gradient(int i, int k) const {
        const int i0 = std::max(i - 1, 0), i1 = std::min(i + 1, grid.width - 1);
        const int k0 = std::max(k - 1, 0), k1 = std::min(k + 1, grid.height - 1);
        const double gx = i1 > i0 ? (double(at(i1, k)) - at(i0, k)) / ((i1 - i0) * grid.cell) : 0.0;
        const double gz = k1 > k0 ? (double(at(i, k1)) - at(i, k0)) / ((k1 - k0) * grid.cell) : 0.0;
        return {gx, gz};
    }
    /// Lowest and highest of the column and its 4 neighbours.
    std::pair<float, float> neighbourhood(int i, int k) const {
        const float c = at(i, k), a = at(i - 1, k), b = at(i + 1, k), d = at(i, k - 1), e = at(i, k + 1);
        return {std::min({c, a, b, d, e}), std::max({c, a, b, d, e})};
    }
};

Columns make_columns(ConstGridView h, double voxel) {
    Columns c;
    if (voxel == h.cell) {
        c.grid = h;
        return c;
    }
    const int nx = int(std::floor((h.width - 1) * h.cell / voxel + 1e-9)) + 1;
    const int nz = int(std::floor((h.height - 1) * h.cell / voxel + 1e-9)) + 1;
    c.storage.resize(std::size_t(nx) * std::size_t(nz));
    parallel_for(0, nz, 16, [&](std::int64_t k0, std::int64_t k1) {
        for (std::int64_t k = k0; k < k1; ++k)
            for (int i = 0; i < nx; ++i) {
                const double sx = std::min(i * voxel / h.cell, double(h.width - 1));
                const double sz = std::min(double(k) * voxel / h.cell, double(h.height - 1));
                const int x0 = std::min(int(sx), std::max(h.width - 2, 0)),
                          z0 = std::min(int(sz), std::max(h.height - 2, 0));
                const int x1 = std::min(x0 + 1, h.width - 1), z1 = std::min(z0 + 1, h.height - 1);
                const double fx = sx - x0, fz = sz - z0;
                c.storage[std::size_t(k) * std::size_t(nx) + std::size_t(i)] =
                    float((h.at(x0, z0) * (1 - fx) + h.at(x1, z0) * fx) * (1 - fz) +
                          (h.at(x0, z1) * (1 - fx) + h.at(x1, z1) * fx) * fz);
            }
    });
    c.grid = ConstGridView(c.storage.data(), nx, nz, voxel);
    return c;
}

/// Build a float grid from per-column voxel ranges [j0, j1] (empty if j0 > j1)
/// and per-voxel values: range(i, k) → std::pair<int, int>; value(i, k, j) →
/// float (the active voxels); inside(i, k, j) → bool decides the sign of the
/// leaves' inactive voxels (±background). With `fill_below`, everything under
/// the band, down to 4096 voxels under the lowest leaf, becomes inside tiles:
/// the ground under the band reads −background. (OpenVDB's signedFloodFill guesses signs along scanlines,
/// which goes wrong at the open edges of a heightfield; here they are known.)
template <typename Range, typename Value, typename Inside>
FloatGrid::Ptr build(int nx, int nz, float background, const Range& range, const Value& value, const Inside& inside,
                     bool fill_below, std::size_t& active) {
    const int blocks_x = (nx + 7) / 8, blocks_z = (nz + 7) / 8;
    std::vector<std::vector<Leaf*>> parts(static_cast<std::size_t>(blocks_z));
    std::vector<std::size_t> counts(static_cast<std::size_t>(blocks_z), 0);
    std::vector<int> lowest_leaf(std::size_t(blocks_x) * std::size_t(blocks_z), INT_MAX);
    parallel_for(0, blocks_z, 1, [&](std::int64_t b0, std::int64_t b1) {
        for (std::int64_t bz = b0; bz < b1; ++bz) {
            std::vector<Leaf*> leaves;
            std::size_t count = 0;
            int lo[64], hi[64];
            for (int bx = 0; bx < blocks_x; ++bx) {
                int jmin = INT_MAX, jmax = INT_MIN;
                for (int c = 0; c < 64; ++c) {
                    const int i = bx * 8 + (c & 7), k = int(bz) * 8 + (c >> 3);
                    lo[c] = 1;
                    hi[c] = 0;
                    if (i >= nx || k >= nz) continue;
                    std::tie(lo[c], hi[c]) = range(i, k);
                    if (lo[c] > hi[c]) continue;
                    jmin = std::min(jmin, lo[c]);
                    jmax = std::max(jmax, hi[c]);
                }
                if (jmin > jmax) continue;
                lowest_leaf[std::size_t(bz) * std::size_t(blocks_x) + std::size_t(bx)] = (jmin >> 3) << 3;
                for (int jl = (jmin >> 3) << 3; jl <= jmax; jl += 8) {
                    auto leaf = std::make_unique<Leaf>(Coord(bx * 8, jl, int(bz) * 8), background, false);
                    float* values = leaf->buffer().data();
                    auto& mask = leaf->getValueMask();
                    for (int c = 0; c < 64; ++c) {
                        const int i = bx * 8 + (c & 7), k = int(bz) * 8 + (c >> 3);
                        // Leaf offset of (i, j, k): x·64 + y·8 + z in leaf-local coordinates.
                        const Index column = Index(c & 7) << 6 | Index(c >> 3);
                        for (int j = jl; j < jl + 8; ++j) {
                            const Index offset = column | Index(j - jl) << 3;
                            if (j >= lo[c] && j <= hi[c]) {
                                values[offset] = value(i, k, j);
                                mask.setOn(offset);
                                ++count;
                            } else {
                                values[offset] = inside(i, k, j) ? -background : background;
                            }
                        }
                    }
                    if (!mask.isOff()) leaves.push_back(leaf.release());
                }
            }
            parts[std::size_t(bz)] = std::move(leaves);
            counts[std::size_t(bz)] = count;
        }
    });
    auto grid = FloatGrid::create(background);
    // Hand the leaves to the one tree in a fixed order (each insert is a pointer
    // store; merging per-thread trees cost more than building them).
    for (auto& part : parts)
        for (Leaf* leaf : part) grid->tree().addLeaf(leaf);
    if (fill_below) {
        // Under each column block's lowest leaf down to the lowest leaf anywhere,
        // then 4096 voxels deeper under the whole terrain: inside tiles.
        const int floor_j = *std::min_element(lowest_leaf.begin(), lowest_leaf.end());
        auto& tree = grid->tree();
        for (int bz = 0; bz < blocks_z; ++bz)
            for (int bx = 0; bx < blocks_x; ++bx) {
                const int top = lowest_leaf[std::size_t(bz) * std::size_t(blocks_x) + std::size_t(bx)];
                if (top != INT_MAX && top > floor_j)
                    tree.fill(
                        openvdb::CoordBBox(Coord(bx * 8, floor_j, bz * 8), Coord(bx * 8 + 7, top - 1, bz * 8 + 7)),
                        -background, false);
            }
        tree.fill(
            openvdb::CoordBBox(Coord(0, floor_j - 4096, 0), Coord(blocks_x * 8 - 1, floor_j - 1, blocks_z * 8 - 1)),
            -background, false);
    }
    active = 0;
    for (auto n : counts) active += n;
    return grid;
}

int floor_div(double y, double v) { return int(std::ceil(y / v - 1e-9)); }  // first voxel at or above y
int ceil_div(double y, double v) { return int(std::floor(y / v + 1e-9)); }  // last voxel at or below y

}  // namespace

TerrainSummary write_terrain(ConstGridView heights, const ConstGridView* water, const fs::path& target,
                             const TerrainOptions& o) {
    if (target.extension() != ".vdb")
        throw BadInput("export:vdb writes .vdb files; '" + target.filename().string() + "' has another extension");
    if (heights.width < 2 || heights.height < 2)
        throw BadInput("a level set needs at least 2 x 2 samples, the heightmap has " + std::to_string(heights.width) +
                       " x " + std::to_string(heights.height));
    const double v = o.voxel_size > 0 ? o.voxel_size : heights.cell;
    if (!(o.half_width >= 1.0)) throw BadInput("half_width must be at least 1 voxel");
    initialize_once();

    const Columns col = make_columns(heights, v);
    const int nx = col.grid.width, nz = col.grid.height;
    const double band = o.half_width * v;  // metres
    const float background = float(band);
    auto transform = openvdb::math::Transform::createLinearTransform(v);
    TerrainSummary summary;
    summary.voxel_size = v;

    // Surface: d = (y − H)·cos(slope), clamped to ±band; voxels with |d| < band,
    // and no further than the neighbours' heights ± band (cliffs stay finite).
    // cos(slope) per column, computed once (a column has ~2·half_width voxels).
    std::vector<float> cos_slope(std::size_t(nx) * std::size_t(nz));
    parallel_for(0, nz, 16, [&](std::int64_t k0, std::int64_t k1) {
        for (std::int64_t k = k0; k < k1; ++k)
            for (int i = 0; i < nx; ++i) {
                const auto [gx, gz] = col.gradient(i, int(k));
                cos_slope[std::size_t(k) * std::size_t(nx) + std::size_t(i)] =
                    float(1.0 / std::sqrt(1.0 + gx * gx + gz * gz));
            }
    });
    auto cos_at = [&](int i, int k) { return double(cos_slope[std::size_t(k) * std::size_t(nx) + std::size_t(i)]); };
    auto surface_range = [&](int i, int k) {
        const double h = col.at(i, k);
        const double reach = band / cos_at(i, k);
        const auto [nlo, nhi] = col.neighbourhood(i, k);
        const double lo = std::max(h - reach, double(nlo) - band), hi = std::min(h + reach, double(nhi) + band);
        return std::pair<int, int>{floor_div(lo, v), ceil_div(hi, v)};
    };
    auto surface_value = [&](int i, int k, int j) {
        const double d = (j * v - double(col.at(i, k))) * cos_at(i, k);
        return float(std::clamp(d, -band, band));
    };
    auto below_ground = [&](int i, int k, int j) {
        return j * v < double(col.at(i, k));  // columns past the edge: the edge's height (Columns::at clamps)
    };
    auto surface = build(nx, nz, background, surface_range, surface_value, below_ground, true, summary.surface_voxels);
    surface->setName("surface");
    surface->setGridClass(openvdb::GRID_LEVEL_SET);
    surface->setTransform(transform->copy());
    surface->setSaveFloatAsHalf(o.half_float);
    surface->insertMeta("units", openvdb::StringMetadata("m"));

    std::size_t height_voxels = 0;
    auto height = build(
        nx, nz, 0.0f,
        [](int, int) {
            return std::pair<int, int>{0, 0};
        },
        [&](int i, int k, int) { return col.at(i, k); }, [](int, int, int) { return false; }, false, height_voxels);
    height->setName("height");
    height->setGridClass(openvdb::GRID_UNKNOWN);
    height->setTransform(transform->copy());
    height->setSaveFloatAsHalf(false);  // metres of elevation need 32 bits (half has 11)
    height->insertMeta("units", openvdb::StringMetadata("m"));

    openvdb::GridCPtrVec grids{surface, height};

    Columns wcol;
    if (water) {
        if (water->width != heights.width || water->height != heights.height)
            throw Error("internal error: the water layer's size differs from the heightmap's");
        wcol = make_columns(*water, v);
        auto wet = [&](int i, int k) { return wcol.at(i, k) > o.water_min; };
        auto near_wet = [&](int i, int k) {
            return wet(i, k) || wet(i - 1, k) || wet(i + 1, k) || wet(i, k - 1) || wet(i, k + 1);
        };
        auto top = [&](int i, int k) { return double(col.at(i, k)) + double(wcol.at(i, k)); };
        auto top_cos = [&](int i, int k) {
            const double gx = (top(std::min(i + 1, nx - 1), k) - top(std::max(i - 1, 0), k)) /
                (std::max(1, std::min(i + 1, nx - 1) - std::max(i - 1, 0)) * v);
            const double gz = (top(i, std::min(k + 1, nz - 1)) - top(i, std::max(k - 1, 0))) /
                (std::max(1, std::min(k + 1, nz - 1) - std::max(k - 1, 0)) * v);
            return 1.0 / std::sqrt(1.0 + gx * gx + gz * gz);
        };
        // The water body lies between the ground B and the water surface T:
        // d = max((y − T)·cos_T, (B − y)·cos_B), negative inside.
        auto water_range = [&](int i, int k) {
            if (!near_wet(i, k)) return std::pair<int, int>{1, 0};
            const double b = col.at(i, k), t = top(i, k);
            const double lo = b - band / cos_at(i, k);
            const double hi = t + band / top_cos(i, k);
            const auto [nlo, nhi] = col.neighbourhood(i, k);
            return std::pair<int, int>{floor_div(std::max(lo, double(nlo) - band), v),
                                       ceil_div(std::min(hi, std::max(t, double(nhi)) + band), v)};
        };
        auto water_value = [&](int i, int k, int j) {
            const double y = j * v, b = col.at(i, k), t = top(i, k);
            const double d = std::max((y - t) * top_cos(i, k), (b - y) * cos_at(i, k));
            return float(std::clamp(d, -band, band));
        };
        auto in_water = [&](int i, int k, int j) {
            const double y = j * v;
            return wet(i, k) && y > double(col.at(i, k)) && y < top(i, k);
        };
        auto w = build(nx, nz, background, water_range, water_value, in_water, false, summary.water_voxels);
        w->setName("water");
        w->setGridClass(openvdb::GRID_LEVEL_SET);
        w->setTransform(transform->copy());
        w->setSaveFloatAsHalf(o.half_float);
        w->insertMeta("units", openvdb::StringMetadata("m"));
        grids.push_back(w);
    }

    AtomicFile file(target);
    try {
        openvdb::MetaMap meta;
        meta.insertMeta("creator", openvdb::StringMetadata("orogen export:vdb"));
        openvdb::io::Stream stream(file.stream());
        stream.setCompression(openvdb::io::COMPRESS_ACTIVE_MASK);
        stream.write(grids, meta);
    } catch (const openvdb::Exception& e) { throw Error("cannot write " + target.string() + ": OpenVDB: " + e.what()); }
    stamp_content_uuid(file);
    file.commit();  // checks the stream: a full disk is an error, the old file stays
    return summary;
}

}  // namespace orogen::vdb
