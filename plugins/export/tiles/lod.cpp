#include "lod.hpp"

#include <orogen/mesh/terrain_mesh.hpp>
#include "tiles.hpp"

#include <orogen/error.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <sstream>
#include <tuple>

namespace orogen::lod {

namespace {

std::int64_t span_of(int tile_size, int level) { return std::int64_t(tile_size - 1) << level; }

std::int64_t chunks_along(int n, int tile_size, int level) {
    const std::int64_t s = span_of(tile_size, level);
    return std::max<std::int64_t>(1, (std::int64_t(n - 1) + s - 1) / s);
}

bool on_level(int x, int n, int level) { return x == n - 1 || (x & ((1 << level) - 1)) == 0; }

/// The indices into `xs` of the level's samples (in order).
std::vector<int> level_indices(const std::vector<int>& xs, int n, int level) {
    std::vector<int> out;
    for (std::size_t i = 0; i < xs.size(); ++i)
        if (on_level(xs[i], n, level)) out.push_back(int(i));
    return out;
}

/// Central difference (one-sided where the lattice ends) of f over positions, at entry k of `at` (indices into
/// the positions), per metre.
template <typename F>
double slope(const std::vector<int>& at, std::size_t k, const std::vector<int>& xs, double cell, F f) {
    const std::size_t a = k == 0 ? 0 : k - 1, b = std::min(k + 1, at.size() - 1);
    if (a == b) return 0.0;
    const int ia = at[a], ib = at[b];
    return (double(f(ia)) - double(f(ib))) / (double(xs[std::size_t(ia)] - xs[std::size_t(ib)]) * cell);
}

/// For every entry of `xs` in [lo, hi]: the level vertex at or before it (index into `verts`) and the
/// fraction of the way to the next.
struct Bracket {
    int vertex;
    double fraction;
};
std::vector<Bracket> brackets(const std::vector<int>& xs, const std::vector<int>& verts, int lo, int hi) {
    std::vector<Bracket> out(xs.size(), Bracket{-1, 0.0});
    std::size_t v = 0;
    for (std::size_t i = 0; i < xs.size(); ++i) {
        if (xs[i] < lo || xs[i] > hi) continue;
        while (v + 2 < verts.size() && xs[std::size_t(verts[v + 1])] <= xs[i]) ++v;
        const int a = xs[std::size_t(verts[v])], b = xs[std::size_t(verts[v + 1])];
        out[i] = {int(v), double(xs[i] - a) / double(b - a)};
    }
    return out;
}

}  // namespace

int level_count(int width, int height, int tile_size) {
    if (width < 2 || height < 2 || tile_size < 2)
        throw BadInput("a level-of-detail pyramid needs a grid of at least 2 × 2 samples and tiles of at least 2");
    int k = 0;
    while (chunks_along(width, tile_size, k) > 1 || chunks_along(height, tile_size, k) > 1) ++k;
    return k + 1;
}

std::vector<Chunk> pyramid(int width, int height, int tile_size, const std::string& stem) {
    std::vector<Chunk> out;
    const int levels = level_count(width, height, tile_size);
    for (int k = 0; k < levels; ++k) {
        const std::int64_t s = span_of(tile_size, k);
        for (std::int64_t r = 0; r < chunks_along(height, tile_size, k); ++r)
            for (std::int64_t c = 0; c < chunks_along(width, tile_size, k); ++c) {
                Chunk ch;
                ch.level = k;
                ch.column = int(c);
                ch.row = int(r);
                ch.x0 = int(c * s);
                ch.y0 = int(r * s);
                ch.x1 = int(std::min<std::int64_t>(ch.x0 + s, width - 1));
                ch.y1 = int(std::min<std::int64_t>(ch.y0 + s, height - 1));
                ch.file =
                    stem + "_l" + std::to_string(k) + "_x" + std::to_string(c) + "_y" + std::to_string(r) + ".glb";
                out.push_back(std::move(ch));
            }
    }
    return out;
}

AxisSamples level_samples(int n, int level, int a, int b) {
    const int s = 1 << level;
    AxisSamples out;
    out.step = s;
    out.first = (a + s - 1) / s * s;
    out.count = out.first <= b ? (b - out.first) / s + 1 : 0;
    if (b == n - 1 && (n - 1) % s != 0) out.last = n - 1;
    if (out.count == 0) out.first = 0;
    return out;
}

std::array<AxisSamples, 2> chunk_lattice(const Chunk& c, int width, int height) {
    const int s = 1 << c.level, m = std::max(c.level - 1, 0);
    return {level_samples(width, m, std::max(0, c.x0 - s), std::min(width - 1, c.x1 + s)),
            level_samples(height, m, std::max(0, c.y0 - s), std::min(height - 1, c.y1 + s))};
}

std::array<std::array<AxisSamples, 2>, 2> edge_lattices(const Chunk& c, int width, int height, int levels) {
    const std::int64_t s = std::int64_t(1) << (levels - 1);
    const auto widen = [&](int a, int b, int n) {  // [a, b] out to whole steps of the coarsest level
        const int lo = int(a / s * s);
        const int hi = int(std::min<std::int64_t>(n - 1, (b + s - 1) / s * s));
        return AxisSamples{lo, 1, hi - lo + 1, -1};
    };
    return {{{widen(c.x0, c.x1, width), AxisSamples{c.y0, c.y1 - c.y0, 2, -1}},
             {AxisSamples{c.x0, c.x1 - c.x0, 2, -1}, widen(c.y0, c.y1, height)}}};
}

double skirt_depth(const Chunk& c, const Samples& rows, const Samples& columns, int width, int height, int levels,
                   double cell, double vertical_scale) {
    double worst = 0.0;
    // One edge: values v(p) at positions first.. (full resolution), the chunk's part [lo, hi], n samples in all.
    const auto edge = [&](int first, int lo, int hi, int n, auto v) {
        for (int j = 1; j < levels; ++j) {
            const int s = 1 << j;
            for (int x = lo; x <= hi; ++x) {
                const int a = x / s * s;
                if (a == x || x == n - 1) continue;  // a vertex of level j
                const int b = std::min(a + s, n - 1);
                const double va = v(a - first), vb = v(b - first);
                const double line = va + (vb - va) * double(x - a) / double(b - a);
                worst = std::max(worst, std::abs(double(v(x - first)) - line));
            }
        }
    };
    for (std::size_t r = 0; r < 2; ++r)
        edge(rows.xs.front(), c.x0, c.x1, width, [&](int i) { return double(rows.at(std::size_t(i), r)); });
    for (std::size_t k = 0; k < 2; ++k)
        edge(columns.ys.front(), c.y0, c.y1, height, [&](int j) { return double(columns.at(k, std::size_t(j))); });
    return std::max(2.0 * worst * std::abs(vertical_scale), 0.01 * cell);
}

Mesh chunk_mesh(const Chunk& c, const Samples& s, int width, int height, double cell, double vertical_scale,
                double skirt) {
    // The level's samples in the lattice (border included) and, among them, the chunk's.
    const std::vector<int> lx = level_indices(s.xs, width, c.level), ly = level_indices(s.ys, height, c.level);
    std::size_t cx0 = 0, cy0 = 0;
    while (s.xs[std::size_t(lx[cx0])] < c.x0) ++cx0;
    while (s.ys[std::size_t(ly[cy0])] < c.y0) ++cy0;
    std::size_t nx = 0, ny = 0;
    while (cx0 + nx < lx.size() && s.xs[std::size_t(lx[cx0 + nx])] <= c.x1) ++nx;
    while (cy0 + ny < ly.size() && s.ys[std::size_t(ly[cy0 + ny])] <= c.y1) ++ny;
    if (nx < 2 || ny < 2) throw Error("internal error: a chunk with fewer than 2 × 2 vertices");

    Mesh m;
    const std::size_t grid = nx * ny, ring = 2 * (nx - 1) + 2 * (ny - 1);
    const std::size_t verts = grid + (skirt > 0 ? ring : 0);
    m.positions.resize(3 * verts);
    m.normals.resize(3 * verts);
    m.texcoords.resize(2 * verts);
    const double su = 65535.0 / double(c.x1 - c.x0), sv = 65535.0 / double(c.y1 - c.y0);
    for (std::size_t j = 0; j < ny; ++j) {
        const std::size_t kj = cy0 + j;
        const int y = s.ys[std::size_t(ly[kj])];
        for (std::size_t i = 0; i < nx; ++i) {
            const std::size_t ki = cx0 + i;
            const int x = s.xs[std::size_t(lx[ki])];
            const std::size_t v = j * nx + i;
            const double hgt = double(s.at(std::size_t(lx[ki]), std::size_t(ly[kj])));
            m.positions[3 * v] = float(double(x - c.x0) * cell);
            m.positions[3 * v + 1] = float(hgt * vertical_scale);
            m.positions[3 * v + 2] = float(double(y - c.y0) * cell);
            // Slopes of the scaled surface along +X and +Z over the level's neighbours, as surface_normal.
            const double gx =
                slope(lx, ki, s.xs, cell, [&](int a) { return s.at(std::size_t(a), std::size_t(ly[kj])); }) *
                vertical_scale;
            const double gz =
                slope(ly, kj, s.ys, cell, [&](int b) { return s.at(std::size_t(lx[ki]), std::size_t(b)); }) *
                vertical_scale;
            const double inv = 1.0 / std::sqrt(gx * gx + 1.0 + gz * gz);
            m.normals[3 * v] = float(-gx * inv);
            m.normals[3 * v + 1] = float(inv);
            m.normals[3 * v + 2] = float(-gz * inv);
            m.texcoords[2 * v] = std::uint16_t(std::lround(double(x - c.x0) * su));
            m.texcoords[2 * v + 1] = std::uint16_t(std::lround(double(y - c.y0) * sv));
        }
    }
    m.indices.reserve(6 * (nx - 1) * (ny - 1) + (skirt > 0 ? 6 * ring : 0));
    for (std::size_t j = 0; j + 1 < ny; ++j)
        for (std::size_t i = 0; i + 1 < nx; ++i) {
            const auto a = std::uint32_t(j * nx + i), b = a + 1, cc = std::uint32_t(a + nx), d = cc + 1;
            m.indices.insert(m.indices.end(), {a, cc, b, b, cc, d});  // counter-clockwise seen from +Y
        }
    if (skirt > 0) {
        // The edge ring, clockwise seen from above (north edge eastwards, east edge southwards, ...): each
        // edge a → b and its copy a' → b' below make the outward-facing triangles (a, b, a') and (b, b', a').
        std::vector<std::uint32_t> loop;
        for (std::size_t i = 0; i < nx; ++i) loop.push_back(std::uint32_t(i));
        for (std::size_t j = 1; j < ny; ++j) loop.push_back(std::uint32_t(j * nx + nx - 1));
        for (std::size_t i = nx - 1; i-- > 0;) loop.push_back(std::uint32_t((ny - 1) * nx + i));
        for (std::size_t j = ny - 1; j-- > 1;) loop.push_back(std::uint32_t(j * nx));
        for (std::size_t k = 0; k < ring; ++k) {
            const std::size_t from = loop[k], to = grid + k;
            for (int a = 0; a < 3; ++a) {
                m.positions[3 * to + std::size_t(a)] = m.positions[3 * from + std::size_t(a)];
                m.normals[3 * to + std::size_t(a)] = m.normals[3 * from + std::size_t(a)];
            }
            m.positions[3 * to + 1] = float(double(m.positions[3 * from + 1]) - skirt);
            m.texcoords[2 * to] = m.texcoords[2 * from];
            m.texcoords[2 * to + 1] = m.texcoords[2 * from + 1];
        }
        for (std::size_t k = 0; k < ring; ++k) {
            const std::uint32_t a = loop[k], b = loop[(k + 1) % ring];
            const auto a2 = std::uint32_t(grid + k), b2 = std::uint32_t(grid + (k + 1) % ring);
            m.indices.insert(m.indices.end(), {a, b, a2, b, b2, a2});
        }
    }
    m.min = {m.positions[0], m.positions[1], m.positions[2]};
    m.max = m.min;
    for (std::size_t v = 0; v < verts; ++v)
        for (std::size_t a = 0; a < 3; ++a) {
            m.min[a] = std::min(m.min[a], m.positions[3 * v + a]);
            m.max[a] = std::max(m.max[a], m.positions[3 * v + a]);
        }
    return m;
}

double deviation(const Chunk& c, const Samples& s, int width, int height, double vertical_scale) {
    if (c.level == 0) return 0.0;
    const std::vector<int> lx = level_indices(s.xs, width, c.level), ly = level_indices(s.ys, height, c.level);
    const std::vector<Bracket> bx = brackets(s.xs, lx, c.x0, c.x1), by = brackets(s.ys, ly, c.y0, c.y1);
    double worst = 0.0;
    for (std::size_t j = 0; j < s.ys.size(); ++j) {
        if (by[j].vertex < 0) continue;
        const auto ya = std::size_t(ly[std::size_t(by[j].vertex)]), yb = std::size_t(ly[std::size_t(by[j].vertex) + 1]);
        const double fy = by[j].fraction;
        for (std::size_t i = 0; i < s.xs.size(); ++i) {
            if (bx[i].vertex < 0) continue;
            const auto xa = std::size_t(lx[std::size_t(bx[i].vertex)]),
                       xb = std::size_t(lx[std::size_t(bx[i].vertex) + 1]);
            const double fx = bx[i].fraction;
            const double a = s.at(xa, ya), b = s.at(xb, ya), cc = s.at(xa, yb), d = s.at(xb, yb);
            // The cell's triangles (a, c, b) and (b, c, d) meet along the diagonal from b to c.
            const double surface =
                fx + fy <= 1.0 ? a + fx * (b - a) + fy * (cc - a) : d + (1.0 - fx) * (cc - d) + (1.0 - fy) * (b - d);
            worst = std::max(worst, std::abs(double(s.at(i, j)) - surface));
        }
    }
    return worst * std::abs(vertical_scale);
}

std::vector<std::uint8_t> chunk_texture(const Chunk& c, const Samples& s, double cell, float lo, float hi, int tw,
                                        int th) {
    if (tw < 1 || th < 1) throw Error("internal error: texture size must be positive");
    const auto every = [](std::size_t n) {  // every entry of a lattice
        std::vector<int> out(n);
        for (std::size_t i = 0; i < n; ++i) out[i] = int(i);
        return out;
    };
    const std::vector<int> all_x = every(s.xs.size()), all_y = every(s.ys.size());
    // Per pixel column (row): the lattice entry at or before its centre, the fraction to the next, and the
    // nearer of the two (whose slope the pixel takes: the texture is never finer than the samples).
    struct Place {
        std::size_t a, b, near;
        double f;
    };
    const auto places = [](const std::vector<int>& xs, int x0, int x1, int n) {
        std::vector<Place> out(static_cast<std::size_t>(n));
        for (int p = 0; p < n; ++p) {
            const double at = double(x0) + (double(p) + 0.5) / double(n) * double(x1 - x0);
            std::size_t a = std::size_t(std::upper_bound(xs.begin(), xs.end(), int(std::floor(at))) - xs.begin());
            a = std::min(a == 0 ? 0 : a - 1, xs.size() - 2);
            const double f = std::clamp((at - xs[a]) / double(xs[a + 1] - xs[a]), 0.0, 1.0);
            out[std::size_t(p)] = {a, a + 1, f < 0.5 ? a : a + 1, f};
        }
        return out;
    };
    const std::vector<Place> px = places(s.xs, c.x0, c.x1, tw), py = places(s.ys, c.y0, c.y1, th);
    std::vector<std::uint8_t> rgba(std::size_t(tw) * std::size_t(th) * 4);
    for (int j = 0; j < th; ++j) {
        const Place& q = py[std::size_t(j)];
        for (int i = 0; i < tw; ++i) {
            const Place& p = px[std::size_t(i)];
            const double height = (s.at(p.a, q.a) * (1 - p.f) + s.at(p.b, q.a) * p.f) * (1 - q.f) +
                (s.at(p.a, q.b) * (1 - p.f) + s.at(p.b, q.b) * p.f) * q.f;
            const double gx = slope(all_x, p.near, s.xs, cell, [&](int a) { return s.at(std::size_t(a), q.near); });
            const double gz = slope(all_y, q.near, s.ys, cell, [&](int b) { return s.at(p.near, std::size_t(b)); });
            const double ny = 1.0 / std::sqrt(gx * gx + 1.0 + gz * gz);  // the true terrain's slope
            const auto rgb = mesh::splat_colour(mesh::splat_weights(float(height), lo, hi, float(ny)));
            std::uint8_t* o = &rgba[(std::size_t(j) * std::size_t(tw) + std::size_t(i)) * 4];
            o[0] = rgb[0];
            o[1] = rgb[1];
            o[2] = rgb[2];
            o[3] = 255;
        }
    }
    return rgba;
}

std::array<double, 3> translation(const Chunk& c, double cell) {
    return {double(c.x0) * cell, 0.0, double(c.y0) * cell};
}

std::string tileset_json(const std::vector<Chunk>& chunks, const std::vector<Written>& written, int width, int height,
                         int tile_size, double cell, double vertical_scale) {
    using tiles_export::json_string;
    using tiles_export::number;
    if (chunks.empty() || written.size() != chunks.size()) throw Error("internal error: a tileset without its chunks");
    std::map<std::tuple<int, int, int>, std::size_t> at;  // (level, column, row) → index
    int top = 0;
    for (std::size_t i = 0; i < chunks.size(); ++i) {
        at[{chunks[i].level, chunks[i].column, chunks[i].row}] = i;
        top = std::max(top, chunks[i].level);
    }
    const auto children = [&](std::size_t i) {
        std::vector<std::size_t> out;
        const Chunk& c = chunks[i];
        if (c.level == 0) return out;
        for (int dr = 0; dr < 2; ++dr)
            for (int dc = 0; dc < 2; ++dc) {
                const auto it = at.find({c.level - 1, 2 * c.column + dc, 2 * c.row + dr});
                if (it != at.end()) out.push_back(it->second);
            }
        return out;
    };
    // Bottom-up (levels in increasing order): the error bound and the box (tileset frame: x, y, z min, then max).
    std::vector<double> error(chunks.size(), 0.0);
    std::vector<std::array<double, 6>> box(chunks.size());
    for (int level = 0; level <= top; ++level)
        for (std::size_t i = 0; i < chunks.size(); ++i) {
            if (chunks[i].level != level) continue;
            const auto t = translation(chunks[i], cell);
            const Written& w = written[i];
            std::array<double, 6> b = {t[0] + w.min[0], -(t[2] + double(w.max[2])), double(w.min[1]),
                                       t[0] + w.max[0], -(t[2] + double(w.min[2])), double(w.max[1])};
            double child_error = 0.0;
            for (std::size_t k : children(i)) {
                child_error = std::max(child_error, error[k]);
                for (int a = 0; a < 3; ++a) {
                    b[std::size_t(a)] = std::min(b[std::size_t(a)], box[k][std::size_t(a)]);
                    b[std::size_t(a) + 3] = std::max(b[std::size_t(a) + 3], box[k][std::size_t(a) + 3]);
                }
            }
            error[i] = w.deviation + child_error;
            box[i] = b;
        }
    std::ostringstream o;
    const std::function<void(std::size_t, int)> tile = [&](std::size_t i, int depth) {
        const std::string pad(std::size_t(2 * depth), ' ');
        const auto& b = box[i];
        o << pad << "{\"boundingVolume\": {\"box\": [" << number(0.5 * (b[0] + b[3])) << ", "
          << number(0.5 * (b[1] + b[4])) << ", " << number(0.5 * (b[2] + b[5])) << ", " << number(0.5 * (b[3] - b[0]))
          << ", 0, 0, 0, " << number(0.5 * (b[4] - b[1])) << ", 0, 0, 0, " << number(0.5 * (b[5] - b[2])) << "]},\n"
          << pad << " \"geometricError\": " << number(error[i])
          << ", \"refine\": \"REPLACE\", \"content\": {\"uri\": " << json_string(chunks[i].file) << "}";
        const auto kids = children(i);
        if (!kids.empty()) {
            o << ",\n" << pad << " \"children\": [\n";
            for (std::size_t k = 0; k < kids.size(); ++k) {
                tile(kids[k], depth + 1);
                o << (k + 1 < kids.size() ? ",\n" : "\n");
            }
            o << pad << " ]";
        }
        o << "}";
    };
    const std::size_t root = at.at({top, 0, 0});
    float lo = written[0].min[1], hi = written[0].max[1];
    for (const Written& w : written) lo = std::min(lo, w.min[1]), hi = std::max(hi, w.max[1]);
    o << "{\n\"asset\": {\"version\": \"1.1\", \"generator\": \"orogen export:tiles\"},\n"
      << "\"extras\": {\"orogen\": {\"width\": " << width << ", \"height\": " << height
      << ", \"cell_m\": " << number(cell) << ", \"tile_size\": " << tile_size << ", \"levels\": " << top + 1
      << ", \"vertical_scale\": " << number(vertical_scale)
      << ", \"frame\": \"x east, y north, z up, metres, origin at sample (0, 0); glTF content y up, z south\"}},\n"
      // Rendering nothing at all is off by the whole relief.
      << "\"geometricError\": " << number(std::max(2.0 * error[root], double(hi) - double(lo))) << ",\n"
      << "\"root\":\n";
    tile(root, 1);
    o << "\n}\n";
    return o.str();
}

}  // namespace orogen::lod
