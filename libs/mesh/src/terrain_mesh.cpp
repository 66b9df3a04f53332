#include <orogen/mesh/terrain_mesh.hpp>

#include <orogen/error.hpp>
#include <orogen/parallel.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace orogen::mesh {

std::vector<int> kept_indices(int n, int step) {
    if (n < 1 || step < 1) throw Error("kept_indices: need n >= 1 and step >= 1");
    std::vector<int> kept;
    kept.reserve(std::size_t(n / step + 2));
    for (int i = 0; i < n; i += step) kept.push_back(i);
    if (kept.back() != n - 1) kept.push_back(n - 1);
    return kept;
}

std::size_t TerrainMesh::vertex_count() const {
    std::size_t n = 0;
    for (const auto& c : chunks) n += c.vertex_count();
    return n;
}

std::size_t TerrainMesh::triangle_count() const {
    std::size_t n = 0;
    for (const auto& c : chunks) n += c.triangle_count();
    return n;
}

namespace {

/// Split `tiles` tiles into `parts` nearly equal runs: boundary i at i·tiles/parts.
std::vector<int> split(int tiles, int parts) {
    std::vector<int> b(std::size_t(parts) + 1);
    for (int i = 0; i <= parts; ++i) b[std::size_t(i)] = int(std::int64_t(i) * tiles / parts);
    return b;
}

std::size_t largest_chunk_vertices(int column_tiles, int row_tiles, int per_side) {
    const int cx = std::min(per_side, column_tiles), cy = std::min(per_side, row_tiles);
    const std::size_t w = std::size_t((column_tiles + cx - 1) / cx) + 1;
    const std::size_t h = std::size_t((row_tiles + cy - 1) / cy) + 1;
    return w * h;
}

}  // namespace

TerrainMesh plan_mesh(ConstGridView heights, int decimate, int chunks, double vertical_scale) {
    if (heights.width < 2 || heights.height < 2)
        throw BadInput("a mesh needs at least 2 x 2 samples, the heightmap has " + std::to_string(heights.width) +
                       " x " + std::to_string(heights.height));
    if (decimate < 1)
        throw BadInput("decimate must be at least 1 (1 keeps every vertex), got " + std::to_string(decimate));
    if (chunks < 0) throw BadInput("chunks must be 0 (automatic) or at least 1, got " + std::to_string(chunks));
    TerrainMesh mesh;
    mesh.heights = heights;
    mesh.vertical_scale = vertical_scale;
    mesh.columns = kept_indices(heights.width, decimate);
    mesh.rows = kept_indices(heights.height, decimate);
    const int column_tiles = int(mesh.columns.size()) - 1;
    const int row_tiles = int(mesh.rows.size()) - 1;
    int per_side = chunks;
    if (per_side == 0) {
        per_side = 1;
        while (largest_chunk_vertices(column_tiles, row_tiles, per_side) > max_16bit_vertices) ++per_side;
    }
    const auto bx = split(column_tiles, std::min(per_side, column_tiles));
    const auto by = split(row_tiles, std::min(per_side, row_tiles));
    for (std::size_t j = 0; j + 1 < by.size(); ++j)
        for (std::size_t i = 0; i + 1 < bx.size(); ++i) mesh.chunks.push_back({bx[i], bx[i + 1], by[j], by[j + 1]});
    return mesh;
}

std::array<float, 3> surface_normal(ConstGridView h, int x, int y, double vertical_scale) {
    const int x0 = std::max(x - 1, 0), x1 = std::min(x + 1, h.width - 1);
    const int y0 = std::max(y - 1, 0), y1 = std::min(y + 1, h.height - 1);
    // Slopes of the scaled surface, m per m, along +X (east) and +Z (south).
    const double gx = (double(h.at(x1, y)) - double(h.at(x0, y))) * vertical_scale / (double(x1 - x0) * h.cell);
    const double gz = (double(h.at(x, y1)) - double(h.at(x, y0))) * vertical_scale / (double(y1 - y0) * h.cell);
    const double inv = 1.0 / std::sqrt(gx * gx + 1.0 + gz * gz);
    return {float(-gx * inv), float(inv), float(-gz * inv)};
}

Bounds chunk_bounds(const TerrainMesh& mesh, const MeshChunk& chunk) {
    Bounds b;
    const int xa = mesh.columns[std::size_t(chunk.column_begin)], xb = mesh.columns[std::size_t(chunk.column_end)];
    const int ya = mesh.rows[std::size_t(chunk.row_begin)], yb = mesh.rows[std::size_t(chunk.row_end)];
    b.min[0] = position(mesh, xa, ya)[0];
    b.max[0] = position(mesh, xb, ya)[0];
    b.min[2] = position(mesh, xa, ya)[2];
    b.max[2] = position(mesh, xa, yb)[2];
    float lo = position(mesh, xa, ya)[1], hi = lo;
    for (int r = chunk.row_begin; r <= chunk.row_end; ++r)
        for (int c = chunk.column_begin; c <= chunk.column_end; ++c) {
            const float v = position(mesh, mesh.columns[std::size_t(c)], mesh.rows[std::size_t(r)])[1];
            lo = std::min(lo, v);
            hi = std::max(hi, v);
        }
    b.min[1] = lo;
    b.max[1] = hi;
    return b;
}

namespace {

/// Call f(vertex_index, x, y) for every vertex of a chunk, rows in parallel.
template <typename F>
void for_each_vertex(const TerrainMesh& mesh, const MeshChunk& chunk, F&& f) {
    const int w = chunk.vertex_columns();
    parallel_for(0, chunk.vertex_rows(), 16, [&](std::int64_t r0, std::int64_t r1) {
        for (std::int64_t r = r0; r < r1; ++r) {
            const int y = mesh.rows[std::size_t(chunk.row_begin + r)];
            for (int c = 0; c < w; ++c)
                f(std::size_t(r) * std::size_t(w) + std::size_t(c), mesh.columns[std::size_t(chunk.column_begin + c)],
                  y);
        }
    });
}

void check_size(std::size_t have, std::size_t want, const char* what) {
    if (have != want)
        throw Error(std::string("internal error: ") + what + " buffer holds " + std::to_string(have) +
                    " values, needs " + std::to_string(want));
}

template <typename Index>
void indices_impl(const MeshChunk& chunk, std::span<Index> out) {
    check_size(out.size(), chunk.triangle_count() * 3, "index");
    const int w = chunk.vertex_columns();
    const int tiles_x = w - 1;
    parallel_for(0, chunk.vertex_rows() - 1, 16, [&](std::int64_t r0, std::int64_t r1) {
        for (std::int64_t r = r0; r < r1; ++r) {
            std::size_t o = std::size_t(r) * std::size_t(tiles_x) * 6;
            for (int c = 0; c < tiles_x; ++c) {
                const auto a = Index(std::size_t(r) * std::size_t(w) + std::size_t(c));
                const auto b = Index(a + 1);
                const auto cc = Index(a + w);
                const auto d = Index(cc + 1);
                out[o++] = a;  // (a, c, b): counter-clockwise seen from +Y
                out[o++] = cc;
                out[o++] = b;
                out[o++] = b;  // (b, c, d)
                out[o++] = cc;
                out[o++] = d;
            }
        }
    });
}

}  // namespace

void chunk_positions(const TerrainMesh& mesh, const MeshChunk& chunk, std::span<float> out) {
    check_size(out.size(), chunk.vertex_count() * 3, "position");
    for_each_vertex(mesh, chunk, [&](std::size_t i, int x, int y) {
        const auto p = position(mesh, x, y);
        out[3 * i] = p[0];
        out[3 * i + 1] = p[1];
        out[3 * i + 2] = p[2];
    });
}

void chunk_normals(const TerrainMesh& mesh, const MeshChunk& chunk, std::span<float> out) {
    check_size(out.size(), chunk.vertex_count() * 3, "normal");
    for_each_vertex(mesh, chunk, [&](std::size_t i, int x, int y) {
        const auto n = surface_normal(mesh.heights, x, y, mesh.vertical_scale);
        out[3 * i] = n[0];
        out[3 * i + 1] = n[1];
        out[3 * i + 2] = n[2];
    });
}

void chunk_texcoords(const TerrainMesh& mesh, const MeshChunk& chunk, std::span<float> out) {
    check_size(out.size(), chunk.vertex_count() * 2, "texcoord");
    const double su = 1.0 / double(mesh.heights.width - 1), sv = 1.0 / double(mesh.heights.height - 1);
    for_each_vertex(mesh, chunk, [&](std::size_t i, int x, int y) {
        out[2 * i] = float(double(x) * su);
        out[2 * i + 1] = float(double(y) * sv);
    });
}

void chunk_texcoords(const TerrainMesh& mesh, const MeshChunk& chunk, std::span<std::uint16_t> out) {
    check_size(out.size(), chunk.vertex_count() * 2, "texcoord");
    const double su = 65535.0 / double(mesh.heights.width - 1), sv = 65535.0 / double(mesh.heights.height - 1);
    for_each_vertex(mesh, chunk, [&](std::size_t i, int x, int y) {
        out[2 * i] = std::uint16_t(std::lround(double(x) * su));
        out[2 * i + 1] = std::uint16_t(std::lround(double(y) * sv));
    });
}

void chunk_indices(const MeshChunk& chunk, std::span<std::uint32_t> out) { indices_impl(chunk, out); }

void chunk_indices(const MeshChunk& chunk, std::span<std::uint16_t> out) {
    if (!chunk.fits_16bit())
        throw Error("internal error: a chunk of " + std::to_string(chunk.vertex_count()) +
                    " vertices needs 32-bit indices");
    indices_impl(chunk, out);
}

// ------------------------------------------------------------------ colour

SplatWeights splat_weights(float height, float min_height, float max_height, float normal_y, const SplatRules& rules) {
    // Height bands: t in [0, 1] across the terrain's range; band k starts at start[k].
    const float range = max_height - min_height;
    const float t = range > 0 ? std::clamp((height - min_height) / range, 0.0f, 1.0f) : 0.0f;
    const float start[5] = {0.0f, rules.band_start[0], rules.band_start[1], rules.band_start[2], 1.0f};
    float w[4] = {0, 0, 0, 0};  // sand, grass, rock, snow
    const int k = t >= start[3] ? 3 : t >= start[2] ? 2 : t >= start[1] ? 1 : 0;
    const float blend = rules.blend_fraction * (start[k + 1] - start[k]);
    const float into = t - start[k];  // how far into band k
    if (k == 0 || into >= blend) {
        w[k] = 1;
    } else {
        const float f = into / blend;
        w[k - 1] = 1 - f;
        w[k] = f;
    }
    // Slope: grass and snow do not hold on steep ground; they turn to rock
    // between n_y = slope_start and slope_full.
    const float steep = std::clamp((rules.slope_start - normal_y) / (rules.slope_start - rules.slope_full), 0.0f, 1.0f);
    const float moved = steep * (w[1] + w[3]);
    w[1] *= 1 - steep;
    w[3] *= 1 - steep;
    w[2] += moved;
    return {w[0], w[1], w[2], w[3]};
}

void validate(const SplatRules& r) {
    const auto& b = r.band_start;
    if (!(0 < b[0] && b[0] < b[1] && b[1] < b[2] && b[2] < 1))
        throw BadInput(
            "splatting: the bands must start in increasing order between 0 and 1 (grass < rock < snow), got " +
            std::to_string(b[0]) + ", " + std::to_string(b[1]) + ", " + std::to_string(b[2]));
    if (!(r.blend_fraction >= 0 && r.blend_fraction <= 1))
        throw BadInput("splatting: the blend fraction must be in [0, 1], got " + std::to_string(r.blend_fraction));
    if (!(0 <= r.slope_full && r.slope_full < r.slope_start && r.slope_start <= 1))
        throw BadInput(
            "splatting: rock must start covering at a flatter slope than it covers fully (0 ≤ slope_full < "
            "slope_start ≤ 1, normal y), got " +
            std::to_string(r.slope_start) + " and " + std::to_string(r.slope_full));
}

std::array<std::uint8_t, 3> splat_colour(const SplatWeights& w) {
    std::array<std::uint8_t, 3> rgb{};
    for (int c = 0; c < 3; ++c) {
        const float v = w.sand * float(sand_colour[std::size_t(c)]) + w.grass * float(grass_colour[std::size_t(c)]) +
            w.rock * float(rock_colour[std::size_t(c)]) + w.snow * float(snow_colour[std::size_t(c)]);
        rgb[std::size_t(c)] = std::uint8_t(std::clamp(std::lround(v), 0L, 255L));
    }
    return rgb;
}

std::vector<std::uint8_t> bake_splat_texture(ConstGridView h, int tw, int th) {
    if (tw < 1 || th < 1) throw Error("internal error: texture size must be positive");
    float lo = h.data[0], hi = h.data[0];
    for (float v : h.span()) {
        lo = std::min(lo, v);
        hi = std::max(hi, v);
    }
    std::vector<std::uint8_t> rgba(std::size_t(tw) * std::size_t(th) * 4);
    parallel_for(0, th, 8, [&](std::int64_t j0, std::int64_t j1) {
        for (std::int64_t j = j0; j < j1; ++j) {
            // Pixel centre → sample coordinates; the texture spans sample 0 to width−1 (u 0..1).
            const double sy = std::clamp((double(j) + 0.5) / th * (h.height - 1), 0.0, double(h.height - 1));
            const int y0 = std::min(int(sy), std::max(h.height - 2, 0));
            const int y1 = std::min(y0 + 1, h.height - 1);
            const double fy = sy - y0;
            for (int i = 0; i < tw; ++i) {
                const double sx = std::clamp((double(i) + 0.5) / tw * (h.width - 1), 0.0, double(h.width - 1));
                const int x0 = std::min(int(sx), std::max(h.width - 2, 0));
                const int x1 = std::min(x0 + 1, h.width - 1);
                const double fx = sx - x0;
                auto lerp2 = [&](double a, double b, double c, double d) {
                    return (a * (1 - fx) + b * fx) * (1 - fy) + (c * (1 - fx) + d * fx) * fy;
                };
                const double height = lerp2(h.at(x0, y0), h.at(x1, y0), h.at(x0, y1), h.at(x1, y1));
                // Slope at the nearest sample: the texture is never finer than the tiles.
                const double ny = surface_normal(h, int(std::lround(sx)), int(std::lround(sy)), 1.0)[1];
                const auto rgb = splat_colour(splat_weights(float(height), lo, hi, float(ny)));
                std::uint8_t* p = &rgba[(std::size_t(j) * std::size_t(tw) + std::size_t(i)) * 4];
                p[0] = rgb[0];
                p[1] = rgb[1];
                p[2] = rgb[2];
                p[3] = 255;
            }
        }
    });
    return rgba;
}

}  // namespace orogen::mesh
