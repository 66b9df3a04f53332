// terrain_boundary.hpp — the terrain as the fluid's boundary: heights (in double), the triangulated surface,
// its normals, the ray test of a particle's motion against it, the exchange of material with the particles,
// and the wall table (the terrain's share of a particle's kernel).
//
// surface_in, normal_in, hit_tile, add and the exchanges run per particle and sub-step (several times):
// they are defined here so the integrator's loops inline them.
#pragma once

#include "kernels.hpp"
#include "sph.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace orogen::sph {

class TerrainBoundary {
public:
    /// `terrain`: heights in m (copied into double, so the exchange with the particles conserves material);
    /// `radius`: the particles' radius, m (above() lifts by a fraction of it).
    TerrainBoundary(ConstGridView terrain, double radius);

    int width() const { return w_; }
    int height() const { return hgt_; }
    double cell() const { return cell_; }
    double inv_cell() const { return inv_cell_; }
    double extent_x() const { return extent_x_; }  ///< m, the last vertex column's x
    double extent_z() const { return extent_z_; }  ///< m, the last vertex row's z
    const std::vector<double>& heights() const { return terrain_; }
    const std::vector<double>& water_sum() const { return water_sum_; }
    std::int64_t water_steps() const { return water_steps_; }

    double H(int x, int z) const { return terrain_[std::size_t(z) * std::size_t(w_) + std::size_t(x)]; }

    /// Tile containing (x, z), clamped to the map, and the fractions inside it.
    void tile(double x, double z, int& i, int& j, double& fx, double& fz) const {
        const double gx = std::clamp(x * inv_cell_, 0.0, double(w_ - 1));
        const double gz = std::clamp(z * inv_cell_, 0.0, double(hgt_ - 1));
        i = std::min(int(gx), std::max(w_ - 2, 0));
        j = std::min(int(gz), std::max(hgt_ - 2, 0));
        fx = gx - i;
        fz = gz - j;
    }

    /// Height of the triangulated surface (diagonal from (i,j) to (i+1,j+1)).
    double surface(double x, double z) const {
        int i, j;
        double fx, fz;
        tile(x, z, i, j, fx, fz);
        return surface_in(i, j, fx, fz);
    }
    /// surface() in tile (i, j) at fractions (fx, fz), as tile() gives them.
    double surface_in(int i, int j, double fx, double fz) const {
        if (w_ == 1 || hgt_ == 1) return H(0, 0);
        const double a = H(i, j), b = H(i + 1, j), c = H(i, j + 1), d = H(i + 1, j + 1);
        if (fx >= fz) return a + fx * (b - a) + fz * (d - b);
        return a + fz * (c - a) + fx * (d - c);
    }

    /// The normal at (x, z): the tile's four vertex normals, bilinearly weighted, normalised.
    void normal(double x, double z, double n[3]) const {
        int i, j;
        double fx, fz;
        tile(x, z, i, j, fx, fz);
        normal_in(i, j, fx, fz, n);
    }
    /// normal() in tile (i, j) at fractions (fx, fz): the callers that need the surface height at the same
    /// point too (density_pass, integrate) locate the tile once for both.
    void normal_in(int i, int j, double fx, double fz, double n[3]) const {
        if (w_ == 1 || hgt_ == 1) {
            n[0] = 0, n[1] = 1, n[2] = 0;
            return;
        }
        const float* a = &vnormal_[3 * (std::size_t(j) * std::size_t(w_) + std::size_t(i))];
        const float* b = a + 3;
        const float* c = a + 3 * std::size_t(w_);
        const float* d = c + 3;
        double l = 0.0;
        for (int k = 0; k < 3; ++k) {
            n[k] = (1 - fx) * (1 - fz) * a[k] + fx * (1 - fz) * b[k] + (1 - fx) * fz * c[k] + fx * fz * d[k];
            l += n[k] * n[k];
        }
        const double il = 1.0 / std::sqrt(l);
        for (int k = 0; k < 3; ++k) n[k] *= il;
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
        const double qv[3] = {tv[1] * e1[2] - tv[2] * e1[1], tv[2] * e1[0] - tv[0] * e1[2],
                              tv[0] * e1[1] - tv[1] * e1[0]};
        const double v = (d[0] * qv[0] + d[1] * qv[1] + d[2] * qv[2]) * inv;
        if (v < 0.0 || u + v > 1.0) return -1.0;
        const double t = (e2[0] * qv[0] + e2[1] * qv[1] + e2[2] * qv[2]) * inv;
        return t >= 0.0 && t <= 1.0 ? t : -1.0;
    }

    /// Earliest hit of the motion o → o + d with the two triangles of tile (i, j); -1 if none.
    double hit_tile(int i, int j, const double o[3], const double d[3]) const {
        if (w_ < 2 || hgt_ < 2) return -1.0;
        const double x0 = i * cell_, x1 = (i + 1) * cell_, z0 = j * cell_, z1 = (j + 1) * cell_;
        const double a[3] = {x0, H(i, j), z0}, b[3] = {x1, H(i + 1, j), z0};
        const double c[3] = {x0, H(i, j + 1), z1}, e[3] = {x1, H(i + 1, j + 1), z1};
        // A motion that stays above the tile's highest corner cannot cross its triangles (most particles
        // off the ground): skip the two ray tests.
        if (std::min(o[1], o[1] + d[1]) > std::max(std::max(a[1], b[1]), std::max(c[1], e[1]))) return -1.0;
        double best = -1.0;
        for (double t : {ray_triangle(o, d, a, b, e), ray_triangle(o, d, a, e, c)})
            if (t >= 0.0 && (best < 0.0 || t < best)) best = t;
        return best;
    }

    /// Earliest hit of the motion o → o + d (m) with the triangles of the tiles beneath its start and its end
    /// (p = o + d); -1 if none.
    double hit_motion(const double o[3], const double d[3], const double p[3]) const {
        int ti, tj, ui, uj;
        double fx, fz;
        tile(o[0], o[2], ti, tj, fx, fz);
        tile(p[0], p[2], ui, uj, fx, fz);
        double t = hit_tile(ti, tj, o, d);
        if (ui != ti || uj != tj) {
            const double t2 = hit_tile(ui, uj, o, d);
            if (t2 >= 0.0 && (t < 0.0 || t2 < t)) t = t2;
        }
        return t;
    }

    /// Lift a float height onto or above the surface height `ys` (rounding up).
    float above(double ys) const {
        float f = float(ys + 1e-4 * radius_);
        while (double(f) < ys) f = std::nextafter(f, std::numeric_limits<float>::infinity());
        return f;
    }

    /// Add `volume` m³ to the terrain at (x, z), spread bilinearly over the tile's vertices.
    void exchange_terrain(double x, double z, double volume) {
        int i, j;
        double fx, fz;
        tile(x, z, i, j, fx, fz);
        for (int r = j; r <= std::min(j + 1, hgt_ - 1); ++r) {
            dirty_lo_[std::size_t(r)] = std::min(dirty_lo_[std::size_t(r)], i);
            dirty_hi_[std::size_t(r)] = std::max(dirty_hi_[std::size_t(r)], std::min(i + 1, w_ - 1));
        }
        any_dirty_ = true;
        const double dh = volume * inv_cell_ * inv_cell_;
        const auto at = [&](int a, int b) -> double& {
            return terrain_[std::size_t(std::min(b, hgt_ - 1)) * std::size_t(w_) + std::size_t(std::min(a, w_ - 1))];
        };
        if (w_ == 1 || hgt_ == 1) {
            at(i, j) += dh;
            return;
        }
        at(i, j) += dh * (1 - fx) * (1 - fz);
        at(i + 1, j) += dh * fx * (1 - fz);
        at(i, j + 1) += dh * (1 - fx) * fz;
        at(i + 1, j + 1) += dh * fx * fz;
    }

    /// exchange_terrain (w, hgt ≥ 2) restricted to the rows for which `mine(row)`; true if it skipped one.
    /// Rows that only one thread's `mine` accepts may be changed in parallel (see Simulation::Impl::settle).
    template <typename Mine>
    bool exchange_rows(double x, double z, double volume, Mine mine) {
        int i, j;
        double fx, fz;
        tile(x, z, i, j, fx, fz);
        const double dh = volume * inv_cell_ * inv_cell_;
        const int i1 = std::min(i + 1, w_ - 1);
        bool skipped = false;
        for (int r = j; r <= std::min(j + 1, hgt_ - 1); ++r) {
            if (!mine(r)) {
                skipped = true;
                continue;
            }
            dirty_lo_[std::size_t(r)] = std::min(dirty_lo_[std::size_t(r)], i);
            dirty_hi_[std::size_t(r)] = std::max(dirty_hi_[std::size_t(r)], i1);
            double* row = &terrain_[std::size_t(r) * std::size_t(w_)];
            const double fr = r == j ? 1 - fz : fz;
            // The same products, in the same order, as exchange_terrain.
            row[i] += dh * (1 - fx) * fr;
            row[i1] += dh * fx * fr;
        }
        return skipped;
    }
    /// After exchange_rows changed the terrain: the normals are refreshed at the next refresh_normals().
    void mark_dirty() { any_dirty_ = true; }

    /// Recompute the cached vertex normals whose stencil (the vertex and its 4
    /// neighbours) holds a vertex an exchange changed: per row, the union of
    /// the dirty spans of the rows above, itself and below, widened by one.
    void refresh_normals();

    /// Add a particle's `volume` m³ of water at (x, z) to the water depth summed per vertex (bilinear, as
    /// exchange_terrain); end_water_step() counts the steps the mean is over.
    void add_water(double x, double z, double volume) {
        int ti, tj;
        double fx, fz;
        tile(x, z, ti, tj, fx, fz);
        const double vcell = volume * inv_cell_ * inv_cell_;  // m of depth
        auto at = [&](int a, int b) -> double& {
            return water_sum_[std::size_t(std::min(b, hgt_ - 1)) * std::size_t(w_) + std::size_t(std::min(a, w_ - 1))];
        };
        at(ti, tj) += vcell * (1 - fx) * (1 - fz);
        at(ti + 1, tj) += vcell * fx * (1 - fz);
        at(ti, tj + 1) += vcell * (1 - fx) * fz;
        at(ti + 1, tj + 1) += vcell * fx * fz;
    }
    void end_water_step() { ++water_steps_; }

private:
    void vertex_normal(int x, int z, double n[3]) const;
    void store_normal(int x, int z);

    int w_ = 0, hgt_ = 0;
    double cell_ = 1.0, inv_cell_ = 1.0;
    double extent_x_ = 0.0, extent_z_ = 0.0;
    double radius_ = 0.0;
    std::vector<double> terrain_;
    std::vector<double> water_sum_;  // Σ over steps of the water depth per vertex, m
    std::int64_t water_steps_ = 0;
    // The vertex normals (x, y, z per vertex), kept current: the exchanges mark the span of each row they
    // changed (dirty_lo..dirty_hi, vertex columns) and refresh_normals() recomputes what those changes reach.
    // normal() runs several times per particle and sub-step; from scratch each took 4 square roots.
    std::vector<float> vnormal_;
    std::vector<int> dirty_lo_, dirty_hi_;
    bool any_dirty_ = false;
};

/// The terrain's share of the kernel, as if the fluid's rest lattice continued below it (Akinci et al.
/// 2012's boundary particles, summed once into a table): at distance d = k·h/kSteps from the ground, phi[k]
/// is the missing neighbours' Σ V·W (a density fraction) and area[k] their Σ V·(−∂W/∂d) (1/m).
class WallTable {
public:
    static constexpr int kSteps = 64;

    /// Tabulate, once per simulation, for particles of `volume` m³. The half-space behind a wall is filled
    /// with the fluid's own rest lattice (spacing 2·radius, layers at d + spacing/2, d + 3·spacing/2, ...
    /// behind the particle, columns aligned with it), summed exactly rather than integrated: WCSPH's pressure
    /// is B((ρ/ρ0)⁷ − 1), so a 1 % mismatch between the wall's share and the missing neighbours is several
    /// kPa. With the lattice sum, a particle resting on the floor has the interior's density exactly.
    void tabulate(const CubicSpline& kernel, float volume);

    /// Add the share of a wall at distance d (m, ≥ 0 in front of it) with unit normal (nx, ny, nz) into the
    /// fluid: to the density fraction `phi` and the push `push`.
    void add(double d, double nx, double ny, double nz, float& phi, Vec3& push) const {
        if (!(d < double(h_))) return;
        const double u = std::max(d, 0.0) / double(h_) * kSteps;
        const int k = std::min(int(u), kSteps - 1);
        const float f = float(u - k);
        const std::size_t a = std::size_t(k), b = a + 1;
        phi += phi_[a] + f * (phi_[b] - phi_[a]);
        const float area = area_[a] + f * (area_[b] - area_[a]);
        push.x += area * float(nx);
        push.y += area * float(ny);
        push.z += area * float(nz);
    }

    /// Where two walls meet (the map's side walls with each other or with the ground), both half-spaces hold
    /// the quadrant behind the two: add() counted it twice. Subtract it once, at distances d1, d2 (m, ≥ 0) in
    /// front of walls with unit normals n1, n2 (taken as perpendicular): its lattice points (d1 + s/2 + i·s,
    /// d2 + s/2 + j·s) behind them, columns aligned with the particle along the edge, summed directly (a few
    /// dozen points, only for particles within the support of two walls).
    void subtract_quadrant(double d1, double d2, const double n1[3], const double n2[3], float& phi, Vec3& push) const;
    /// Where three walls meet (a corner of the map's floor), the octant behind all three was added three times
    /// by add() and subtracted three times by subtract_quadrant(): add it back once (inclusion–exclusion).
    void add_octant(const double d[3], const double* const n[3], float& phi, Vec3& push) const;

private:
    /// Σ V·W and Σ V·(−∂W/∂d_k) over the lattice points behind `walls` (2 or 3) walls at distances d (m).
    void corner_sum(int walls, const double d[3], double& phi, double area[3]) const;

    CubicSpline kernel_;
    double spacing_ = 0, volume_ = 0;  // the fluid's rest lattice: m, m³
    float h_ = 0;  // the kernel's support, m
    std::array<float, kSteps + 1> phi_{}, area_{};
};

}  // namespace orogen::sph
