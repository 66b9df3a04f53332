// integrator.cpp — the WCSPH sub-step's passes (see integrator.hpp; the model in sph.hpp).
#include "integrator.hpp"

#include <orogen/parallel.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <vector>

namespace orogen::sph {

namespace {

constexpr std::int64_t kGrain = 512;  // particles per parallel task (integration)
constexpr std::int64_t kCellGrain = 64;  // cells per parallel task (density, forces)

/// Candidate buffers per thread, kept across tasks and sub-steps (density_pass uses the first 3,
/// force_pass all 8): vectors of a task's own were allocated and zero-filled anew for every task. Neither
/// pass starts parallel work inside a task, so a thread runs one task at a time on them.
struct Scratch {
    std::vector<float> buf[8];
};
thread_local Scratch scratch;

}  // namespace

FluidConstants FluidConstants::from(const Settings& settings, float h) {
    const double spacing = 2.0 * settings.radius;
    FluidConstants f;
    f.volume = float(spacing * spacing * spacing);
    f.rho0 = float(settings.rest_density);
    f.mass = float(settings.rest_density * spacing * spacing * spacing);
    f.c0 = float(settings.sound_speed);
    f.B = float(settings.rest_density * settings.sound_speed * settings.sound_speed / 7.0);
    const double hs = 0.5 * double(h);  // the smoothing length of the viscosity term
    f.visc_eps = float(0.01 * hs * hs);
    f.alpha_c_hs = float(settings.viscosity * settings.sound_speed * hs);
    return f;
}

Simulation::Impl::Impl(ConstGridView terrain_in, const Settings& settings, std::size_t capacity)
    : s(settings), kernel(CubicSpline::with_support(float(4.0 * settings.radius))),
      fluid(FluidConstants::from(settings, kernel.h)), terrain(terrain_in, settings.radius) {
    walls.tabulate(kernel, fluid.volume);
    p.reserve(capacity);
    cells.reserve(capacity, kernel.h);
}

/// Density and pressure, a cell at a time: the candidates of the cell's 27
/// neighbour cells are copied once into contiguous arrays and every particle
/// of the cell sums over all of them (lanes of kLanes, out-of-support ones masked).
void Simulation::Impl::density_pass() {
    const auto& soa = p.soa;
    const float h = kernel.h, w_norm = kernel.w_norm;
    const Support support{kernel.h2, kernel.inv_h};
    const float mass = fluid.mass, rho0 = fluid.rho0;
    const bool closed = s.boundary == Boundary::closed && terrain.width() >= 2 && terrain.height() >= 2;
    const double far_x = terrain.extent_x() - double(h), far_z = terrain.extent_z() - double(h);
    parallel_for(0, std::int64_t(cells.cells()), kCellGrain, [&](std::int64_t c0, std::int64_t c1) {
        FlushDenormals ftz;
        std::vector<float>& bx = scratch.buf[0];
        std::vector<float>& by = scratch.buf[1];
        std::vector<float>& bz = scratch.buf[2];
        std::uint32_t run[9][2];
        Neighbourhood::RowWalker rows(cells);
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
            const DensityCandidates cand{X, Y, Z};
            for (std::size_t i = cells.cell_begin(c); i < cells.cell_begin(c + 1); ++i) {
                float rho = mass * (w_norm * density_sum(cand, mp, soa[0][i], soa[1][i], soa[2][i], support));
                // The terrain as the fluid's rest lattice continued behind it (Akinci et al. 2012's boundary
                // particles, summed once into a table): without it a particle on the ground misses half its
                // kernel and the fluid crowds against the ground.
                float phi = 0.0f;
                Vec3 push{0.0f, 0.0f, 0.0f};
                const double x = soa[0][i], y = soa[1][i], z = soa[2][i];
                int ti, tj;
                double fx, fz;
                terrain.tile(x, z, ti, tj, fx, fz);
                const double above = y - terrain.surface_in(ti, tj, fx, fz);
                double ground = double(h), nrm[3] = {0.0, 1.0, 0.0};
                if (above < double(h)) {
                    terrain.normal_in(ti, tj, fx, fz, nrm);
                    ground = above * nrm[1];  // the distance to the tangent plane
                    walls.add(ground, nrm[0], nrm[1], nrm[2], phi, push);
                }
                // The map's edges as walls too (closed boundary), the same lattice behind them.
                if (closed && (x < h || z < h || x > far_x || z > far_z)) side_walls(x, z, ground, nrm, phi, push);
                p.wall_push[i] = push;
                p.density[i] = rho + rho0 * phi;
            }
        }
        // The task's particles are contiguous (cells c0..c1): their pressures in one vector loop, off
        // the per-particle path (its two divisions were a quarter of this pass, one particle at a time).
        const std::uint32_t first = cells.cell_begin(std::size_t(c0)), last = cells.cell_begin(std::size_t(c1));
        pressure_terms(p.density.data() + first, p.pterm.data() + first, last - first, rho0, fluid.B);
    });
}

/// The map's edges (closed boundary) as walls for a particle at (x, z) within the support of one: the fluid's
/// rest lattice behind each (WallTable::add), and, where two walls meet (two edges, or an edge and the
/// ground at distance `ground` with unit normal `nrm`), the quadrant behind both counted once; where the
/// ground and two edges meet, the octant behind all three as well.
void Simulation::Impl::side_walls(double x, double z, double ground, const double nrm[3], float& phi,
                                  Vec3& push) const {
    static constexpr double kNormals[4][3] = {{1.0, 0.0, 0.0}, {-1.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, {0.0, 0.0, -1.0}};
    const double hh = double(kernel.h);
    const double dist[4] = {std::max(x, 0.0), std::max(terrain.extent_x() - x, 0.0), std::max(z, 0.0),
                            std::max(terrain.extent_z() - z, 0.0)};
    bool near[4];
    for (int w = 0; w < 4; ++w) {
        near[w] = dist[w] < hh;
        if (near[w]) walls.add(dist[w], kNormals[w][0], kNormals[w][1], kNormals[w][2], phi, push);
    }
    const bool on_ground = ground < hh;
    if (on_ground)
        for (int w = 0; w < 4; ++w)
            if (near[w]) walls.subtract_quadrant(dist[w], ground, kNormals[w], nrm, phi, push);
    for (int a = 0; a < 2; ++a)  // an x wall and a z wall (parallel walls' half-spaces do not overlap)
        for (int b = 2; b < 4; ++b) {
            if (!near[a] || !near[b]) continue;
            walls.subtract_quadrant(dist[a], dist[b], kNormals[a], kNormals[b], phi, push);
            if (on_ground) {
                const double d[3] = {dist[a], dist[b], ground};
                const double* const n[3] = {kNormals[a], kNormals[b], nrm};
                walls.add_octant(d, n, phi, push);
            }
        }
}

/// Pressure, viscosity, the ground's push and gravity, a cell at a time as
/// in density_pass.
void Simulation::Impl::force_pass() {
    const auto& soa = p.soa;
    const float g = float(-s.gravity);
    const float visc_k = 2.0f * fluid.alpha_c_hs;
    const float rho0 = fluid.rho0;
    const ForceConstants fk{Support{kernel.h2, kernel.inv_h}, fluid.visc_eps, visc_k};
    const float scale = -fluid.mass * kernel.grad_norm * kernel.inv_h;  // force_sum's result → m/s²
    const std::size_t ncell = cells.cells();
    const std::int64_t blocks = (std::int64_t(ncell) + kCellGrain - 1) / kCellGrain;
    std::vector<float> block_max(std::size_t(std::max<std::int64_t>(blocks, 1)), 0.0f);
    parallel_for(0, blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
        FlushDenormals ftz;
        std::vector<float>* buf = scratch.buf;
        std::uint32_t run[9][2];
        Neighbourhood::RowWalker rows(cells);
        for (std::int64_t blk = b0; blk < b1; ++blk) {
            float amax = 0.0f;
            const std::size_t clo = std::size_t(blk * kCellGrain), chi = std::min(ncell, clo + std::size_t(kCellGrain));
            for (std::size_t c = clo; c < chi; ++c) {
                const int nr = rows.next(c, run);
                const std::size_t mp = padded(run_total(run, nr));
                float* f[8];
                for (int a = 0; a < 8; ++a) f[a] = room(buf[a], mp + kSlack);
                const float* const from[8] = {soa[0].data(), soa[1].data(), soa[2].data(),  soa[3].data(),
                                              soa[4].data(), soa[5].data(), p.pterm.data(), p.density.data()};
                float* const to[8] = {f[0], f[1], f[2], f[3], f[4], f[5], f[6], f[7]};
                std::size_t k = gather8(from, to, run, nr);
                for (; k < mp; ++k) {
                    f[0][k] = f[1][k] = f[2][k] = kFar;
                    f[3][k] = f[4][k] = f[5][k] = f[6][k] = 0.0f;
                    f[7][k] = rho0;
                }
                const ForceCandidates cand{f[0], f[1], f[2], f[3], f[4], f[5], f[6], f[7]};
                for (std::size_t i = cells.cell_begin(c); i < cells.cell_begin(c + 1); ++i) {
                    const float pi = p.pterm[i];
                    const ForceParticle me{soa[0][i], soa[1][i], soa[2][i], soa[3][i],
                                           soa[4][i], soa[5][i], pi,        p.density[i]};
                    float sum[3];
                    force_sum(cand, mp, me, fk, sum);
                    // The ground pushes back with the particle's own pressure (mirrored): −(2 p/ρ²) ρ0 ∇Φ.
                    const float wall = 2.0f * pi * rho0;
                    const Vec3& push = p.wall_push[i];
                    const float ax = scale * sum[0] + wall * push.x;
                    const float ay = scale * sum[1] + wall * push.y + g;
                    const float az = scale * sum[2] + wall * push.z;
                    p.acc[i] = Vec3{ax, ay, az};
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

/// integrate()'s constants for one sub-step.
struct Simulation::Impl::StepConstants {
    double ddt;  // s
    double e;  // restitution
    double fric;  // the tangential velocity's factor over the sub-step while in contact
    double dissolve_frac;  // share of the capacity's deficit dissolved (times acidity·Δt)
    double deposit_frac;  // share of the excess over capacity dropped
    double particle_volume;  // m³
    double max_take;  // m³: max_dig over a tile
};

/// The m³ of terrain particle i in contact takes up this sub-step (< 0: drops), from its tangential velocity
/// vt (m/s) and the normal's vertical component ny: towards the capacity Kc · V · |v_t| · max(sin α, min_slope).
[[gnu::always_inline]] inline double Simulation::Impl::erosion_take(std::size_t i, const double vt[3], double ny,
                                                                    const StepConstants& k) const {
    const double speed = std::sqrt(vt[0] * vt[0] + vt[1] * vt[1] + vt[2] * vt[2]);
    const double sin_slope = std::sqrt(std::max(0.0, 1.0 - ny * ny));
    const double cap = s.capacity * k.particle_volume * speed * std::max(sin_slope, s.min_slope);
    const double sed = p.sediment[i];
    if (sed < cap)
        return std::min(std::min(1.0, double(p.acidity[i]) * k.ddt) * k.dissolve_frac * (cap - sed), k.max_take);
    return -k.deposit_frac * (sed - cap);
}

[[gnu::always_inline]] inline bool Simulation::Impl::integrate_particle(std::size_t i, const StepConstants& k) {
    const auto& soa = p.soa;
    const double ddt = k.ddt, e = k.e;
    p.exchange[i] = 0.0;
    const auto keep = [&] {  // pos and vel unchanged: as sorted
        p.pos[i] = Vec3{soa[0][i], soa[1][i], soa[2][i]};
        p.vel[i] = Vec3{soa[3][i], soa[4][i], soa[5][i]};
    };
    if (!p.alive[i]) {  // not after Neighbourhood::sort (it drops the dead); kept for safety
        keep();
        return true;
    }
    // The sorted positions and velocities are in the component arrays (Neighbourhood::sort); pos and
    // vel are written below, for every particle.
    const Vec3& a = p.acc[i];
    double v[3] = {soa[3][i] + double(a.x) * ddt, soa[4][i] + double(a.y) * ddt, soa[5][i] + double(a.z) * ddt};
    const double o[3] = {soa[0][i], soa[1][i], soa[2][i]};
    const double d[3] = {v[0] * ddt, v[1] * ddt, v[2] * ddt};
    double q[3] = {o[0] + d[0], o[1] + d[1], o[2] + d[2]};
    if (!std::isfinite(q[0] + q[1] + q[2] + v[0] + v[1] + v[2])) {
        keep();  // never index the terrain with it
        return false;
    }
    bool contact = false;
    // Möller–Trumbore against the tiles beneath the start and the end of the motion.
    const double t = terrain.hit_motion(o, d, q);
    double n3[3] = {0.0, 1.0, 0.0};  // set below wherever it is read
    if (t >= 0.0) {
        for (int c = 0; c < 3; ++c) q[c] = o[c] + t * d[c];
        terrain.normal(q[0], q[2], n3);
        const double vn = v[0] * n3[0] + v[1] * n3[1] + v[2] * n3[2];
        if (vn < 0.0)
            for (int c = 0; c < 3; ++c) v[c] -= (1.0 + e) * vn * n3[c];
        contact = true;
    }
    // The map's edges.
    bool out = false;
    const double lim[2] = {terrain.extent_x(), terrain.extent_z()};
    for (int c : {0, 2}) {
        const double l = lim[c == 0 ? 0 : 1];
        if (q[c] < 0.0 || q[c] > l) {
            if (s.boundary == Boundary::open) {
                out = true;
            } else {
                // A wall: stop there, reflect the outward velocity (restitution e).
                const bool low = q[c] < 0.0;
                q[c] = low ? 0.0 : l;
                if (low ? v[c] < 0.0 : v[c] > 0.0) v[c] *= -e;
            }
        }
    }
    if (out) {
        p.pos[i] = Vec3{float(q[0]), float(q[1]), float(q[2])};
        p.vel[i] = Vec3{float(v[0]), float(v[1]), float(v[2])};
        p.exchange[i] = std::numeric_limits<double>::quiet_NaN();  // marks "left" for settle()
        return true;
    }
    // Never below the triangulated surface (at the position as stored, in float).
    Vec3 np{float(q[0]), float(q[1]), float(q[2])};
    q[0] = np.x;
    q[2] = np.z;
    int ui, uj;
    double fx, fz;
    terrain.tile(q[0], q[2], ui, uj, fx, fz);
    const double ys = terrain.surface_in(ui, uj, fx, fz);
    // The normal only where it is used: within a radius of the ground or after a hit.
    if (contact || q[1] - ys < s.radius || q[1] < ys + 1e-4 * s.radius) terrain.normal_in(ui, uj, fx, fz, n3);
    if (q[1] < ys + 1e-4 * s.radius) {
        q[1] = ys;
        const double vn = v[0] * n3[0] + v[1] * n3[1] + v[2] * n3[2];
        if (vn < 0.0)
            for (int c = 0; c < 3; ++c) v[c] -= (1.0 + e) * vn * n3[c];
        contact = true;
    }
    if (q[1] - ys < s.radius) contact = true;
    double take = 0.0;
    if (contact) {
        const double vn = v[0] * n3[0] + v[1] * n3[1] + v[2] * n3[2];
        double vt[3] = {v[0] - vn * n3[0], v[1] - vn * n3[1], v[2] - vn * n3[2]};
        for (int c = 0; c < 3; ++c) {
            vt[c] *= k.fric;
            v[c] = vn * n3[c] + vt[c];
        }
        if (s.erode) take = erosion_take(i, vt, n3[1], k);
    }
    p.exchange[i] = take;
    np.y = float(q[1]);
    if (double(np.y) < ys) np.y = terrain.above(ys);
    p.pos[i] = np;
    p.vel[i] = Vec3{float(v[0]), float(v[1]), float(v[2])};
    return finite3(np) && finite3(p.vel[i]);
}

/// Integrate, collide with the terrain and the walls, compute the erosion
/// exchange. Returns false if a particle went non-finite.
bool Simulation::Impl::integrate(float dt) {
    const double ddt = dt;
    const double cell = terrain.cell();
    const StepConstants k{ddt,
                          s.restitution,
                          std::exp(-s.friction * ddt),
                          1.0,
                          std::min(1.0, s.deposit * ddt),
                          double(fluid.volume),
                          s.max_dig * cell * cell};
    const std::size_t n = p.n;
    const std::int64_t blocks = (std::int64_t(n) + kGrain - 1) / kGrain;
    std::vector<std::uint8_t> block_bad(std::size_t(std::max<std::int64_t>(blocks, 1)), 0);
    parallel_for(0, blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
        FlushDenormals ftz;
        const StepConstants task_k = k;  // the task's own copy: stays in registers (no store can alias it)
        for (std::int64_t blk = b0; blk < b1; ++blk) {
            const std::size_t lo = std::size_t(blk * kGrain), hi = std::min(n, lo + std::size_t(kGrain));
            for (std::size_t i = lo; i < hi; ++i)
                if (!integrate_particle(i, task_k)) block_bad[std::size_t(blk)] = 1;  // reported by substep()
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
struct Simulation::Impl::Deferred {
    float x, z;  // m, where the exchange happens; x NaN: a particle that left over an open edge
    double volume;  // m³ added to the terrain there (< 0: taken); or the sediment that left with it
};

void Simulation::Impl::settle() {
    const std::size_t n = p.n;
    const int hgt = terrain.height();
    const std::size_t chunk = std::max<std::size_t>(s.settle_chunk, 1);
    const std::size_t chunks = (n + chunk - 1) / chunk;
    if (terrain.width() < 2 || hgt < 2 || chunks <= 1) return settle_serial();
    // 1. Each chunk's band of rows (the rows of every tile it may change).
    std::vector<std::array<int, 2>> band(chunks);
    parallel_for(0, std::int64_t(chunks), 1, [&](std::int64_t c0, std::int64_t c1) {
        for (auto c = std::size_t(c0); c < std::size_t(c1); ++c) {
            int lo = hgt, hi = -1;
            for (std::size_t i = c * chunk; i < std::min(n, (c + 1) * chunk); ++i) {
                if (!p.alive[i]) continue;
                const double x = p.exchange[i];
                if (!(x != 0.0 && !std::isnan(x)) && !(double(p.pos[i].y) < s.sea_level)) continue;
                int ti, tj;
                double fx, fz;
                terrain.tile(p.pos[i].x, p.pos[i].z, ti, tj, fx, fz);
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
                if (terrain.exchange_rows(x, z, volume, mine)) q.push_back(Deferred{x, z, volume});
                changed = 1;
            };
            for (std::size_t i = c * chunk; i < std::min(n, (c + 1) * chunk); ++i) {
                if (!p.alive[i]) continue;
                const double x = p.exchange[i];
                const Vec3& at = p.pos[i];
                if (std::isnan(x)) {  // left over an open edge, with its sediment (summed in step 3)
                    q.push_back(Deferred{std::numeric_limits<float>::quiet_NaN(), 0.0f, p.sediment[i]});
                    p.sediment[i] = 0.0;
                    p.alive[i] = 0;
                    continue;
                }
                if (x != 0.0) {
                    apply(at.x, at.z, -x);
                    p.sediment[i] += x;
                }
                if (double(at.y) < s.sea_level) {
                    if (p.sediment[i] != 0.0) apply(at.x, at.z, p.sediment[i]);
                    p.sediment[i] = 0.0;
                    p.alive[i] = 0;
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
                --p.live;
                ++counts.left;
            } else {
                terrain.exchange_rows(d.x, d.z, d.volume, shared);
            }
        }
        p.live -= std::size_t(tally[c][0]);
        counts.sea += tally[c][0];
        changed = changed || tally[c][1] != 0;
    }
    if (changed) {
        terrain.mark_dirty();
        terrain.refresh_normals();
        lift_all();
    }
}

/// settle() in one loop, in particle order (few particles, or a map one vertex wide).
void Simulation::Impl::settle_serial() {
    bool changed = false;
    for (std::size_t i = 0; i < p.n; ++i) {
        if (!p.alive[i]) continue;
        const double x = p.exchange[i];
        const Vec3& at = p.pos[i];
        if (std::isnan(x)) {  // left over an open edge, with its sediment
            removed += p.sediment[i];
            p.sediment[i] = 0.0;
            p.kill(i);
            ++counts.left;
            continue;
        }
        if (x != 0.0) {
            terrain.exchange_terrain(at.x, at.z, -x);
            p.sediment[i] += x;
            changed = true;
        }
        if (double(at.y) < s.sea_level) {
            if (p.sediment[i] != 0.0) terrain.exchange_terrain(at.x, at.z, p.sediment[i]);
            p.sediment[i] = 0.0;
            p.kill(i);
            ++counts.sea;
            changed = true;
        }
    }
    if (changed) {
        terrain.refresh_normals();
        lift_all();
    }
}

/// After the terrain changed: lift particles a deposit has covered.
void Simulation::Impl::lift_all() {
    parallel_for(0, std::int64_t(p.n), 4096, [&](std::int64_t b, std::int64_t e) {
        for (std::int64_t ii = b; ii < e; ++ii) {
            const auto i = std::size_t(ii);
            if (!p.alive[i]) continue;
            const double ys = terrain.surface(p.pos[i].x, p.pos[i].z);
            if (double(p.pos[i].y) < ys) p.pos[i].y = terrain.above(ys);
        }
    });
}

/// The largest particle speed, m/s.
float Simulation::Impl::speed_max() const {
    const std::size_t n = p.n;
    const std::int64_t blocks = (std::int64_t(n) + 4095) / 4096;
    std::vector<float> m(std::size_t(std::max<std::int64_t>(blocks, 1)), 0.0f);
    parallel_for(0, blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
        for (std::int64_t blk = b0; blk < b1; ++blk) {
            float v2 = 0.0f;
            const std::size_t lo = std::size_t(blk * 4096), hi = std::min(n, lo + 4096);
            for (std::size_t i = lo; i < hi; ++i) {
                const Vec3& v = p.vel[i];
                v2 = std::max(v2, v.x * v.x + v.y * v.y + v.z * v.z);
            }
            m[std::size_t(blk)] = v2;
        }
    });
    float v2 = 0.0f;
    for (float x : m) v2 = std::max(v2, x);
    return std::sqrt(v2);
}

}  // namespace orogen::sph
