// kernels.cpp — the neighbour sums in kLanes vector lanes (see kernels.hpp), one build per instruction set.
#include "kernels.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace orogen::sph {

namespace {

/// Combine the lanes in a fixed pairwise order, in place (a copy went through the stack and cost a
/// quarter of force_sum).
inline float lane_sum(float* a) {
    for (std::size_t w = kLanes / 2; w > 0; w /= 2)
        for (std::size_t l = 0; l < w; ++l) a[l] = a[l] + a[l + w];
    return a[0];
}

}  // namespace

OROGEN_SPH_CLONES
float density_sum(const DensityCandidates& c, std::size_t m, float px, float py, float pz, Support support) {
    const float* __restrict cx = c.x;
    const float* __restrict cy = c.y;
    const float* __restrict cz = c.z;
    const float h2 = support.h2, inv_h = support.inv_h;
    float acc[kLanes] = {};
    for (std::size_t k = 0; k < m; k += kLanes)
        for (std::size_t l = 0; l < kLanes; ++l) {
            const float dx = px - cx[k + l], dy = py - cy[k + l], dz = pz - cz[k + l];
            const float r2 = dx * dx + dy * dy + dz * dz;
            const float q = std::sqrt(r2) * inv_h;
            const float f = 1.0f - q;
            const float inner = 6.0f * q * q * (q - 1.0f) + 1.0f, outer = 2.0f * f * f * f;
            const float wq = q <= 0.5f ? inner : outer;
            acc[l] += r2 < h2 ? wq : 0.0f;
        }
    return lane_sum(acc);
}

OROGEN_SPH_CLONES
void pressure_terms(const float* __restrict rho, float* __restrict pterm, std::size_t count, float rho0, float B) {
    for (std::size_t i = 0; i < count; ++i) {
        const float ratio = rho[i] / rho0;
        const float r2 = ratio * ratio;
        const float p = std::max(0.0f, B * (r2 * r2 * r2 * ratio - 1.0f));
        pterm[i] = p / (rho[i] * rho[i]);
    }
}

OROGEN_SPH_CLONES
void force_sum(const ForceCandidates& c, std::size_t m, const ForceParticle& p, const ForceConstants& fk,
               float out[3]) {
    // The particle and the constants in locals (registers through the loop; no store can alias them).
    const float px = p.x, py = p.y, pz = p.z, vx = p.vx, vy = p.vy, vz = p.vz, pi = p.pterm, rhoi = p.rho;
    const float h2 = fk.support.h2, inv_h = fk.support.inv_h, visc_eps = fk.visc_eps, visc_k = fk.visc_k;
    float ax[kLanes] = {}, ay[kLanes] = {}, az[kLanes] = {};
    const float* __restrict X = c.x;
    const float* __restrict Y = c.y;
    const float* __restrict Z = c.z;
    const float* __restrict VX = c.vx;
    const float* __restrict VY = c.vy;
    const float* __restrict VZ = c.vz;
    const float* __restrict P = c.pterm;
    const float* __restrict R = c.rho;
    for (std::size_t k = 0; k < m; k += kLanes)
        for (std::size_t l = 0; l < kLanes; ++l) {
            const std::size_t j = k + l;
            const float dx = px - X[j], dy = py - Y[j], dz = pz - Z[j];
            const float r2 = dx * dx + dy * dy + dz * dz;
            const float ux = vx - VX[j], uy = vy - VY[j], uz = vz - VZ[j];
            const float vr = ux * dx + uy * dy + uz * dz;
            // term = pi + pj − visc_k·vr / ((r² + ε)(ρi + ρj)) for approaching pairs (Monaghan's Π),
            // over one denominator D = (r² + ε)(ρi + ρj).
            const float d = (r2 + visc_eps) * (rhoi + R[j]);
            const float visc = vr < 0.0f ? visc_k * vr : 0.0f;
            const float num = (pi + P[j]) * d - visc;
            // The particle itself (r = 0) adds nothing: its separation vector is zero.
            const float r = std::max(std::sqrt(r2), 1e-12f);
            const float q = r * inv_h;
            const float inner = q * (3.0f * q - 2.0f), outer = -(1.0f - q) * (1.0f - q);
            const float shape = q <= 0.5f ? inner : outer;
            const float f = num * shape / (d * r);
            const float g = r2 < h2 ? f : 0.0f;
            ax[l] += g * dx;
            ay[l] += g * dy;
            az[l] += g * dz;
        }
    out[0] = lane_sum(ax);
    out[1] = lane_sum(ay);
    out[2] = lane_sum(az);
}

}  // namespace orogen::sph
