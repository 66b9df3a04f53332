// kernels.hpp — the SPH kernel (cubic spline, support h) and the neighbour sums that run in vector lanes.
//
// CubicSpline is called per particle pair outside the lane loops (the wall table) and stays inline here.
// The lane sums (density_sum, force_sum, pressure_terms) live in kernels.cpp: each is built for several
// instruction sets and picked at load time (OROGEN_SPH_CLONES), so a call goes through that choice and
// is never inlined anyway; one call per particle, the loop inside it over a cell's ~100 candidates.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>

namespace orogen::sph {

// Runtime dispatch: GCC builds these loops for AVX-512, AVX2 and the x86-64
// baseline and picks one at load time (any x86-64 runs it; the result bits are
// the same for every clone, see kLanes).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__) && \
    !defined(__SANITIZE_THREAD__) && !defined(OROGEN_SPH_NO_CLONES)
#define OROGEN_SPH_CLONES __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define OROGEN_SPH_CLONES
#endif

// Candidates are evaluated in kLanes independent partial sums, combined in a
// fixed order at the end: the compiler maps the lanes onto whatever vector
// width the clone it runs has (SSE2, AVX2, AVX-512), and since every lane is
// plain IEEE float arithmetic (no FMA: -ffp-contract=off, no reassociation),
// every clone, thread count and machine gives the same bits.
constexpr std::size_t kLanes = 16;
// Padding candidates sit this far away (m): beyond any support, and still
// finite when squared (3e30 < FLT_MAX), so masked lanes stay NaN-free.
constexpr float kFar = 1e15f;

/// The cubic spline kernel (Monaghan 1992) with support h, in 3-D: W(q) = w_norm · shape(q), q = r/h,
/// shape = 6q²(q − 1) + 1 for q ≤ 1/2 and 2(1 − q)³ beyond. The constants are derived from h once.
struct CubicSpline {
    float h = 0, h2 = 0, inv_h = 0;  ///< support m, m², 1/m
    float w_norm = 0;  ///< 8/(π h³), 1/m³
    float grad_norm = 0;  ///< 48/(π h³), 1/m³: dW/dq = grad_norm · shape'(q) with shape' below

    static CubicSpline with_support(float h) {
        CubicSpline k;
        k.h = h;
        k.h2 = h * h;
        k.inv_h = 1.0f / h;
        const double hh = h;
        k.w_norm = float(8.0 / (std::numbers::pi * hh * hh * hh));
        k.grad_norm = float(48.0 / (std::numbers::pi * hh * hh * hh));
        return k;
    }

    /// W(r) in 1/m³, from r² in m².
    float kernel(float r2) const {
        const float q = std::sqrt(r2) * inv_h;
        const float f = 1.0f - q;
        const float inner = 6.0f * q * q * (q - 1.0f) + 1.0f, outer = 2.0f * f * f * f;
        return w_norm * (q <= 0.5f ? inner : outer);
    }
    /// dW/dr / r in 1/m⁵ (multiply by the separation vector for ∇W).
    float grad(float r2) const {
        // The particle itself (r = 0) contributes nothing: its separation vector is zero.
        const float r = std::max(std::sqrt(r2), 1e-12f);
        const float q = r * inv_h;
        const float inner = q * (3.0f * q - 2.0f), outer = -(1.0f - q) * (1.0f - q);
        return grad_norm * (q <= 0.5f ? inner : outer) * inv_h / r;
    }
};

/// The support as the neighbour sums use it: h² (m²) and 1/h (1/m).
struct Support {
    float h2, inv_h;
};

/// A cell's candidate positions for the density pass (structure of arrays, kLanes-padded).
struct DensityCandidates {
    const float *x, *y, *z;
};

/// Σ over candidates within the support of the cubic spline's shape
/// (W / w_norm, dimensionless) at (px, py, pz). The candidate arrays hold `m`
/// entries, a multiple of kLanes (padded with far-away points).
float density_sum(const DensityCandidates& c, std::size_t m, float px, float py, float pz, Support support);

/// Tait's equation of state, p = B((ρ/ρ0)⁷ − 1) clamped at 0 (Pa), stored as p/ρ² (m⁵/(kg·s²)) for the
/// force pass, for `count` particles.
void pressure_terms(const float* __restrict rho, float* __restrict pterm, std::size_t count, float rho0, float B);

/// The candidates' fields for the force pass (structure of arrays, kLanes-padded).
struct ForceCandidates {
    const float *x, *y, *z, *vx, *vy, *vz, *pterm, *rho;
};

/// The particle a force sum is for: position (m), velocity (m/s), p/ρ² (m⁵/(kg·s²)) and ρ (kg/m³).
struct ForceParticle {
    float x, y, z, vx, vy, vz, pterm, rho;
};

/// The force pass's constants: the support, and Monaghan's viscosity as force_sum uses it (visc_eps the
/// 0.01 (h/2)² that keeps Π finite, m²; visc_k = 2 α c0 h/2, m²/s).
struct ForceConstants {
    Support support;
    float visc_eps, visc_k;
};

/// Σ_j (p_i/ρ_i² + p_j/ρ_j² + Π_ij) · shape'(q) / r · r_ij over the candidates
/// within the support (shape' the cubic spline's derivative without its
/// normalisation): particle i's pressure + viscosity acceleration in m/s² is
/// −m · grad_norm / h times the result, applied by the caller. One division
/// per pair: Π's two denominators and 1/r share it.
void force_sum(const ForceCandidates& c, std::size_t m, const ForceParticle& p, const ForceConstants& fk, float out[3]);

}  // namespace orogen::sph
