// terrain_boundary.cpp — see terrain_boundary.hpp.
#include "terrain_boundary.hpp"

#include <orogen/parallel.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace orogen::sph {

TerrainBoundary::TerrainBoundary(ConstGridView terrain, double radius)
    : w_(terrain.width), hgt_(terrain.height), cell_(terrain.cell), inv_cell_(1.0 / terrain.cell),
      extent_x_((terrain.width - 1) * terrain.cell), extent_z_((terrain.height - 1) * terrain.cell), radius_(radius),
      terrain_(terrain.data, terrain.data + terrain.size()), water_sum_(terrain.size(), 0.0),
      vnormal_(3 * terrain.size()), dirty_lo_(std::size_t(terrain.height), 0),
      dirty_hi_(std::size_t(terrain.height), terrain.width - 1), any_dirty_(true) {
    refresh_normals();  // all of them
}

void TerrainBoundary::vertex_normal(int x, int z, double n[3]) const {
    const int x0 = std::max(x - 1, 0), x1 = std::min(x + 1, w_ - 1);
    const int z0 = std::max(z - 1, 0), z1 = std::min(z + 1, hgt_ - 1);
    // Central differences (one-sided at the map's edges), 1/m; multiplications, not divisions: this runs
    // for every vertex an exchange reaches, every sub-step.
    const double sx = x1 - x0 == 2 ? 0.5 * inv_cell_ : inv_cell_, sz = z1 - z0 == 2 ? 0.5 * inv_cell_ : inv_cell_;
    const double dx = x1 > x0 ? (H(x1, z) - H(x0, z)) * sx : 0.0;
    const double dz = z1 > z0 ? (H(x, z1) - H(x, z0)) * sz : 0.0;
    const double il = 1.0 / std::sqrt(dx * dx + dz * dz + 1.0);
    n[0] = -dx * il;
    n[1] = il;
    n[2] = -dz * il;
}

void TerrainBoundary::store_normal(int x, int z) {
    double nv[3];
    vertex_normal(x, z, nv);
    float* o = &vnormal_[3 * (std::size_t(z) * std::size_t(w_) + std::size_t(x))];
    for (int k = 0; k < 3; ++k) o[k] = float(nv[k]);
}

void TerrainBoundary::refresh_normals() {
    if (!any_dirty_) return;
    parallel_for(0, hgt_, 16, [&](std::int64_t z0, std::int64_t z1) {
        for (std::int64_t zz = z0; zz < z1; ++zz) {
            const auto z = std::size_t(zz);
            int lo = w_, hi = -1;
            for (std::size_t r = z == 0 ? 0 : z - 1; r <= std::min(z + 1, std::size_t(hgt_ - 1)); ++r) {
                lo = std::min(lo, dirty_lo_[r]);
                hi = std::max(hi, dirty_hi_[r]);
            }
            for (int x = std::max(lo - 1, 0); x <= std::min(hi + 1, w_ - 1); ++x) store_normal(x, int(z));
        }
    });
    std::fill(dirty_lo_.begin(), dirty_lo_.end(), w_);
    std::fill(dirty_hi_.begin(), dirty_hi_.end(), -1);
    any_dirty_ = false;
}

void WallTable::tabulate(const CubicSpline& kernel, float volume) {
    h_ = kernel.h;
    kernel_ = kernel;
    const double spacing = std::cbrt(double(volume));
    spacing_ = spacing;
    volume_ = double(volume);
    const int reach = int(std::ceil(double(kernel.h) / spacing)) + 1;
    auto layer = [&](double z, double& phi, double& area) {  // one lattice layer at distance z behind
        for (int a = -reach; a <= reach; ++a)
            for (int b = -reach; b <= reach; ++b) {
                const double r2 = (a * a + b * b) * spacing * spacing + z * z;
                if (r2 >= double(kernel.h2)) continue;
                phi += double(volume) * double(kernel.kernel(float(r2)));
                area -= double(volume) * double(kernel.grad(float(r2))) * z;  // −∂W/∂z, ≥ 0
            }
    };
    for (int k = 0; k <= kSteps; ++k) {
        const double d = double(kernel.h) * k / kSteps;
        double phi = 0.0, area = 0.0;
        for (double z = d + 0.5 * spacing; z < double(kernel.h); z += spacing) layer(z, phi, area);
        phi_[std::size_t(k)] = float(phi);
        area_[std::size_t(k)] = float(area);
    }
}

void WallTable::corner_sum(int walls, const double d[3], double& phi, double area[3]) const {
    const double s = spacing_, h = double(kernel_.h), h2 = double(kernel_.h2);
    const int reach = int(std::ceil(h / s)) + 1;
    // Behind a wall: layers at d + s/2, d + 3s/2, ... (as in tabulate); along the edge (2 walls): the
    // particle's own column and reach columns either side.
    int lo[3];
    for (int k = 0; k < 3; ++k) lo[k] = k < walls ? 0 : -reach;
    phi = 0.0;
    area[0] = area[1] = area[2] = 0.0;
    for (int i = lo[0]; i <= reach; ++i)
        for (int j = lo[1]; j <= reach; ++j)
            for (int l = lo[2]; l <= reach; ++l) {
                const int idx[3] = {i, j, l};
                double u[3], r2 = 0.0;
                for (int k = 0; k < 3; ++k) {
                    u[k] = k < walls ? d[k] + (0.5 + idx[k]) * s : idx[k] * s;
                    r2 += u[k] * u[k];
                }
                if (r2 >= h2) continue;
                phi += volume_ * double(kernel_.kernel(float(r2)));
                const double g = -volume_ * double(kernel_.grad(float(r2)));  // −(dW/dr)/r ≥ 0
                for (int k = 0; k < walls; ++k) area[k] += g * u[k];
            }
}

void WallTable::subtract_quadrant(double d1, double d2, const double n1[3], const double n2[3], float& phi,
                                  Vec3& push) const {
    const double d[3] = {std::max(d1, 0.0), std::max(d2, 0.0), 0.0};
    double f, a[3];
    corner_sum(2, d, f, a);
    phi -= float(f);
    push.x -= float(a[0] * n1[0] + a[1] * n2[0]);
    push.y -= float(a[0] * n1[1] + a[1] * n2[1]);
    push.z -= float(a[0] * n1[2] + a[1] * n2[2]);
}

void WallTable::add_octant(const double d[3], const double* const n[3], float& phi, Vec3& push) const {
    const double dd[3] = {std::max(d[0], 0.0), std::max(d[1], 0.0), std::max(d[2], 0.0)};
    double f, a[3];
    corner_sum(3, dd, f, a);
    phi += float(f);
    push.x += float(a[0] * n[0][0] + a[1] * n[1][0] + a[2] * n[2][0]);
    push.y += float(a[0] * n[0][1] + a[1] * n[1][1] + a[2] * n[2][1]);
    push.z += float(a[0] * n[0][2] + a[1] * n[1][2] + a[2] * n[2][2]);
}

}  // namespace orogen::sph
