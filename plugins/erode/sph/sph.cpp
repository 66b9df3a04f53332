// sph.cpp — see sph.hpp for the model.
#include "sph.hpp"

#include <orogen/error.hpp>
#include <orogen/parallel.hpp>
#include <orogen/random.hpp>
#include <orogen/values.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <array>
#include <numbers>
#include <sstream>

namespace orogen::sph {

namespace {

constexpr std::int64_t kGrain = 512;       // particles per parallel task
constexpr std::int64_t kReorderEvery = 8;  // sub-steps between Morton reorders
constexpr int kCellBias = 1 << 20;         // keeps cell coordinates non-negative

/// Spread the low 10 bits of v over every third bit (30-bit Morton codes).
std::uint32_t spread3(std::uint32_t v) {
    v &= 0x3FFu;
    v = (v | (v << 16)) & 0x030000FFu;
    v = (v | (v << 8)) & 0x0300F00Fu;
    v = (v | (v << 4)) & 0x030C30C3u;
    v = (v | (v << 2)) & 0x09249249u;
    return v;
}

std::uint32_t morton(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
    return spread3(x) | (spread3(y) << 1) | (spread3(z) << 2);
}

/// Bucket of cell (cx, cy, cz) in a table of 2^bits ≥ 64 buckets. The low 6
/// bits are the cell's coordinates mod 4, so the 27 cells around any cell land
/// in 27 different buckets (no duplicate visits, no check needed); the other
/// bits hash the 4³ block, so buckets fill evenly however the particles lie.
std::uint32_t bucket_of(std::uint32_t cx, std::uint32_t cy, std::uint32_t cz, std::uint32_t mask) {
    const std::uint32_t low = ((cx & 3u) << 4) | ((cy & 3u) << 2) | (cz & 3u);
    const std::uint32_t block = ((cx >> 2) * 73856093u) ^ ((cy >> 2) * 19349663u) ^ ((cz >> 2) * 83492791u);
    return ((block << 6) | low) & mask;
}

bool finite3(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

}  // namespace

struct Simulation::Impl {
    Settings s;
    // Terrain, kept in double so the exchange with the particles conserves material.
    int w = 0, hgt = 0;
    double cell = 1.0, inv_cell = 1.0;
    double extent_x = 0.0, extent_z = 0.0;
    std::vector<double> terrain;
    std::vector<double> water_sum;  // Σ over steps of the water depth per vertex, m
    std::int64_t water_steps = 0;

    // Derived fluid constants (float: the SPH loops run in single precision).
    float h = 0, h2 = 0, inv_h = 0, mass = 0, volume = 0, rho0 = 0, B = 0, c0 = 0;
    float w_norm = 0, grad_norm = 0, visc_eps = 0, alpha_c_hs = 0;
    // The terrain's share of the kernel, as if the fluid's rest lattice continued below it: at distance
    // d = k·h/kWallSteps from the ground, wall_phi[k] is the missing neighbours' Σ V·W (a density fraction)
    // and wall_area[k] their Σ V·(−∂W/∂d) (1/m).
    static constexpr int kWallSteps = 64;
    std::array<float, kWallSteps + 1> wall_phi{}, wall_area{};
    std::vector<Vec3> wall_push;  // wall_area · the terrain's normal under each particle (this sub-step)

    // Particles (structure of arrays), `n` of them, dead ones flagged until the next compaction.
    std::size_t cap = 0, n = 0, live = 0;
    std::vector<Vec3> pos, vel, acc;
    std::vector<float> density, pterm;  // pterm = p/ρ²
    std::vector<double> sediment, exchange;  // m³ carried; m³ taken up this sub-step (<0 = dropped)
    std::vector<float> acidity;
    std::vector<std::int32_t> age, lifespan;
    std::vector<std::uint8_t> alive;
    // Neighbour search.
    std::vector<std::uint32_t> bucket, order, start;
    std::uint32_t mask = 63;
    std::size_t sorted = 0;  // particles in `order`
    std::vector<std::uint32_t> sort_key, sort_tmp_key, perm, perm_tmp;  // reorder scratch (reuses bucket storage size)

    Counts counts;
    std::int64_t substeps = 0, since_reorder = 0;
    double t = 0.0;
    double removed = 0.0;  // m³ of sediment gone over open edges
    float max_acc = 0.0f;

    // ------------------------------------------------------------ terrain
    double H(int x, int z) const { return terrain[std::size_t(z) * std::size_t(w) + std::size_t(x)]; }

    /// Tile containing (x, z), clamped to the map, and the fractions inside it.
    void tile(double x, double z, int& i, int& j, double& fx, double& fz) const {
        const double gx = std::clamp(x * inv_cell, 0.0, double(w - 1));
        const double gz = std::clamp(z * inv_cell, 0.0, double(hgt - 1));
        i = std::min(int(gx), std::max(w - 2, 0));
        j = std::min(int(gz), std::max(hgt - 2, 0));
        fx = gx - i;
        fz = gz - j;
    }

    /// Height of the triangulated surface (diagonal from (i,j) to (i+1,j+1)).
    double surface(double x, double z) const {
        int i, j;
        double fx, fz;
        tile(x, z, i, j, fx, fz);
        if (w == 1 || hgt == 1) return H(0, 0);
        const double a = H(i, j), b = H(i + 1, j), c = H(i, j + 1), d = H(i + 1, j + 1);
        if (fx >= fz) return a + fx * (b - a) + fz * (d - b);
        return a + fz * (c - a) + fx * (d - c);
    }

    void vertex_normal(int x, int z, double n[3]) const {
        const int x0 = std::max(x - 1, 0), x1 = std::min(x + 1, w - 1);
        const int z0 = std::max(z - 1, 0), z1 = std::min(z + 1, hgt - 1);
        const double dx = x1 > x0 ? (H(x1, z) - H(x0, z)) / ((x1 - x0) * cell) : 0.0;
        const double dz = z1 > z0 ? (H(x, z1) - H(x, z0)) / ((z1 - z0) * cell) : 0.0;
        const double l = std::sqrt(dx * dx + dz * dz + 1.0);
        n[0] = -dx / l;
        n[1] = 1.0 / l;
        n[2] = -dz / l;
    }

    /// The normal at (x, z): the tile's four vertex normals, bilinearly weighted, normalised.
    void normal(double x, double z, double n[3]) const {
        int i, j;
        double fx, fz;
        tile(x, z, i, j, fx, fz);
        if (w == 1 || hgt == 1) {
            n[0] = 0, n[1] = 1, n[2] = 0;
            return;
        }
        double a[3], b[3], c[3], d[3];
        vertex_normal(i, j, a);
        vertex_normal(i + 1, j, b);
        vertex_normal(i, j + 1, c);
        vertex_normal(i + 1, j + 1, d);
        double l = 0.0;
        for (int k = 0; k < 3; ++k) {
            n[k] = (1 - fx) * (1 - fz) * a[k] + fx * (1 - fz) * b[k] + (1 - fx) * fz * c[k] + fx * fz * d[k];
            l += n[k] * n[k];
        }
        l = std::sqrt(l);
        for (int k = 0; k < 3; ++k) n[k] /= l;
    }

    /// Möller–Trumbore: the ray o + t·d against triangle (p0, p1, p2); t in [0, 1] or -1.
    static double ray_triangle(const double o[3], const double d[3], const double p0[3], const double p1[3],
                               const double p2[3]) {
        const double e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
        const double e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
        const double pv[3] = {d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2], d[0] * e2[1] - d[1] * e2[0]};
        const double det = e1[0] * pv[0] + e1[1] * pv[1] + e1[2] * pv[2];
        if (std::abs(det) < 1e-18) return -1.0;
        const double inv = 1.0 / det;
        const double tv[3] = {o[0] - p0[0], o[1] - p0[1], o[2] - p0[2]};
        const double u = (tv[0] * pv[0] + tv[1] * pv[1] + tv[2] * pv[2]) * inv;
        if (u < 0.0 || u > 1.0) return -1.0;
        const double qv[3] = {tv[1] * e1[2] - tv[2] * e1[1], tv[2] * e1[0] - tv[0] * e1[2], tv[0] * e1[1] - tv[1] * e1[0]};
        const double v = (d[0] * qv[0] + d[1] * qv[1] + d[2] * qv[2]) * inv;
        if (v < 0.0 || u + v > 1.0) return -1.0;
        const double t = (e2[0] * qv[0] + e2[1] * qv[1] + e2[2] * qv[2]) * inv;
        return t >= 0.0 && t <= 1.0 ? t : -1.0;
    }

    /// Earliest hit of the motion o → o + d with the two triangles of tile (i, j); -1 if none.
    double hit_tile(int i, int j, const double o[3], const double d[3]) const {
        if (w < 2 || hgt < 2) return -1.0;
        const double x0 = i * cell, x1 = (i + 1) * cell, z0 = j * cell, z1 = (j + 1) * cell;
        const double a[3] = {x0, H(i, j), z0}, b[3] = {x1, H(i + 1, j), z0};
        const double c[3] = {x0, H(i, j + 1), z1}, e[3] = {x1, H(i + 1, j + 1), z1};
        double best = -1.0;
        for (double t : {ray_triangle(o, d, a, b, e), ray_triangle(o, d, a, e, c)})
            if (t >= 0.0 && (best < 0.0 || t < best)) best = t;
        return best;
    }

    /// Lift a float height onto or above the surface height `ys` (rounding up).
    float above(double ys) const {
        float f = float(ys + 1e-4 * s.radius);
        while (double(f) < ys) f = std::nextafter(f, std::numeric_limits<float>::infinity());
        return f;
    }

    /// Add `volume` m³ to the terrain at (x, z), spread bilinearly over the tile's vertices.
    void exchange_terrain(double x, double z, double volume) {
        int i, j;
        double fx, fz;
        tile(x, z, i, j, fx, fz);
        const double dh = volume * inv_cell * inv_cell;
        const auto at = [&](int a, int b) -> double& {
            return terrain[std::size_t(std::min(b, hgt - 1)) * std::size_t(w) + std::size_t(std::min(a, w - 1))];
        };
        if (w == 1 || hgt == 1) {
            at(i, j) += dh;
            return;
        }
        at(i, j) += dh * (1 - fx) * (1 - fz);
        at(i + 1, j) += dh * fx * (1 - fz);
        at(i, j + 1) += dh * (1 - fx) * fz;
        at(i + 1, j + 1) += dh * fx * fz;
    }

    // --------------------------------------------------------- particles
    void kill(std::size_t i) {
        alive[i] = 0;
        --live;
    }

    /// Sort the particle arrays along the Morton curve of their cells (dead
    /// ones dropped): stable LSD radix sort of 30-bit keys, ties in index order.
    void reorder() {
        since_reorder = 0;
        std::size_t m = 0;
        for (std::size_t i = 0; i < n; ++i) {
            if (!alive[i]) continue;
            const Vec3& p = pos[i];
            const auto cx = std::uint32_t(int(std::floor(p.x * inv_h)) + kCellBias);
            const auto cy = std::uint32_t(int(std::floor(p.y * inv_h)) + kCellBias);
            const auto cz = std::uint32_t(int(std::floor(p.z * inv_h)) + kCellBias);
            sort_key[m] = morton(cx, cy, cz);
            perm[m] = std::uint32_t(i);
            ++m;
        }
        std::uint32_t* key = sort_key.data();
        std::uint32_t* tkey = sort_tmp_key.data();
        std::uint32_t* idx = perm.data();
        std::uint32_t* tidx = perm_tmp.data();
        for (int shift = 0; shift < 30; shift += 10) {
            std::uint32_t count[1025] = {};
            for (std::size_t k = 0; k < m; ++k) ++count[((key[k] >> shift) & 1023u) + 1];
            for (int b = 0; b < 1024; ++b) count[b + 1] += count[b];
            for (std::size_t k = 0; k < m; ++k) {
                const std::uint32_t dst = count[(key[k] >> shift) & 1023u]++;
                tkey[dst] = key[k];
                tidx[dst] = idx[k];
            }
            std::swap(key, tkey);
            std::swap(idx, tidx);
        }
        // Three passes: the result is in the temporaries' storage.
        const std::uint32_t* p = idx;
        permute(pos, p, m);
        permute(vel, p, m);
        permute(acc, p, m);
        permute(density, p, m);
        permute(pterm, p, m);
        permute(sediment, p, m);
        permute(acidity, p, m);
        permute(age, p, m);
        permute(lifespan, p, m);
        std::fill(alive.begin(), alive.begin() + std::ptrdiff_t(m), std::uint8_t(1));
        n = m;
        live = m;
    }

    template <typename T>
    void permute(std::vector<T>& v, const std::uint32_t* p, std::size_t m) {
        // `exchange` (double) is free between sub-steps: use it as scratch for 8-byte types,
        // `bucket` + `order` for 4-byte ones, `acc`-sized storage for Vec3.
        if constexpr (sizeof(T) == 8) {
            auto* tmp = reinterpret_cast<T*>(exchange.data());
            for (std::size_t k = 0; k < m; ++k) tmp[k] = v[p[k]];
            std::copy(tmp, tmp + m, v.begin());
        } else if constexpr (sizeof(T) == 4) {
            auto* tmp = reinterpret_cast<T*>(bucket.data());
            for (std::size_t k = 0; k < m; ++k) tmp[k] = v[p[k]];
            std::copy(tmp, tmp + m, v.begin());
        } else {
            static_assert(sizeof(T) == 12);
            // Vec3: two passes through the 8-byte scratch would be awkward; use
            // bucket (4 B) + exchange (8 B) together as 12 bytes per particle.
            auto* a = reinterpret_cast<float*>(bucket.data());
            auto* b = reinterpret_cast<double*>(exchange.data());
            for (std::size_t k = 0; k < m; ++k) {
                const Vec3& q = v[p[k]];
                a[k] = q.x;
                float yz[2] = {q.y, q.z};
                std::memcpy(&b[k], yz, 8);
            }
            for (std::size_t k = 0; k < m; ++k) {
                float yz[2];
                std::memcpy(yz, &b[k], 8);
                v[k] = Vec3{a[k], yz[0], yz[1]};
            }
        }
    }

    std::uint32_t cell_coord(float x) const { return std::uint32_t(int(std::floor(x * inv_h)) + kCellBias); }

    /// Bucket every live particle; stable counting sort into `order`, `start`.
    void build_grid() {
        if (since_reorder >= kReorderEvery || live != n) reorder();
        ++since_reorder;
        std::uint32_t bits = 6;
        while ((std::size_t(1) << bits) < 2 * n) ++bits;
        mask = (1u << bits) - 1u;
        const std::size_t tsize = std::size_t(mask) + 1;
        parallel_for(0, std::int64_t(n), 4096, [&](std::int64_t b, std::int64_t e) {
            for (std::int64_t i = b; i < e; ++i) {
                const Vec3& p = pos[std::size_t(i)];
                bucket[std::size_t(i)] = bucket_of(cell_coord(p.x), cell_coord(p.y), cell_coord(p.z), mask);
            }
        });
        std::fill(start.begin(), start.begin() + std::ptrdiff_t(tsize + 1), 0u);
        for (std::size_t i = 0; i < n; ++i) ++start[bucket[i] + 1];
        for (std::size_t b = 0; b < tsize; ++b) start[b + 1] += start[b];
        // Scatter using start[b] as a cursor, then shift back (start[b] ends at the old start[b+1]).
        for (std::size_t i = 0; i < n; ++i) order[start[bucket[i]]++] = std::uint32_t(i);
        for (std::size_t b = tsize; b > 0; --b) start[b] = start[b - 1];
        start[0] = 0;
        sorted = n;
    }

    /// The particles within h of particle i (i itself included), in a fixed
    /// order (27 cells in order, each bucket's particles in sorted order),
    /// into nb[] with their squared distances; returns how many. The filter
    /// is branch-free (write always, advance on a hit): most candidates miss.
    std::size_t gather(std::size_t i, std::uint32_t* nb, float* r2s, std::size_t room) const {
        const Vec3 p = pos[i];
        const std::uint32_t cx = cell_coord(p.x), cy = cell_coord(p.y), cz = cell_coord(p.z);
        std::size_t c = 0;
        for (std::uint32_t ox = cx - 1; ox != cx + 2; ++ox)
            for (std::uint32_t oy = cy - 1; oy != cy + 2; ++oy)
                for (std::uint32_t oz = cz - 1; oz != cz + 2; ++oz) {
                    const std::uint32_t b = bucket_of(ox, oy, oz, mask);
                    const std::uint32_t e = start[b + 1];
                    std::uint32_t k = start[b];
                    if (c + (e - k) > room) k = e - std::uint32_t(room - c);  // cannot happen below 4× rest density
                    for (; k < e; ++k) {
                        const std::uint32_t j = order[k];
                        const Vec3& q = pos[j];
                        const float dx = p.x - q.x, dy = p.y - q.y, dz = p.z - q.z;
                        const float r2 = dx * dx + dy * dy + dz * dz;
                        nb[c] = j;
                        r2s[c] = r2;
                        c += r2 < h2 ? 1u : 0u;
                    }
                }
        return c;
    }
    static constexpr std::size_t kRoom = 4096;

    /// Cubic spline kernel W(r) with support h.
    float kernel(float r2) const {
        const float q = std::sqrt(r2) * inv_h;
        const float f = 1.0f - q;
        const float inner = 6.0f * q * q * (q - 1.0f) + 1.0f, outer = 2.0f * f * f * f;
        return w_norm * (q <= 0.5f ? inner : outer);
    }
    /// dW/dr / r (multiply by the separation vector for ∇W).
    float kernel_grad(float r2) const {
        // The particle itself (r = 0) contributes nothing: its separation vector is zero.
        const float r = std::max(std::sqrt(r2), 1e-12f);
        const float q = r * inv_h;
        const float inner = q * (3.0f * q - 2.0f), outer = -(1.0f - q) * (1.0f - q);
        return grad_norm * (q <= 0.5f ? inner : outer) * inv_h / r;
    }

    /// Tabulate the walls' kernel share, once per simulation. The half-space behind a wall is filled with the
    /// fluid's own rest lattice (spacing 2·radius, layers at d + spacing/2, d + 3·spacing/2, ... behind the
    /// particle, columns aligned with it), summed exactly rather than integrated: WCSPH's pressure is
    /// B((ρ/ρ0)⁷ − 1), so a 1 % mismatch between the wall's share and the missing neighbours is several kPa.
    /// With the lattice sum, a particle resting on the floor has the interior's density exactly.
    void tabulate_walls() {
        const double spacing = std::cbrt(double(volume));
        const int reach = int(std::ceil(double(h) / spacing)) + 1;
        auto layer = [&](double z, double& phi, double& area) {  // one lattice layer at distance z behind
            for (int a = -reach; a <= reach; ++a)
                for (int b = -reach; b <= reach; ++b) {
                    const double r2 = (a * a + b * b) * spacing * spacing + z * z;
                    if (r2 >= double(h2)) continue;
                    phi += double(volume) * double(kernel(float(r2)));
                    area -= double(volume) * double(kernel_grad(float(r2))) * z;  // −∂W/∂z, ≥ 0
                }
        };
        for (int k = 0; k <= kWallSteps; ++k) {
            const double d = double(h) * k / kWallSteps;
            double phi = 0.0, area = 0.0;
            for (double z = d + 0.5 * spacing; z < double(h); z += spacing) layer(z, phi, area);
            wall_phi[std::size_t(k)] = float(phi);
            wall_area[std::size_t(k)] = float(area);
        }
    }
    /// Add the share of a wall at distance d (m, ≥ 0 in front of it) with unit normal (nx, ny, nz) into the
    /// fluid: to the density fraction `phi` and the push `push`.
    void add_wall(double d, double nx, double ny, double nz, float& phi, Vec3& push) const {
        if (!(d < double(h))) return;
        const double u = std::max(d, 0.0) / double(h) * kWallSteps;
        const int k = std::min(int(u), kWallSteps - 1);
        const float f = float(u - k);
        const std::size_t a = std::size_t(k), b = a + 1;
        phi += wall_phi[a] + f * (wall_phi[b] - wall_phi[a]);
        const float area = wall_area[a] + f * (wall_area[b] - wall_area[a]);
        push.x += area * float(nx);
        push.y += area * float(ny);
        push.z += area * float(nz);
    }

    void density_pass() {
        parallel_for(0, std::int64_t(n), kGrain, [&](std::int64_t b, std::int64_t e) {
            FlushDenormals ftz;
            std::vector<std::uint32_t> nb(kRoom);
            std::vector<float> r2s(kRoom);
            for (std::int64_t ii = b; ii < e; ++ii) {
                const auto i = std::size_t(ii);
                const std::size_t c = gather(i, nb.data(), r2s.data(), kRoom);
                float rho = 0.0f;
                for (std::size_t k = 0; k < c; ++k) rho += kernel(r2s[k]);
                rho *= mass;
                // The terrain as the fluid's rest lattice continued behind it (Akinci et al. 2012's boundary
                // particles, summed once into a table): without it a particle on the ground misses half its
                // kernel and the fluid crowds against the ground.
                float phi = 0.0f;
                Vec3 push{0.0f, 0.0f, 0.0f};
                const double x = pos[i].x, y = pos[i].y, z = pos[i].z;
                // Only the terrain: the map's side walls (closed boundary) stay geometric. With them as walls too
                // (and the quadrant where two meet subtracted once), Martin & Moyce's dam break in its narrow
                // tank ran 30 % ahead of the measurements; see docs/sph.md.
                const double above = y - surface(x, z);
                if (above < double(h)) {
                    double nrm[3];
                    normal(x, z, nrm);
                    add_wall(above * nrm[1], nrm[0], nrm[1], nrm[2], phi, push);  // the distance to the tangent plane
                }
                wall_push[i] = push;
                rho += rho0 * phi;
                density[i] = rho;
                const float ratio = rho / rho0;
                const float r2_ = ratio * ratio;
                const float p = std::max(0.0f, B * (r2_ * r2_ * r2_ * ratio - 1.0f));
                pterm[i] = p / (rho * rho);
            }
        });
    }

    void force_pass() {
        const float g = float(-s.gravity);
        const std::int64_t blocks = (std::int64_t(n) + kGrain - 1) / kGrain;
        std::vector<float> block_max(std::size_t(std::max<std::int64_t>(blocks, 1)), 0.0f);
        parallel_for(0, blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
            FlushDenormals ftz;
            std::vector<std::uint32_t> nb(kRoom);
            std::vector<float> r2s(kRoom);
            for (std::int64_t blk = b0; blk < b1; ++blk) {
                float amax = 0.0f;
                const std::size_t lo = std::size_t(blk * kGrain), hi = std::min(n, lo + std::size_t(kGrain));
                for (std::size_t i = lo; i < hi; ++i) {
                    const Vec3 vi = vel[i];
                    const Vec3 pi3 = pos[i];
                    const float pi = pterm[i], rhoi = density[i];
                    float ax = 0, ay = 0, az = 0;
                    const std::size_t c = gather(i, nb.data(), r2s.data(), kRoom);
                    for (std::size_t k = 0; k < c; ++k) {
                        const std::uint32_t j = nb[k];
                        const float r2 = r2s[k];
                        const Vec3& pj = pos[j];
                        const float dx = pi3.x - pj.x, dy = pi3.y - pj.y, dz = pi3.z - pj.z;
                        const Vec3& vj = vel[j];
                        const float vx = vi.x - vj.x, vy = vi.y - vj.y, vz = vi.z - vj.z;
                        const float vr = vx * dx + vy * dy + vz * dz;
                        float term = pi + pterm[j];
                        if (vr < 0.0f) {
                            const float mu = vr / (r2 + visc_eps);
                            term -= alpha_c_hs * mu * 2.0f / (rhoi + density[j]);
                        }
                        const float gw = -mass * term * kernel_grad(r2);
                        ax += gw * dx;
                        ay += gw * dy;
                        az += gw * dz;
                    }
                    // The ground pushes back with the particle's own pressure (mirrored): −(2 p/ρ²) ρ0 ∇Φ.
                    const float wall = 2.0f * pi * rho0;
                    ax += wall * wall_push[i].x;
                    ay += wall * wall_push[i].y + g;
                    az += wall * wall_push[i].z;
                    acc[i] = Vec3{ax, ay, az};
                    amax = std::max(amax, ax * ax + ay * ay + az * az);
                }
                block_max[std::size_t(blk)] = amax;
            }
        });
        float amax = 0.0f;
        for (float a : block_max) amax = std::max(amax, a);
        max_acc = std::sqrt(amax);
    }

    /// Integrate, collide with the terrain and the walls, compute the erosion
    /// exchange. Returns false if a particle went non-finite.
    bool integrate(float dt) {
        const double ddt = dt;
        const double e = s.restitution;
        const double fric = std::exp(-s.friction * ddt);
        const double dissolve_frac = 1.0, deposit_frac = std::min(1.0, s.deposit * ddt);
        const double particle_volume = double(volume);
        const double max_take = s.max_dig * cell * cell;
        const std::int64_t blocks = (std::int64_t(n) + kGrain - 1) / kGrain;
        std::vector<std::uint8_t> block_bad(std::size_t(std::max<std::int64_t>(blocks, 1)), 0);
        parallel_for(0, blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
            FlushDenormals ftz;
            for (std::int64_t blk = b0; blk < b1; ++blk) {
                const std::size_t lo = std::size_t(blk * kGrain), hi = std::min(n, lo + std::size_t(kGrain));
                for (std::size_t i = lo; i < hi; ++i) {
                    exchange[i] = 0.0;
                    if (!alive[i]) continue;
                    double v[3] = {vel[i].x + double(acc[i].x) * ddt, vel[i].y + double(acc[i].y) * ddt,
                                   vel[i].z + double(acc[i].z) * ddt};
                    const double o[3] = {pos[i].x, pos[i].y, pos[i].z};
                    const double d[3] = {v[0] * ddt, v[1] * ddt, v[2] * ddt};
                    double p[3] = {o[0] + d[0], o[1] + d[1], o[2] + d[2]};
                    if (!std::isfinite(p[0] + p[1] + p[2] + v[0] + v[1] + v[2])) {
                        block_bad[std::size_t(blk)] = 1;  // reported by substep(); never index the terrain with it
                        continue;
                    }
                    bool contact = false;
                    // Möller–Trumbore against the tiles beneath the start and the end of the motion.
                    int ti, tj, ui, uj;
                    double fx, fz;
                    tile(o[0], o[2], ti, tj, fx, fz);
                    tile(p[0], p[2], ui, uj, fx, fz);
                    double t = hit_tile(ti, tj, o, d);
                    if (ui != ti || uj != tj) {
                        const double t2 = hit_tile(ui, uj, o, d);
                        if (t2 >= 0.0 && (t < 0.0 || t2 < t)) t = t2;
                    }
                    double n3[3];
                    if (t >= 0.0) {
                        for (int k = 0; k < 3; ++k) p[k] = o[k] + t * d[k];
                        normal(p[0], p[2], n3);
                        const double vn = v[0] * n3[0] + v[1] * n3[1] + v[2] * n3[2];
                        if (vn < 0.0)
                            for (int k = 0; k < 3; ++k) v[k] -= (1.0 + e) * vn * n3[k];
                        contact = true;
                    }
                    // The map's edges.
                    bool out = false;
                    const double lim[2] = {extent_x, extent_z};
                    for (int k : {0, 2}) {
                        const double l = lim[k == 0 ? 0 : 1];
                        if (p[k] < 0.0 || p[k] > l) {
                            if (s.boundary == Boundary::open) {
                                out = true;
                            } else {
                                // A wall: stop there, reflect the outward velocity (restitution e).
                                const bool low = p[k] < 0.0;
                                p[k] = low ? 0.0 : l;
                                if (low ? v[k] < 0.0 : v[k] > 0.0) v[k] *= -e;
                            }
                        }
                    }
                    if (out) {
                        pos[i] = Vec3{float(p[0]), float(p[1]), float(p[2])};
                        vel[i] = Vec3{float(v[0]), float(v[1]), float(v[2])};
                        exchange[i] = std::numeric_limits<double>::quiet_NaN();  // marks "left" for the serial pass
                        continue;
                    }
                    // Never below the triangulated surface (at the position as stored, in float).
                    Vec3 np{float(p[0]), float(p[1]), float(p[2])};
                    p[0] = np.x;
                    p[2] = np.z;
                    const double ys = surface(p[0], p[2]);
                    normal(p[0], p[2], n3);
                    if (p[1] < ys + 1e-4 * s.radius) {
                        p[1] = ys;
                        const double vn = v[0] * n3[0] + v[1] * n3[1] + v[2] * n3[2];
                        if (vn < 0.0)
                            for (int k = 0; k < 3; ++k) v[k] -= (1.0 + e) * vn * n3[k];
                        contact = true;
                    }
                    if (p[1] - ys < s.radius) contact = true;
                    double take = 0.0;
                    if (contact) {
                        const double vn = v[0] * n3[0] + v[1] * n3[1] + v[2] * n3[2];
                        double vt[3] = {v[0] - vn * n3[0], v[1] - vn * n3[1], v[2] - vn * n3[2]};
                        for (int k = 0; k < 3; ++k) {
                            vt[k] *= fric;
                            v[k] = vn * n3[k] + vt[k];
                        }
                        if (s.erode) {
                            const double speed = std::sqrt(vt[0] * vt[0] + vt[1] * vt[1] + vt[2] * vt[2]);
                            const double sin_slope = std::sqrt(std::max(0.0, 1.0 - n3[1] * n3[1]));
                            const double cap = s.capacity * particle_volume * speed * std::max(sin_slope, s.min_slope);
                            const double sed = sediment[i];
                            if (sed < cap)
                                take = std::min(std::min(1.0, double(acidity[i]) * ddt) * dissolve_frac * (cap - sed), max_take);
                            else
                                take = -deposit_frac * (sed - cap);
                        }
                    }
                    exchange[i] = take;
                    np.y = float(p[1]);
                    if (double(np.y) < ys) np.y = above(ys);
                    pos[i] = np;
                    vel[i] = Vec3{float(v[0]), float(v[1]), float(v[2])};
                    if (!finite3(np) || !finite3(vel[i])) block_bad[std::size_t(blk)] = 1;
                }
            }
        });
        for (auto b : block_bad)
            if (b) return false;
        return true;
    }

    /// Serial, in particle order: apply the exchanges to the terrain, remove
    /// particles that left or reached the sea.
    void settle() {
        bool changed = false;
        for (std::size_t i = 0; i < n; ++i) {
            if (!alive[i]) continue;
            const double x = exchange[i];
            const Vec3& p = pos[i];
            if (std::isnan(x)) {  // left over an open edge, with its sediment
                removed += sediment[i];
                sediment[i] = 0.0;
                kill(i);
                ++counts.left;
                continue;
            }
            if (x != 0.0) {
                exchange_terrain(p.x, p.z, -x);
                sediment[i] += x;
                changed = true;
            }
            if (double(p.y) < s.sea_level) {
                if (sediment[i] != 0.0) exchange_terrain(p.x, p.z, sediment[i]);
                sediment[i] = 0.0;
                kill(i);
                ++counts.sea;
                changed = true;
            }
        }
        if (changed) lift_all();
    }

    /// After the terrain changed: lift particles a deposit has covered.
    void lift_all() {
        parallel_for(0, std::int64_t(n), 4096, [&](std::int64_t b, std::int64_t e) {
            for (std::int64_t ii = b; ii < e; ++ii) {
                const auto i = std::size_t(ii);
                if (!alive[i]) continue;
                const double ys = surface(pos[i].x, pos[i].z);
                if (double(pos[i].y) < ys) pos[i].y = above(ys);
            }
        });
    }

    float speed_max() const {
        const std::int64_t blocks = (std::int64_t(n) + 4095) / 4096;
        std::vector<float> m(std::size_t(std::max<std::int64_t>(blocks, 1)), 0.0f);
        parallel_for(0, blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
            for (std::int64_t blk = b0; blk < b1; ++blk) {
                float v2 = 0.0f;
                const std::size_t lo = std::size_t(blk * 4096), hi = std::min(n, lo + 4096);
                for (std::size_t i = lo; i < hi; ++i) {
                    const Vec3& v = vel[i];
                    v2 = std::max(v2, v.x * v.x + v.y * v.y + v.z * v.z);
                }
                m[std::size_t(blk)] = v2;
            }
        });
        float v2 = 0.0f;
        for (float x : m) v2 = std::max(v2, x);
        return std::sqrt(v2);
    }
};

Simulation::Simulation(ConstGridView terrain, const Settings& settings, std::size_t capacity)
    : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    m.s = settings;
    m.w = terrain.width;
    m.hgt = terrain.height;
    m.cell = terrain.cell;
    m.inv_cell = 1.0 / terrain.cell;
    m.extent_x = (m.w - 1) * m.cell;
    m.extent_z = (m.hgt - 1) * m.cell;
    m.terrain.assign(terrain.data, terrain.data + terrain.size());
    m.water_sum.assign(terrain.size(), 0.0);

    const double r = settings.radius;
    const double spacing = 2.0 * r;
    m.h = float(4.0 * r);
    m.h2 = m.h * m.h;
    m.inv_h = 1.0f / m.h;
    m.volume = float(spacing * spacing * spacing);
    m.rho0 = float(settings.rest_density);
    m.mass = float(settings.rest_density * spacing * spacing * spacing);
    m.c0 = float(settings.sound_speed);
    m.B = float(settings.rest_density * settings.sound_speed * settings.sound_speed / 7.0);
    const double hh = m.h;
    m.w_norm = float(8.0 / (std::numbers::pi * hh * hh * hh));
    m.grad_norm = float(48.0 / (std::numbers::pi * hh * hh * hh));
    const double hs = 0.5 * hh;  // the smoothing length of the viscosity term
    m.visc_eps = float(0.01 * hs * hs);
    m.alpha_c_hs = float(settings.viscosity * settings.sound_speed * hs);
    m.tabulate_walls();

    m.cap = capacity;
    m.pos.resize(capacity);
    m.vel.resize(capacity);
    m.acc.resize(capacity);
    m.density.resize(capacity);
    m.wall_push.resize(capacity);
    m.pterm.resize(capacity);
    m.sediment.resize(capacity);
    m.exchange.resize(capacity);
    m.acidity.resize(capacity);
    m.age.resize(capacity);
    m.lifespan.resize(capacity);
    m.alive.resize(capacity);
    m.bucket.resize(capacity);
    m.order.resize(capacity);
    std::size_t table = 64;
    while (table < 2 * capacity) table *= 2;
    m.start.resize(table + 1);
    m.sort_key.resize(capacity);
    m.sort_tmp_key.resize(capacity);
    m.perm.resize(capacity);
    m.perm_tmp.resize(capacity);
}

Simulation::~Simulation() = default;

std::size_t Simulation::bytes_per_particle() {
    // pos, vel, acc (36) + density, pterm, acidity, age, lifespan (20) + sediment, exchange (16)
    // + alive (1) + bucket, order (8) + hash table (≤ 4 × 4 buckets) + sort scratch (16).
    return 36 + 20 + 16 + 1 + 8 + 16 + 16;
}

bool Simulation::add(Vec3 p, Vec3 v, float acidity, std::int32_t lifespan) {
    Impl& m = *impl_;
    if (m.n >= m.cap) {
        ++m.counts.refused;
        return false;
    }
    const std::size_t i = m.n++;
    ++m.live;
    const double ys = m.surface(p.x, p.z);
    if (double(p.y) < ys) p.y = m.above(ys);
    m.pos[i] = p;
    m.vel[i] = v;
    m.acc[i] = Vec3{0.0f, float(-m.s.gravity), 0.0f};
    m.density[i] = m.rho0;
    m.pterm[i] = 0.0f;
    m.sediment[i] = 0.0;
    m.exchange[i] = 0.0;
    m.acidity[i] = acidity;
    m.age[i] = 0;
    m.lifespan[i] = lifespan;
    m.alive[i] = 1;
    ++m.counts.spawned;
    return true;
}

void Simulation::rain(std::int64_t count, double height, std::uint64_t seed, std::int64_t step, float acidity,
                      std::int32_t lifespan) {
    Impl& m = *impl_;
    for (std::int64_t k = 0; k < count; ++k) {
        const double x = random::uniform(seed, 0x5241494Eu, std::uint64_t(step), std::uint64_t(k), 0) * m.extent_x;
        const double z = random::uniform(seed, 0x5241494Eu, std::uint64_t(step), std::uint64_t(k), 1) * m.extent_z;
        add(Vec3{float(x), float(m.surface(x, z) + height), float(z)}, Vec3{}, acidity, lifespan);
    }
}

void Simulation::spring(double x, double z, std::int64_t count, std::uint64_t seed, std::int64_t step,
                        std::int64_t which, float acidity, std::int32_t lifespan) {
    Impl& m = *impl_;
    const double spacing = 2.0 * m.s.radius;
    for (std::int64_t k = 0; k < count; ++k) {
        const double a = 2.0 * std::numbers::pi *
                         random::uniform(seed, 0x535052u, std::uint64_t(which), std::uint64_t(step), std::uint64_t(k), 0);
        const double rr = 2.0 * spacing *
                          std::sqrt(random::uniform(seed, 0x535052u, std::uint64_t(which), std::uint64_t(step),
                                                    std::uint64_t(k), 1));
        const double px = std::clamp(x + rr * std::cos(a), 0.0, m.extent_x);
        const double pz = std::clamp(z + rr * std::sin(a), 0.0, m.extent_z);
        const double lift = spacing * (1.0 + random::uniform(seed, 0x535052u, std::uint64_t(which),
                                                             std::uint64_t(step), std::uint64_t(k), 2));
        add(Vec3{float(px), float(m.surface(px, pz) + lift), float(pz)}, Vec3{}, acidity, lifespan);
    }
}

double Simulation::stable_dt() const {
    const Impl& m = *impl_;
    const double vmax = m.speed_max();
    double dt = m.s.cfl * m.h / (m.c0 + vmax);
    if (m.max_acc > 0.0f) dt = std::min(dt, 0.25 * std::sqrt(double(m.h) / m.max_acc));
    return dt;
}

void Simulation::substep(double dt) {
    Impl& m = *impl_;
    if (m.n == 0 && m.live == 0) {
        m.t += dt;
        ++m.substeps;
        return;
    }
    m.build_grid();
    m.density_pass();
    m.force_pass();
    const bool ok = m.integrate(float(dt));
    m.t += dt;
    ++m.substeps;
    if (!ok) {
        std::ostringstream msg;
        msg << "the SPH simulation went non-finite in sub-step " << m.substeps << " with " << m.live
            << " particles; lower dt or cfl, or raise sound_speed";
        throw Error(msg.str());
    }
    m.settle();
}

void Simulation::advance(double dt, std::int64_t step) {
    double left = dt;
    while (left > 0.0) {
        double h = stable_dt();
        if (h >= left * (1.0 - 1e-9)) h = left;
        if (!(h > 0.0) || !std::isfinite(h)) {
            std::ostringstream msg;
            msg << "the SPH simulation went non-finite at step " << step << " with " << impl_->live << " particles";
            throw Error(msg.str());
        }
        try {
            substep(h);
        } catch (const Error& e) {
            std::ostringstream msg;
            msg << "step " << step << ": " << e.what();
            throw Error(msg.str());
        }
        left -= h;
    }
}

void Simulation::end_step() {
    Impl& m = *impl_;
    bool changed = false;
    const double vcell = double(m.volume) * m.inv_cell * m.inv_cell;
    for (std::size_t i = 0; i < m.n; ++i) {
        if (!m.alive[i]) continue;
        ++m.age[i];
        const Vec3& p = m.pos[i];
        if (m.lifespan[i] > 0 && m.age[i] >= m.lifespan[i]) {
            if (m.sediment[i] != 0.0) {
                m.exchange_terrain(p.x, p.z, m.sediment[i]);
                changed = true;
            }
            m.sediment[i] = 0.0;
            m.kill(i);
            ++m.counts.evaporated;
            continue;
        }
        int ti, tj;
        double fx, fz;
        m.tile(p.x, p.z, ti, tj, fx, fz);
        auto at = [&](int a, int b) -> double& {
            return m.water_sum[std::size_t(std::min(b, m.hgt - 1)) * std::size_t(m.w) + std::size_t(std::min(a, m.w - 1))];
        };
        at(ti, tj) += vcell * (1 - fx) * (1 - fz);
        at(ti + 1, tj) += vcell * fx * (1 - fz);
        at(ti, tj + 1) += vcell * (1 - fx) * fz;
        at(ti + 1, tj + 1) += vcell * fx * fz;
    }
    ++m.water_steps;
    if (changed) m.lift_all();
    if (m.live != m.n) m.reorder();
}

std::size_t Simulation::size() const { return impl_->live; }
std::size_t Simulation::capacity() const { return impl_->cap; }
const Counts& Simulation::counts() const { return impl_->counts; }
std::int64_t Simulation::substeps() const { return impl_->substeps; }
double Simulation::time() const { return impl_->t; }
double Simulation::surface(double x, double z) const { return impl_->surface(x, z); }

double Simulation::min_clearance() const {
    const Impl& m = *impl_;
    double c = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < m.n; ++i)
        if (m.alive[i]) c = std::min(c, double(m.pos[i].y) - m.surface(m.pos[i].x, m.pos[i].z));
    return c;
}

double Simulation::terrain_volume() const {
    const Impl& m = *impl_;
    double v = 0.0;
    for (double h : m.terrain) v += h;
    return v * m.cell * m.cell;
}

double Simulation::carried_sediment() const {
    const Impl& m = *impl_;
    double s = 0.0;
    for (std::size_t i = 0; i < m.n; ++i)
        if (m.alive[i]) s += m.sediment[i];
    return s;
}

double Simulation::removed_sediment() const { return impl_->removed; }

// Views of the particle arrays: valid (dead ones compacted away) after end_step()
// or right after construction/add(); between sub-steps dead particles may remain.
std::span<const Vec3> Simulation::positions() const { return {impl_->pos.data(), impl_->n}; }
std::span<const Vec3> Simulation::velocities() const { return {impl_->vel.data(), impl_->n}; }
std::span<const float> Simulation::densities() const { return {impl_->density.data(), impl_->n}; }
std::span<const float> Simulation::pressures() const {
    // Not stored: p = pterm·ρ²; computed into a thread-local buffer.
    thread_local std::vector<float> p;
    const Impl& m = *impl_;
    p.resize(m.n);
    for (std::size_t i = 0; i < m.n; ++i) p[i] = m.pterm[i] * m.density[i] * m.density[i];
    return {p.data(), p.size()};
}
std::span<const float> Simulation::sediments() const {
    thread_local std::vector<float> s;
    const Impl& m = *impl_;
    s.resize(m.n);
    for (std::size_t i = 0; i < m.n; ++i) s[i] = float(m.sediment[i]);
    return {s.data(), s.size()};
}

void Simulation::write_terrain(GridView out) const {
    const Impl& m = *impl_;
    for (std::size_t i = 0; i < m.terrain.size(); ++i) out.data[i] = float(m.terrain[i]);
}

void Simulation::write_water(GridView out) const {
    const Impl& m = *impl_;
    const double k = m.water_steps > 0 ? 1.0 / double(m.water_steps) : 0.0;
    for (std::size_t i = 0; i < m.water_sum.size(); ++i) out.data[i] = float(m.water_sum[i] * k);
}

void Simulation::record(ParticleFrame& f) const {
    const Impl& m = *impl_;
    f.time = m.t;
    auto& pos = f.attributes["position"];
    auto& vel = f.attributes["velocity"];
    auto& rho = f.attributes["density"];
    auto& pre = f.attributes["pressure"];
    auto& sed = f.attributes["sediment"];
    auto& acid = f.attributes["acidity"];
    auto& age = f.attributes["age"];
    pos.components = vel.components = 3;
    for (std::size_t i = 0; i < m.n; ++i) {
        if (!m.alive[i]) continue;
        pos.data.insert(pos.data.end(), {m.pos[i].x, m.pos[i].y, m.pos[i].z});
        vel.data.insert(vel.data.end(), {m.vel[i].x, m.vel[i].y, m.vel[i].z});
        rho.data.push_back(m.density[i]);
        pre.data.push_back(m.pterm[i] * m.density[i] * m.density[i]);
        sed.data.push_back(float(m.sediment[i]));
        acid.data.push_back(m.acidity[i]);
        age.data.push_back(float(m.age[i]));
    }
}

}  // namespace orogen::sph
