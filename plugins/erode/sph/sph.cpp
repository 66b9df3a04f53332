// sph.cpp — see sph.hpp for the model.
#include "sph.hpp"

#include <orogen/error.hpp>
#include <orogen/parallel.hpp>
#include <orogen/random.hpp>
#include <orogen/values.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <array>
#include <numbers>
#include <sstream>
#include <type_traits>

namespace orogen::sph {

namespace {

constexpr std::int64_t kGrain = 512;      // particles per parallel task (integration)
constexpr std::int64_t kCellGrain = 64;   // cells per parallel task (density, forces)
constexpr float kCellLimit = 524288.0f;   // 2^19: cell coordinates are clamped to ±this (keys fit 63 bits)
// Candidates are evaluated in kLanes independent partial sums, combined in a
// fixed order at the end: the compiler maps the lanes onto whatever vector
// width the clone it runs has (SSE2, AVX2, AVX-512), and since every lane is
// plain IEEE float arithmetic (no FMA: -ffp-contract=off, no reassociation),
// every clone, thread count and machine gives the same bits.
constexpr std::size_t kLanes = 16;
// Padding candidates sit this far away (m): beyond any support, and still
// finite when squared (3e30 < FLT_MAX), so masked lanes stay NaN-free.
constexpr float kFar = 1e15f;

bool finite3(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// Combine the lanes in a fixed pairwise order, in place (a copy went through the stack and cost a
/// quarter of force_sum).
inline float lane_sum(float* a) {
    for (std::size_t w = kLanes / 2; w > 0; w /= 2)
        for (std::size_t l = 0; l < w; ++l) a[l] = a[l] + a[l + w];
    return a[0];
}

// Runtime dispatch: GCC builds these loops for AVX-512, AVX2 and the x86-64
// baseline and picks one at load time (any x86-64 runs it; the result bits are
// the same for every clone, see kLanes).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__) && \
    !defined(__SANITIZE_THREAD__) && !defined(OROGEN_SPH_NO_CLONES)
#define OROGEN_SPH_CLONES __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define OROGEN_SPH_CLONES
#endif

/// Σ over candidates within the support of the cubic spline's shape
/// (W / w_norm, dimensionless) at (px, py, pz). The candidate arrays hold `m`
/// entries, a multiple of kLanes (padded with far-away points).
OROGEN_SPH_CLONES
float density_sum(const float* __restrict cx, const float* __restrict cy, const float* __restrict cz, std::size_t m,
                  float px, float py, float pz, float h2, float inv_h) {
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

/// Tait's equation of state, p = B((ρ/ρ0)⁷ − 1) clamped at 0 (Pa), stored as p/ρ² (m⁵/(kg·s²)) for the
/// force pass, for `count` particles.
OROGEN_SPH_CLONES
void pressure_terms(const float* __restrict rho, float* __restrict pterm, std::size_t count, float rho0, float B) {
    for (std::size_t i = 0; i < count; ++i) {
        const float ratio = rho[i] / rho0;
        const float r2 = ratio * ratio;
        const float p = std::max(0.0f, B * (r2 * r2 * r2 * ratio - 1.0f));
        pterm[i] = p / (rho[i] * rho[i]);
    }
}

/// The candidates' fields for the force pass (structure of arrays, kLanes-padded).
struct ForceCandidates {
    const float *x, *y, *z, *vx, *vy, *vz, *pterm, *rho;
};

/// Σ_j (p_i/ρ_i² + p_j/ρ_j² + Π_ij) · shape'(q) / r · r_ij over the candidates
/// within the support (shape' the cubic spline's derivative without its
/// normalisation): particle i's pressure + viscosity acceleration in m/s² is
/// −m · grad_norm / h times the result, applied by the caller. One division
/// per pair: Π's two denominators and 1/r share it.
OROGEN_SPH_CLONES
void force_sum(const ForceCandidates& c, std::size_t m, float px, float py, float pz, float vx, float vy, float vz,
               float pi, float rhoi, float h2, float inv_h, float visc_eps, float visc_k, float out[3]) {
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

/// A cell's candidates are copied in whole blocks of kSlack floats (a row of a few cells: memcpy's call
/// costs more than the copy): up to kSlack − 1 floats past a run are read and written, so the source
/// arrays and the candidate buffers have that much slack at the end (what is written past a run is then
/// overwritten by the next run or the padding).
constexpr std::size_t kSlack = 8;

/// Candidate buffers per thread, kept across tasks and sub-steps (density_pass uses the first 3,
/// force_pass all 8): vectors of a task's own were allocated and zero-filled anew for every task. Neither
/// pass starts parallel work inside a task, so a thread runs one task at a time on them.
struct Scratch {
    std::vector<float> buf[8];
};
thread_local Scratch scratch;

/// Gather a cell's candidates: the runs [run[r][0], run[r][1]) of A source arrays, one run after
/// another, into A destination arrays, copied for all A arrays per block of kSlack floats (see
/// kSlack: up to kSlack − 1 floats past each run are read and written). One loop per run for all
/// arrays: with a loop per run and array, the loops' set-up cost more than the copies (runs of ~20).
/// Returns the candidates gathered.
template <int A>
inline std::size_t gather_runs(const float* const (&from)[A], float* const (&to)[A], const std::uint32_t (*run)[2],
                               int nr) {
    std::size_t k = 0;
    for (int r = 0; r < nr; ++r) {
        const std::size_t j = run[r][0], len = run[r][1] - run[r][0];
        for (std::size_t b = 0; b < len; b += kSlack)
            for (int a = 0; a < A; ++a) {
                float t[kSlack];
                for (std::size_t l = 0; l < kSlack; ++l) t[l] = from[a][j + b + l];
                for (std::size_t l = 0; l < kSlack; ++l) to[a][k + b + l] = t[l];
            }
        k += len;
    }
    return k;
}
OROGEN_SPH_CLONES
std::size_t gather3(const float* const (&from)[3], float* const (&to)[3], const std::uint32_t (*run)[2], int nr) {
    return gather_runs<3>(from, to, run, nr);
}
OROGEN_SPH_CLONES
std::size_t gather8(const float* const (&from)[8], float* const (&to)[8], const std::uint32_t (*run)[2], int nr) {
    return gather_runs<8>(from, to, run, nr);
}

/// Grow a scratch buffer to at least `m` entries (never shrinks: reused across cells).
inline float* room(std::vector<float>& v, std::size_t m) {
    if (v.size() < m) v.resize(m + m / 2);
    return v.data();
}

}  // namespace

struct Simulation::Impl {
    Settings s;
    // Terrain, kept in double so the exchange with the particles conserves material.
    int w = 0, hgt = 0;
    double cell = 1.0, inv_cell = 1.0;
    double extent_x = 0.0, extent_z = 0.0;
    std::vector<double> terrain;
    std::vector<double> water_sum;  // Σ over steps of the water depth per vertex, m
    // The vertex normals (x, y, z per vertex), kept current: exchange_terrain() marks the span of each row it
    // changed (dirty_lo..dirty_hi, vertex columns) and refresh_normals() recomputes what those changes reach.
    // normal() runs several times per particle and sub-step; from scratch each took 4 square roots.
    std::vector<float> vnormal;
    std::vector<int> dirty_lo, dirty_hi;
    bool any_dirty = false;
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
    // Neighbour search (sort_by_cell): the particles are sorted by cell every sub-step; `ncell` occupied
    // cells, each with its key and its first particle. sort_keys holds two key arrays (the radix sort's
    // ping-pong), reused as the permutation's 16 bytes per particle of scratch.
    std::vector<std::uint64_t> sort_keys;
    std::vector<std::uint32_t> perm, perm_tmp;
    std::vector<std::uint8_t> moved;  // per sorted entry: changed cell since the last sort (merge_movers)
    std::int64_t merged_sorts = 0;    // sorts done by merge_movers
    std::size_t keyed = 0;            // particles [0, keyed) have a cell from the last sort (in soa)
    std::vector<std::uint32_t> radix_offset;                           // radix_sort's histograms
    std::vector<std::pair<std::uint64_t, std::uint32_t>> mover_list;  // merge_movers' movers
    std::vector<std::uint64_t> cell_key;
    std::vector<std::uint32_t> cell_start;
    std::size_t ncell = 0;
    std::uint64_t stride_y = 1, stride_z = 1;  // key steps of one cell in y and z (x: 1)
    int min_cx = 0, min_cy = 0, min_cz = 0;    // the padded box's first cell
    std::array<std::vector<float>, 6> soa;     // x, y, z (m), vx, vy, vz (m/s) of the sorted particles

    Counts counts;
    std::int64_t substeps = 0;
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
        return surface_in(i, j, fx, fz);
    }
    /// surface() in tile (i, j) at fractions (fx, fz), as tile() gives them.
    double surface_in(int i, int j, double fx, double fz) const {
        if (w == 1 || hgt == 1) return H(0, 0);
        const double a = H(i, j), b = H(i + 1, j), c = H(i, j + 1), d = H(i + 1, j + 1);
        if (fx >= fz) return a + fx * (b - a) + fz * (d - b);
        return a + fz * (c - a) + fx * (d - c);
    }

    void vertex_normal(int x, int z, double n[3]) const {
        const int x0 = std::max(x - 1, 0), x1 = std::min(x + 1, w - 1);
        const int z0 = std::max(z - 1, 0), z1 = std::min(z + 1, hgt - 1);
        // Central differences (one-sided at the map's edges), 1/m; multiplications, not divisions: this runs
        // for every particle near the ground several times a sub-step.
        const double sx = x1 - x0 == 2 ? 0.5 * inv_cell : inv_cell, sz = z1 - z0 == 2 ? 0.5 * inv_cell : inv_cell;
        const double dx = x1 > x0 ? (H(x1, z) - H(x0, z)) * sx : 0.0;
        const double dz = z1 > z0 ? (H(x, z1) - H(x, z0)) * sz : 0.0;
        const double il = 1.0 / std::sqrt(dx * dx + dz * dz + 1.0);
        n[0] = -dx * il;
        n[1] = il;
        n[2] = -dz * il;
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
        if (w == 1 || hgt == 1) {
            n[0] = 0, n[1] = 1, n[2] = 0;
            return;
        }
        const float* a = &vnormal[3 * (std::size_t(j) * std::size_t(w) + std::size_t(i))];
        const float* b = a + 3;
        const float* c = a + 3 * std::size_t(w);
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
        // A motion that stays above the tile's highest corner cannot cross its triangles (most particles
        // off the ground): skip the two ray tests.
        if (std::min(o[1], o[1] + d[1]) > std::max(std::max(a[1], b[1]), std::max(c[1], e[1]))) return -1.0;
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
        for (int r = j; r <= std::min(j + 1, hgt - 1); ++r) {
            dirty_lo[std::size_t(r)] = std::min(dirty_lo[std::size_t(r)], i);
            dirty_hi[std::size_t(r)] = std::max(dirty_hi[std::size_t(r)], std::min(i + 1, w - 1));
        }
        any_dirty = true;
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

    /// Recompute the cached vertex normals whose stencil (the vertex and its 4
    /// neighbours) holds a vertex exchange_terrain() changed: per row, the
    /// union of the dirty spans of the rows above, itself and below, widened by one.
    void refresh_normals() {
        if (!any_dirty) return;
        parallel_for(0, hgt, 16, [&](std::int64_t z0, std::int64_t z1) {
            for (std::int64_t zz = z0; zz < z1; ++zz) {
                const auto z = std::size_t(zz);
                int lo = w, hi = -1;
                for (std::size_t r = z == 0 ? 0 : z - 1; r <= std::min(z + 1, std::size_t(hgt - 1)); ++r) {
                    lo = std::min(lo, dirty_lo[r]);
                    hi = std::max(hi, dirty_hi[r]);
                }
                for (int x = std::max(lo - 1, 0); x <= std::min(hi + 1, w - 1); ++x) store_normal(x, int(z));
            }
        });
        std::fill(dirty_lo.begin(), dirty_lo.end(), w);
        std::fill(dirty_hi.begin(), dirty_hi.end(), -1);
        any_dirty = false;
    }
    void store_normal(int x, int z) {
        double nv[3];
        vertex_normal(x, z, nv);
        float* o = &vnormal[3 * (std::size_t(z) * std::size_t(w) + std::size_t(x))];
        for (int k = 0; k < 3; ++k) o[k] = float(nv[k]);
    }

    // --------------------------------------------------------- particles
    void kill(std::size_t i) {
        alive[i] = 0;
        --live;
    }

    /// Cell coordinate (in units of h) of a position in m, clamped so keys fit in 63 bits.
    float cell_of(float x) const { return std::clamp(std::floor(x * inv_h), -kCellLimit, kCellLimit); }

    /// Stable LSD radix sort of (key, idx) by the low `bits` bits of key: each pass, per-block digit
    /// histograms in parallel, their offsets in (digit, block) order, then each block scatters its own
    /// keys in order. Blocks of fixed size: the same permutation on any thread count. The result is left
    /// in key/idx (the pointers are swapped with the scratch t* as the passes go).
    void radix_sort(std::uint64_t*& key, std::uint64_t*& tkey, std::uint32_t*& idx, std::uint32_t*& tidx,
                    std::size_t m, int bits) {
        constexpr int kDigit = 11;
        constexpr std::size_t kDigits = std::size_t(1) << kDigit, kBlock = 16384;
        const std::size_t nblocks = (m + kBlock - 1) / kBlock;
        radix_offset.resize(nblocks * kDigits);
        for (int shift = 0; shift < bits; shift += kDigit) {
            parallel_for(0, std::int64_t(nblocks), 1, [&](std::int64_t b0, std::int64_t b1) {
                for (auto b = std::size_t(b0); b < std::size_t(b1); ++b) {
                    std::uint32_t* count = &radix_offset[b * kDigits];
                    std::fill(count, count + kDigits, 0u);
                    for (std::size_t k = b * kBlock; k < std::min(m, (b + 1) * kBlock); ++k)
                        ++count[(key[k] >> shift) & (kDigits - 1)];
                }
            });
            std::uint32_t run = 0;
            for (std::size_t d = 0; d < kDigits; ++d)
                for (std::size_t b = 0; b < nblocks; ++b) {
                    const std::uint32_t c = radix_offset[b * kDigits + d];
                    radix_offset[b * kDigits + d] = run;
                    run += c;
                }
            parallel_for(0, std::int64_t(nblocks), 1, [&](std::int64_t b0, std::int64_t b1) {
                for (auto b = std::size_t(b0); b < std::size_t(b1); ++b) {
                    std::uint32_t* cursor = &radix_offset[b * kDigits];
                    for (std::size_t k = b * kBlock; k < std::min(m, (b + 1) * kBlock); ++k) {
                        const std::uint32_t dst = cursor[(key[k] >> shift) & (kDigits - 1)]++;
                        tkey[dst] = key[k];
                        tidx[dst] = idx[k];
                    }
                }
            });
            std::swap(key, tkey);
            std::swap(idx, tidx);
        }
    }

    /// The stable sort of (key, idx) by key when few particles changed cell (`moved`, `movers` of the m):
    /// a stable sort orders by (key, idx), idx rising along the list, and the particles that kept their
    /// cell are already in that order (the last sort's, less the dead). So they are taken out in order,
    /// the movers sorted by (key, idx) on their own, and the two merged: the radix sort's permutation
    /// exactly, at a few per cent of the particles' sorting work. Blocks of the kept list merge in
    /// parallel, each with the movers between its first key and the next block's (a unique result).
    /// `mv_first[b]`: the movers before block b of kBlock entries (mv_first[blocks] = all of them).
    static constexpr std::size_t kMoverBlock = 16384;
    void merge_movers(std::uint64_t* key, std::uint64_t* tkey, std::uint32_t* idx, std::uint32_t* tidx,
                      std::size_t m, const std::vector<std::size_t>& mv_first) {
        constexpr std::size_t kBlock = kMoverBlock;
        const std::size_t blocks = (m + kBlock - 1) / kBlock;
        const std::size_t movers = mv_first[blocks];
        mover_list.resize(movers);
        parallel_for(0, std::int64_t(blocks), 1, [&](std::int64_t b0, std::int64_t b1) {
            for (auto b = std::size_t(b0); b < std::size_t(b1); ++b) {
                std::size_t mk = mv_first[b], sk = b * kBlock - mv_first[b];
                for (std::size_t k = b * kBlock; k < std::min(m, (b + 1) * kBlock); ++k)
                    if (moved[k]) {
                        mover_list[mk++] = {key[k], idx[k]};
                    } else {
                        tkey[sk] = key[k];
                        tidx[sk++] = idx[k];
                    }
            }
        });
        std::sort(mover_list.begin(), mover_list.end());
        const std::size_t kept = m - movers;
        const std::size_t sblocks = (kept + kBlock - 1) / kBlock;
        const auto movers_before = [&](std::size_t s) -> std::size_t {  // movers ordered before kept entry s
            if (s >= kept) return movers;
            return std::size_t(std::lower_bound(mover_list.begin(), mover_list.end(), std::pair{tkey[s], tidx[s]}) -
                               mover_list.begin());
        };
        parallel_for(0, std::int64_t(sblocks), 1, [&](std::int64_t b0, std::int64_t b1) {
            for (auto b = std::size_t(b0); b < std::size_t(b1); ++b) {
                const std::size_t s0 = b * kBlock, s1 = std::min(kept, s0 + kBlock);
                std::size_t a = b == 0 ? 0 : movers_before(s0);
                const std::size_t a1 = movers_before(s1);
                std::size_t out = s0 + a;
                for (std::size_t s = s0; s < s1; ++s) {
                    const std::pair here{tkey[s], tidx[s]};
                    for (; a < a1 && mover_list[a] < here; ++a, ++out) {
                        key[out] = mover_list[a].first;
                        idx[out] = mover_list[a].second;
                    }
                    key[out] = here.first;
                    idx[out++] = here.second;
                }
                for (; a < a1; ++a, ++out) {
                    key[out] = mover_list[a].first;
                    idx[out] = mover_list[a].second;
                }
            }
        });
    }

    /// Every sub-step: sort the live particles by cell (dead ones dropped) and
    /// list the occupied cells. A cell's key is linear in the particles'
    /// bounding box of cells, padded by one cell on every side, x fastest: the
    /// cells x−1, x, x+1 of a row are consecutive keys, so each of the 9 rows
    /// around a cell is one contiguous run of particles. Stable LSD radix sort
    /// with ties in the previous order: the order, and with it every
    /// particle's neighbour and summation order, follows from the state alone.
    void sort_by_cell(bool keep_fields) {
        // The live particles, in index order: counted per block of kListBlock in parallel, each block's
        // first place from those counts, then each block lists its own (the serial loop's list).
        constexpr std::size_t kListBlock = 16384;
        std::vector<std::size_t> first(n / kListBlock + 2, 0);
        const auto list_blocks = std::int64_t((n + kListBlock - 1) / kListBlock);
        parallel_for(0, list_blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
            for (auto b = std::size_t(b0); b < std::size_t(b1); ++b) {
                std::size_t c = 0;
                for (std::size_t i = b * kListBlock; i < std::min(n, (b + 1) * kListBlock); ++i) c += alive[i];
                first[b + 1] = c;
            }
        });
        for (std::size_t b = 0; b < std::size_t(list_blocks); ++b) first[b + 1] += first[b];
        const std::size_t m = first[std::size_t(list_blocks)];
        parallel_for(0, list_blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
            for (auto b = std::size_t(b0); b < std::size_t(b1); ++b) {
                std::size_t k = first[b];
                for (std::size_t i = b * kListBlock; i < std::min(n, (b + 1) * kListBlock); ++i)
                    if (alive[i]) perm[k++] = std::uint32_t(i);
            }
        });
        if (m == 0) {
            n = live = ncell = keyed = 0;
            return;
        }
        const std::int64_t blocks = (std::int64_t(m) + 4095) / 4096;
        std::vector<std::array<float, 6>> box(static_cast<std::size_t>(blocks));
        parallel_for(0, blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
            for (std::int64_t blk = b0; blk < b1; ++blk) {
                std::array<float, 6> bb = {kCellLimit, kCellLimit, kCellLimit, -kCellLimit, -kCellLimit, -kCellLimit};
                const std::size_t lo = std::size_t(blk * 4096), hi = std::min(m, lo + 4096);
                for (std::size_t k = lo; k < hi; ++k) {
                    const Vec3& p = pos[perm[k]];
                    const float c[3] = {cell_of(p.x), cell_of(p.y), cell_of(p.z)};
                    for (int a = 0; a < 3; ++a) {
                        bb[std::size_t(a)] = std::min(bb[std::size_t(a)], c[a]);
                        bb[std::size_t(a) + 3] = std::max(bb[std::size_t(a) + 3], c[a]);
                    }
                }
                box[std::size_t(blk)] = bb;
            }
        });
        std::array<float, 6> bb = box[0];
        for (const auto& b : box)
            for (std::size_t a = 0; a < 3; ++a) {
                bb[a] = std::min(bb[a], b[a]);
                bb[a + 3] = std::max(bb[a + 3], b[a + 3]);
            }
        min_cx = int(bb[0]) - 1;
        min_cy = int(bb[1]) - 1;
        min_cz = int(bb[2]) - 1;
        const auto nx = std::uint64_t(int(bb[3]) - min_cx + 2), ny = std::uint64_t(int(bb[4]) - min_cy + 2),
                   nz = std::uint64_t(int(bb[5]) - min_cz + 2);
        stride_y = nx;
        stride_z = nx * ny;
        std::uint64_t* key = sort_keys.data();
        std::uint64_t* tkey = sort_keys.data() + cap;
        // The keys, and which particles changed cell since the last sort (`moved`; a particle spawned
        // since has no cell yet). The component arrays still hold every particle's position at that sort,
        // in its order (integrate() writes pos, never them), so the others keep their old order.
        const auto key_blocks = std::int64_t((m + kListBlock - 1) / kListBlock);
        first.assign(std::size_t(key_blocks) + 1, 0);
        parallel_for(0, key_blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
            for (auto b = std::size_t(b0); b < std::size_t(b1); ++b) {
                std::size_t c = 0;
                for (std::size_t k = b * kListBlock; k < std::min(m, (b + 1) * kListBlock); ++k) {
                    const std::size_t i = perm[k];
                    const Vec3& p = pos[i];
                    const float cx = cell_of(p.x), cy = cell_of(p.y), cz = cell_of(p.z);
                    key[k] = std::uint64_t(int(cz) - min_cz) * stride_z + std::uint64_t(int(cy) - min_cy) * stride_y +
                             std::uint64_t(int(cx) - min_cx);
                    const bool mv = i >= keyed || cx != cell_of(soa[0][i]) || cy != cell_of(soa[1][i]) ||
                                    cz != cell_of(soa[2][i]);
                    moved[k] = mv;
                    c += mv;
                }
                first[b + 1] = c;
            }
        });
        for (std::size_t b = 0; b < std::size_t(key_blocks); ++b) first[b + 1] += first[b];
        const std::size_t movers = first[std::size_t(key_blocks)];
        std::uint32_t* idx = perm.data();
        std::uint32_t* tidx = perm_tmp.data();
        if (keyed == 0 || double(movers) > s.merge_movers_up_to * double(m)) {
            const std::uint64_t top = nx * ny * nz - 1;
            radix_sort(key, tkey, idx, tidx, m, 64 - __builtin_clzll(top | 1u));
        } else {
            static_assert(kListBlock == kMoverBlock);  // `first` counts the movers per block
            merge_movers(key, tkey, idx, tidx, m, first);
            ++merged_sorts;
        }
        // The occupied cells (where the sorted key changes), found per block of kListBlock keys in parallel
        // as the particle list above: the serial scan's table.
        first.assign(std::size_t(key_blocks) + 1, 0);
        const auto starts_cell = [&](std::size_t k) { return k == 0 || key[k] != key[k - 1]; };
        parallel_for(0, key_blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
            for (auto b = std::size_t(b0); b < std::size_t(b1); ++b) {
                std::size_t c = 0;
                for (std::size_t k = b * kListBlock; k < std::min(m, (b + 1) * kListBlock); ++k) c += starts_cell(k);
                first[b + 1] = c;
            }
        });
        for (std::size_t b = 0; b < std::size_t(key_blocks); ++b) first[b + 1] += first[b];
        parallel_for(0, key_blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
            for (auto b = std::size_t(b0); b < std::size_t(b1); ++b) {
                std::size_t c = first[b];
                for (std::size_t k = b * kListBlock; k < std::min(m, (b + 1) * kListBlock); ++k)
                    if (starts_cell(k)) {
                        cell_key[c] = key[k];
                        cell_start[c++] = std::uint32_t(k);
                    }
            }
        });
        ncell = first[std::size_t(key_blocks)];
        cell_start[ncell] = std::uint32_t(m);
        // Density and pressure are recomputed before every use in a sub-step; only a compaction between
        // steps (end_step) must keep them with their particles for the views and record(). The
        // accelerations are always recomputed before use. The keys are spent: their 16 bytes per particle
        // are the permutation's scratch.
        if (keep_fields) {
            permute(density, idx, m);
            permute(pterm, idx, m);
        }
        // The other fields in one gather and one write-back (they were 6 permutes of two passes each and a
        // pass for the component arrays): positions and velocities gathered straight into their component
        // arrays (fixed until integrate(): a cell's candidates are then 9 contiguous runs to copy per
        // component), the sediment into the keys' scratch, acidity, age and lifespan into the
        // accelerations' 12 bytes (recomputed by force_pass before integrate() reads them). Within a
        // sub-step the positions and velocities stay in the component arrays only: density_pass,
        // force_pass and integrate() read them there, and integrate() writes the sorted pos and vel
        // (every particle: it and the exception it may end in need no write-back here). After a
        // compaction between steps (keep_fields) they are written back for the views and record().
        auto* sed_tmp = reinterpret_cast<std::byte*>(sort_keys.data());
        auto* rest_tmp = reinterpret_cast<std::byte*>(acc.data());
        static_assert(sizeof(Vec3) == 12 && sizeof(float) + 2 * sizeof(std::int32_t) == 12);
        parallel_for(0, std::int64_t(m), 8192, [&](std::int64_t b, std::int64_t e) {
            for (auto k = std::size_t(b); k < std::size_t(e); ++k) {
                const std::size_t i = idx[k];
                const Vec3 p = pos[i], v = vel[i];
                soa[0][k] = p.x;
                soa[1][k] = p.y;
                soa[2][k] = p.z;
                soa[3][k] = v.x;
                soa[4][k] = v.y;
                soa[5][k] = v.z;
                std::memcpy(sed_tmp + 8 * k, &sediment[i], 8);
                std::memcpy(rest_tmp + 12 * k, &acidity[i], 4);
                std::memcpy(rest_tmp + 12 * k + 4, &age[i], 4);
                std::memcpy(rest_tmp + 12 * k + 8, &lifespan[i], 4);
            }
        });
        parallel_for(0, std::int64_t(m), 8192, [&](std::int64_t b, std::int64_t e) {
            for (auto k = std::size_t(b); k < std::size_t(e); ++k) {
                if (keep_fields) {
                    pos[k] = Vec3{soa[0][k], soa[1][k], soa[2][k]};
                    vel[k] = Vec3{soa[3][k], soa[4][k], soa[5][k]};
                }
                std::memcpy(&sediment[k], sed_tmp + 8 * k, 8);
                std::memcpy(&acidity[k], rest_tmp + 12 * k, 4);
                std::memcpy(&age[k], rest_tmp + 12 * k + 4, 4);
                std::memcpy(&lifespan[k], rest_tmp + 12 * k + 8, 4);
                alive[k] = 1;
            }
        });
        n = m;
        live = m;
        keyed = m;
    }

    template <typename T>
    void permute(std::vector<T>& v, const std::uint32_t* p, std::size_t m) {
        static_assert(sizeof(T) <= 2 * sizeof(std::uint64_t) && std::is_trivially_copyable_v<T>);
        auto* tmp = reinterpret_cast<std::byte*>(sort_keys.data());
        parallel_for(0, std::int64_t(m), 8192, [&](std::int64_t b, std::int64_t e) {
            for (std::int64_t k = b; k < e; ++k) std::memcpy(tmp + std::size_t(k) * sizeof(T), &v[p[k]], sizeof(T));
        });
        parallel_for(0, std::int64_t(m), 8192, [&](std::int64_t b, std::int64_t e) {
            for (std::int64_t k = b; k < e; ++k) std::memcpy(&v[std::size_t(k)], tmp + std::size_t(k) * sizeof(T), sizeof(T));
        });
    }

    /// The particles in the 9 rows of 3 cells around a cell, as [begin, end)
    /// runs of the sorted arrays, in a fixed order (z, then y; x ascending
    /// within a run), empty rows skipped. Asked for cells in increasing key
    /// order (one task's range), each row's lookup moves forward from where
    /// the previous cell's ended: a binary search only for the first cell or
    /// after a long gap.
    class RowWalker {
    public:
        explicit RowWalker(const Impl& m) : m_(m) {}
        int next(std::size_t c, std::uint32_t (*run)[2]) {
            const std::uint64_t k = m_.cell_key[c];
            const std::uint64_t* first = m_.cell_key.data();
            const std::uint64_t* last = first + m_.ncell;
            int nr = 0, row = 0;
            for (int dz = -1; dz <= 1; ++dz)
                for (int dy = -1; dy <= 1; ++dy, ++row) {
                    // The box's padding keeps every key of the row within it: no wrap-around.
                    const std::uint64_t mid =
                        k + std::uint64_t(std::int64_t(dz)) * m_.stride_z + std::uint64_t(std::int64_t(dy)) * m_.stride_y;
                    const std::uint64_t* lo = started_ ? at_[row] : first;
                    if (!started_ || (last - lo > 8 && lo[8] < mid - 1))
                        lo = std::lower_bound(lo, last, mid - 1);
                    else
                        while (lo != last && *lo < mid - 1) ++lo;
                    at_[row] = lo;
                    const std::uint64_t* hi = lo;
                    while (hi != last && *hi <= mid + 1) ++hi;
                    if (lo == hi) continue;
                    run[nr][0] = m_.cell_start[std::size_t(lo - first)];
                    run[nr][1] = m_.cell_start[std::size_t(hi - first)];
                    ++nr;
                }
            started_ = true;
            return nr;
        }

    private:
        const Impl& m_;
        const std::uint64_t* at_[9] = {};
        bool started_ = false;
    };

    /// Particles in the runs, and that count rounded up to whole kLanes.
    static std::size_t run_total(const std::uint32_t (*run)[2], int nr) {
        std::size_t m = 0;
        for (int r = 0; r < nr; ++r) m += run[r][1] - run[r][0];
        return m;
    }
    static std::size_t padded(std::size_t m) { return (m + kLanes - 1) / kLanes * kLanes; }


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

    /// Density and pressure, a cell at a time: the candidates of the cell's 27
    /// neighbour cells are copied once into contiguous arrays and every particle
    /// of the cell sums over all of them (lanes of kLanes, out-of-support ones masked).
    void density_pass() {
        parallel_for(0, std::int64_t(ncell), kCellGrain, [&](std::int64_t c0, std::int64_t c1) {
            FlushDenormals ftz;
            std::vector<float>& bx = scratch.buf[0];
            std::vector<float>& by = scratch.buf[1];
            std::vector<float>& bz = scratch.buf[2];
            std::uint32_t run[9][2];
            RowWalker rows(*this);
            for (std::int64_t cc = c0; cc < c1; ++cc) {
                const auto c = std::size_t(cc);
                const int nr = rows.next(c, run);
                const std::size_t mp = padded(run_total(run, nr));
                float* X = room(bx, mp + kSlack);
                float* Y = room(by, mp + kSlack);
                float* Z = room(bz, mp + kSlack);
                const float* const from[3] = {soa[0].data(), soa[1].data(), soa[2].data()};
                float* const to[3] = {X, Y, Z};
                std::size_t k = gather3(from, to, run, nr);
                for (; k < mp; ++k) X[k] = Y[k] = Z[k] = kFar;
                for (std::size_t i = cell_start[c]; i < cell_start[c + 1]; ++i) {
                    float rho = mass * (w_norm * density_sum(X, Y, Z, mp, soa[0][i], soa[1][i], soa[2][i], h2, inv_h));
                    // The terrain as the fluid's rest lattice continued behind it (Akinci et al. 2012's boundary
                    // particles, summed once into a table): without it a particle on the ground misses half its
                    // kernel and the fluid crowds against the ground.
                    float phi = 0.0f;
                    Vec3 push{0.0f, 0.0f, 0.0f};
                    const double x = soa[0][i], y = soa[1][i], z = soa[2][i];
                    // Only the terrain: the map's side walls (closed boundary) stay geometric. With them as walls
                    // too (and the quadrant where two meet subtracted once), Martin & Moyce's dam break in its
                    // narrow tank ran 30 % ahead of the measurements; see docs/sph.md.
                    int ti, tj;
                    double fx, fz;
                    tile(x, z, ti, tj, fx, fz);
                    const double above = y - surface_in(ti, tj, fx, fz);
                    if (above < double(h)) {
                        double nrm[3];
                        normal_in(ti, tj, fx, fz, nrm);
                        add_wall(above * nrm[1], nrm[0], nrm[1], nrm[2], phi, push);  // the distance to the tangent plane
                    }
                    wall_push[i] = push;
                    density[i] = rho + rho0 * phi;
                }
            }
            // The task's particles are contiguous (cells c0..c1): their pressures in one vector loop, off
            // the per-particle path (its two divisions were a quarter of this pass, one particle at a time).
            pressure_terms(density.data() + cell_start[std::size_t(c0)], pterm.data() + cell_start[std::size_t(c0)],
                           cell_start[std::size_t(c1)] - cell_start[std::size_t(c0)], rho0, B);
        });
    }

    /// Pressure, viscosity, the ground's push and gravity, a cell at a time as
    /// in density_pass.
    void force_pass() {
        const float g = float(-s.gravity);
        const float visc_k = 2.0f * alpha_c_hs;
        const float scale = -mass * grad_norm * inv_h;  // force_sum's result → m/s²
        const std::int64_t blocks = (std::int64_t(ncell) + kCellGrain - 1) / kCellGrain;
        std::vector<float> block_max(std::size_t(std::max<std::int64_t>(blocks, 1)), 0.0f);
        parallel_for(0, blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
            FlushDenormals ftz;
            std::vector<float>* buf = scratch.buf;
            std::uint32_t run[9][2];
            RowWalker rows(*this);
            for (std::int64_t blk = b0; blk < b1; ++blk) {
                float amax = 0.0f;
                const std::size_t clo = std::size_t(blk * kCellGrain), chi = std::min(ncell, clo + std::size_t(kCellGrain));
                for (std::size_t c = clo; c < chi; ++c) {
                    const int nr = rows.next(c, run);
                    const std::size_t mp = padded(run_total(run, nr));
                    float* f[8];
                    for (int a = 0; a < 8; ++a) f[a] = room(buf[a], mp + kSlack);
                    const float* const from[8] = {soa[0].data(), soa[1].data(), soa[2].data(), soa[3].data(),
                                                  soa[4].data(), soa[5].data(), pterm.data(),  density.data()};
                    float* const to[8] = {f[0], f[1], f[2], f[3], f[4], f[5], f[6], f[7]};
                    std::size_t k = gather8(from, to, run, nr);
                    for (; k < mp; ++k) {
                        f[0][k] = f[1][k] = f[2][k] = kFar;
                        f[3][k] = f[4][k] = f[5][k] = f[6][k] = 0.0f;
                        f[7][k] = rho0;
                    }
                    const ForceCandidates cand{f[0], f[1], f[2], f[3], f[4], f[5], f[6], f[7]};
                    for (std::size_t i = cell_start[c]; i < cell_start[c + 1]; ++i) {
                        const float pi = pterm[i];
                        float sum[3];
                        force_sum(cand, mp, soa[0][i], soa[1][i], soa[2][i], soa[3][i], soa[4][i], soa[5][i], pi, density[i],
                                  h2, inv_h, visc_eps, visc_k, sum);
                        // The ground pushes back with the particle's own pressure (mirrored): −(2 p/ρ²) ρ0 ∇Φ.
                        const float wall = 2.0f * pi * rho0;
                        const float ax = scale * sum[0] + wall * wall_push[i].x;
                        const float ay = scale * sum[1] + wall * wall_push[i].y + g;
                        const float az = scale * sum[2] + wall * wall_push[i].z;
                        acc[i] = Vec3{ax, ay, az};
                        amax = std::max(amax, ax * ax + ay * ay + az * az);
                    }
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
                    const auto keep = [&] {  // pos and vel unchanged: as sorted
                        pos[i] = Vec3{soa[0][i], soa[1][i], soa[2][i]};
                        vel[i] = Vec3{soa[3][i], soa[4][i], soa[5][i]};
                    };
                    if (!alive[i]) {  // not after sort_by_cell (it drops the dead); kept for safety
                        keep();
                        continue;
                    }
                    // The sorted positions and velocities are in the component arrays (sort_by_cell); pos and
                    // vel are written below, for every particle.
                    double v[3] = {soa[3][i] + double(acc[i].x) * ddt, soa[4][i] + double(acc[i].y) * ddt,
                                   soa[5][i] + double(acc[i].z) * ddt};
                    const double o[3] = {soa[0][i], soa[1][i], soa[2][i]};
                    const double d[3] = {v[0] * ddt, v[1] * ddt, v[2] * ddt};
                    double p[3] = {o[0] + d[0], o[1] + d[1], o[2] + d[2]};
                    if (!std::isfinite(p[0] + p[1] + p[2] + v[0] + v[1] + v[2])) {
                        block_bad[std::size_t(blk)] = 1;  // reported by substep(); never index the terrain with it
                        keep();
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
                    double n3[3] = {0.0, 1.0, 0.0};  // set below wherever it is read
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
                    tile(p[0], p[2], ui, uj, fx, fz);
                    const double ys = surface_in(ui, uj, fx, fz);
                    // The normal only where it is used: within a radius of the ground or after a hit.
                    if (contact || p[1] - ys < s.radius || p[1] < ys + 1e-4 * s.radius) normal_in(ui, uj, fx, fz, n3);
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

    /// Apply the exchanges to the terrain, remove particles that left or reached
    /// the sea. Every terrain vertex receives its additions in particle order,
    /// as a serial loop would, on any thread count: the particles are cut into
    /// fixed chunks of s.settle_chunk (sorted by cell, z slowest, so a chunk
    /// covers a band of terrain rows); a row only one chunk's band reaches is
    /// that chunk's and is changed by it directly, in parallel with the other
    /// chunks; what goes to rows two bands share is queued and applied
    /// afterwards, serially, chunk by chunk in order. The sediment that leaves
    /// over an open edge is summed in the same serial pass, in particle order.
    /// A queued exchange (16 bytes; queued only where a particle's tile reaches a shared row, so a few
    /// per cent of the particles at 16384 a chunk, at most two entries per particle).
    struct Deferred {
        float x, z;     // m, where the exchange happens; x NaN: a particle that left over an open edge
        double volume;  // m³ added to the terrain there (< 0: taken); or the sediment that left with it
    };
    std::vector<int> row_owner;  // per terrain row: the chunk that owns it, -1 none, -2 shared

    /// exchange_terrain (w, hgt ≥ 2) restricted to the rows for which `mine(row)`; true if it skipped one.
    template <typename Mine>
    bool exchange_rows(double x, double z, double volume, Mine mine) {
        int i, j;
        double fx, fz;
        tile(x, z, i, j, fx, fz);
        const double dh = volume * inv_cell * inv_cell;
        const int i1 = std::min(i + 1, w - 1);
        bool skipped = false;
        for (int r = j; r <= std::min(j + 1, hgt - 1); ++r) {
            if (!mine(r)) {
                skipped = true;
                continue;
            }
            dirty_lo[std::size_t(r)] = std::min(dirty_lo[std::size_t(r)], i);
            dirty_hi[std::size_t(r)] = std::max(dirty_hi[std::size_t(r)], i1);
            double* row = &terrain[std::size_t(r) * std::size_t(w)];
            const double fr = r == j ? 1 - fz : fz;
            // The same products, in the same order, as exchange_terrain.
            row[i] += dh * (1 - fx) * fr;
            row[i1] += dh * fx * fr;
        }
        return skipped;
    }

    void settle() {
        const std::size_t chunk = std::max<std::size_t>(s.settle_chunk, 1);
        const std::size_t chunks = (n + chunk - 1) / chunk;
        if (w < 2 || hgt < 2 || chunks <= 1) return settle_serial();
        // 1. Each chunk's band of rows (the rows of every tile it may change).
        std::vector<std::array<int, 2>> band(chunks);
        parallel_for(0, std::int64_t(chunks), 1, [&](std::int64_t c0, std::int64_t c1) {
            for (auto c = std::size_t(c0); c < std::size_t(c1); ++c) {
                int lo = hgt, hi = -1;
                for (std::size_t i = c * chunk; i < std::min(n, (c + 1) * chunk); ++i) {
                    if (!alive[i]) continue;
                    const double x = exchange[i];
                    if (!(x != 0.0 && !std::isnan(x)) && !(double(pos[i].y) < s.sea_level)) continue;
                    int ti, tj;
                    double fx, fz;
                    tile(pos[i].x, pos[i].z, ti, tj, fx, fz);
                    lo = std::min(lo, tj);
                    hi = std::max(hi, std::min(tj + 1, hgt - 1));
                }
                band[c] = {lo, hi};
            }
        });
        row_owner.assign(std::size_t(hgt), -1);
        for (std::size_t c = 0; c < chunks; ++c)
            for (int r = band[c][0]; r <= band[c][1]; ++r) {
                int& o = row_owner[std::size_t(r)];
                o = o == -1 ? int(c) : -2;
            }
        // 2. In parallel: the owned rows, the particles' sediment, the sea; the rest queued.
        std::vector<std::vector<Deferred>> queue(chunks);
        std::vector<std::array<std::int64_t, 2>> tally(chunks);  // sea kills, terrain changed
        parallel_for(0, std::int64_t(chunks), 1, [&](std::int64_t c0, std::int64_t c1) {
            for (auto c = std::size_t(c0); c < std::size_t(c1); ++c) {
                const int me = int(c);
                const auto mine = [&](int r) { return row_owner[std::size_t(r)] == me; };
                std::int64_t sea = 0, changed = 0;
                auto& q = queue[c];
                const auto apply = [&](float x, float z, double volume) {
                    if (exchange_rows(x, z, volume, mine)) q.push_back(Deferred{x, z, volume});
                    changed = 1;
                };
                for (std::size_t i = c * chunk; i < std::min(n, (c + 1) * chunk); ++i) {
                    if (!alive[i]) continue;
                    const double x = exchange[i];
                    const Vec3& p = pos[i];
                    if (std::isnan(x)) {  // left over an open edge, with its sediment (summed in step 3)
                        q.push_back(Deferred{std::numeric_limits<float>::quiet_NaN(), 0.0f, sediment[i]});
                        sediment[i] = 0.0;
                        alive[i] = 0;
                        continue;
                    }
                    if (x != 0.0) {
                        apply(p.x, p.z, -x);
                        sediment[i] += x;
                    }
                    if (double(p.y) < s.sea_level) {
                        if (sediment[i] != 0.0) apply(p.x, p.z, sediment[i]);
                        sediment[i] = 0.0;
                        alive[i] = 0;
                        ++sea;
                    }
                }
                tally[c] = {sea, changed};
            }
        });
        // 3. Serially, in particle order: the shared rows and the departures.
        bool changed = false;
        const auto shared = [&](int r) { return row_owner[std::size_t(r)] == -2; };
        for (std::size_t c = 0; c < chunks; ++c) {
            for (const Deferred& d : queue[c]) {
                if (std::isnan(d.x)) {
                    removed += d.volume;
                    --live;
                    ++counts.left;
                } else {
                    exchange_rows(d.x, d.z, d.volume, shared);
                }
            }
            live -= std::size_t(tally[c][0]);
            counts.sea += tally[c][0];
            changed = changed || tally[c][1] != 0;
        }
        if (changed) {
            any_dirty = true;
            refresh_normals();
            lift_all();
        }
    }

    /// settle() in one loop, in particle order (few particles, or a map one vertex wide).
    void settle_serial() {
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
        if (changed) {
            refresh_normals();
            lift_all();
        }
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
    m.vnormal.resize(3 * terrain.size());
    m.dirty_lo.assign(std::size_t(m.hgt), 0);
    m.dirty_hi.assign(std::size_t(m.hgt), m.w - 1);
    m.any_dirty = true;
    m.refresh_normals();  // all of them

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
    m.density.resize(capacity + kSlack);
    m.wall_push.resize(capacity);
    m.pterm.resize(capacity + kSlack);  // kSlack: the candidate gathering's slack
    m.sediment.resize(capacity);
    m.exchange.resize(capacity);
    m.acidity.resize(capacity);
    m.age.resize(capacity);
    m.lifespan.resize(capacity);
    m.alive.resize(capacity);
    m.sort_keys.resize(2 * capacity);
    m.perm.resize(capacity);
    m.perm_tmp.resize(capacity);
    m.moved.resize(capacity);
    m.cell_key.resize(capacity);
    m.cell_start.resize(capacity + 1);
    for (auto& a : m.soa) a.resize(capacity + kSlack);
}

Simulation::~Simulation() = default;

std::size_t Simulation::bytes_per_particle() {
    // pos, vel, acc, wall_push (48) + density, pterm, acidity, age, lifespan (20) + sediment, exchange (16)
    // + alive (1) + sort keys (16) + permutation (8) + cell keys and starts (12, at most one cell per particle)
    // + component copies of position and velocity (24) + moved-since-last-sort flag (1).
    // merge_movers' list (12 B per mover, at most merge_movers_up_to = 1/8 of the particles, so
    // 1.5 B per particle) lives only during a sort and is counted with it: 147 in all.
    return 48 + 20 + 16 + 1 + 16 + 8 + 12 + 24 + 1 + 1;
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
    m.sort_by_cell(false);
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
    if (changed) {
        m.refresh_normals();
        m.lift_all();
    }
    if (m.live != m.n) m.sort_by_cell(true);
}

std::size_t Simulation::size() const { return impl_->live; }
std::size_t Simulation::capacity() const { return impl_->cap; }
const Counts& Simulation::counts() const { return impl_->counts; }
std::int64_t Simulation::substeps() const { return impl_->substeps; }
std::int64_t Simulation::merged_sorts() const { return impl_->merged_sorts; }
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
