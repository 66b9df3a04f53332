// sph.cpp — the public face of the SPH simulation (see sph.hpp for the model). The parts, after
// SPlisHSPlasH's: kernels.hpp (the cubic spline and the neighbour sums in vector lanes), neighbourhood.hpp
// (the cell sort), terrain_boundary.hpp (the terrain: surface, normals, contact, material exchange, wall
// table), integrator.hpp (the state and the sub-step's passes).
#include "sph.hpp"

#include "integrator.hpp"

#include <orogen/error.hpp>
#include <orogen/random.hpp>
#include <orogen/values.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <sstream>

namespace orogen::sph {

Simulation::Simulation(ConstGridView terrain, const Settings& settings, std::size_t capacity)
    : impl_(std::make_unique<Impl>(terrain, settings, capacity)) {}

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
    if (m.p.n >= m.p.cap) {
        ++m.counts.refused;
        return false;
    }
    const std::size_t i = m.p.n++;
    ++m.p.live;
    const double ys = m.terrain.surface(p.x, p.z);
    if (double(p.y) < ys) p.y = m.terrain.above(ys);
    m.p.pos[i] = p;
    m.p.vel[i] = v;
    m.p.acc[i] = Vec3{0.0f, float(-m.s.gravity), 0.0f};
    m.p.density[i] = m.fluid.rho0;
    m.p.pterm[i] = 0.0f;
    m.p.sediment[i] = 0.0;
    m.p.exchange[i] = 0.0;
    m.p.acidity[i] = acidity;
    m.p.age[i] = 0;
    m.p.lifespan[i] = lifespan;
    m.p.alive[i] = 1;
    ++m.counts.spawned;
    return true;
}

void Simulation::rain(std::int64_t count, double height, std::uint64_t seed, std::int64_t step, float acidity,
                      std::int32_t lifespan) {
    Impl& m = *impl_;
    for (std::int64_t k = 0; k < count; ++k) {
        const double x =
            random::uniform(seed, 0x5241494Eu, std::uint64_t(step), std::uint64_t(k), 0) * m.terrain.extent_x();
        const double z =
            random::uniform(seed, 0x5241494Eu, std::uint64_t(step), std::uint64_t(k), 1) * m.terrain.extent_z();
        add(Vec3{float(x), float(m.terrain.surface(x, z) + height), float(z)}, Vec3{}, acidity, lifespan);
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
            std::sqrt(random::uniform(seed, 0x535052u, std::uint64_t(which), std::uint64_t(step), std::uint64_t(k), 1));
        const double px = std::clamp(x + rr * std::cos(a), 0.0, m.terrain.extent_x());
        const double pz = std::clamp(z + rr * std::sin(a), 0.0, m.terrain.extent_z());
        const double lift = spacing *
            (1.0 + random::uniform(seed, 0x535052u, std::uint64_t(which), std::uint64_t(step), std::uint64_t(k), 2));
        add(Vec3{float(px), float(m.terrain.surface(px, pz) + lift), float(pz)}, Vec3{}, acidity, lifespan);
    }
}

double Simulation::stable_dt() const {
    const Impl& m = *impl_;
    const double vmax = m.speed_max();
    double dt = m.s.cfl * m.kernel.h / (m.fluid.c0 + vmax);
    if (m.max_acc > 0.0f) dt = std::min(dt, 0.25 * std::sqrt(double(m.kernel.h) / m.max_acc));
    return dt;
}

void Simulation::substep(double dt) {
    Impl& m = *impl_;
    if (m.p.n == 0 && m.p.live == 0) {
        m.t += dt;
        ++m.substeps;
        return;
    }
    m.cells.sort(m.p, false, m.s.merge_movers_up_to);
    m.density_pass();
    m.force_pass();
    const bool ok = m.integrate(float(dt));
    m.t += dt;
    ++m.substeps;
    if (!ok) {
        std::ostringstream msg;
        msg << "the SPH simulation went non-finite in sub-step " << m.substeps << " with " << m.p.live
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
            msg << "the SPH simulation went non-finite at step " << step << " with " << impl_->p.live << " particles";
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
    for (std::size_t i = 0; i < m.p.n; ++i) {
        if (!m.p.alive[i]) continue;
        ++m.p.age[i];
        const Vec3& p = m.p.pos[i];
        if (m.p.lifespan[i] > 0 && m.p.age[i] >= m.p.lifespan[i]) {
            if (m.p.sediment[i] != 0.0) {
                m.terrain.exchange_terrain(p.x, p.z, m.p.sediment[i]);
                changed = true;
            }
            m.p.sediment[i] = 0.0;
            m.p.kill(i);
            ++m.counts.evaporated;
            continue;
        }
        m.terrain.add_water(p.x, p.z, double(m.fluid.volume));
    }
    m.terrain.end_water_step();
    if (changed) {
        m.terrain.refresh_normals();
        m.lift_all();
    }
    if (m.p.live != m.p.n) m.cells.sort(m.p, true, m.s.merge_movers_up_to);
}

std::size_t Simulation::size() const { return impl_->p.live; }
std::size_t Simulation::capacity() const { return impl_->p.cap; }
const Counts& Simulation::counts() const { return impl_->counts; }
std::int64_t Simulation::substeps() const { return impl_->substeps; }
std::int64_t Simulation::merged_sorts() const { return impl_->cells.merged_sorts(); }
double Simulation::time() const { return impl_->t; }
double Simulation::surface(double x, double z) const { return impl_->terrain.surface(x, z); }

double Simulation::min_clearance() const {
    const Impl& m = *impl_;
    double c = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < m.p.n; ++i)
        if (m.p.alive[i]) c = std::min(c, double(m.p.pos[i].y) - m.terrain.surface(m.p.pos[i].x, m.p.pos[i].z));
    return c;
}

double Simulation::terrain_volume() const {
    const Impl& m = *impl_;
    double v = 0.0;
    for (double h : m.terrain.heights()) v += h;
    return v * m.terrain.cell() * m.terrain.cell();
}

double Simulation::carried_sediment() const {
    const Impl& m = *impl_;
    double s = 0.0;
    for (std::size_t i = 0; i < m.p.n; ++i)
        if (m.p.alive[i]) s += m.p.sediment[i];
    return s;
}

double Simulation::removed_sediment() const { return impl_->removed; }

// Views of the particle arrays: valid (dead ones compacted away) after end_step()
// or right after construction/add(); between sub-steps dead particles may remain.
std::span<const Vec3> Simulation::positions() const { return {impl_->p.pos.data(), impl_->p.n}; }
std::span<const Vec3> Simulation::velocities() const { return {impl_->p.vel.data(), impl_->p.n}; }
std::span<const float> Simulation::densities() const { return {impl_->p.density.data(), impl_->p.n}; }
std::span<const float> Simulation::pressures() const {
    // Not stored: p = pterm·ρ²; computed into a thread-local buffer.
    thread_local std::vector<float> p;
    const Impl& m = *impl_;
    p.resize(m.p.n);
    for (std::size_t i = 0; i < m.p.n; ++i) p[i] = m.p.pterm[i] * m.p.density[i] * m.p.density[i];
    return {p.data(), p.size()};
}
std::span<const float> Simulation::sediments() const {
    thread_local std::vector<float> s;
    const Impl& m = *impl_;
    s.resize(m.p.n);
    for (std::size_t i = 0; i < m.p.n; ++i) s[i] = float(m.p.sediment[i]);
    return {s.data(), s.size()};
}

void Simulation::write_terrain(GridView out) const {
    const Impl& m = *impl_;
    const std::vector<double>& h = m.terrain.heights();
    for (std::size_t i = 0; i < h.size(); ++i) out.data[i] = float(h[i]);
}

void Simulation::write_water(GridView out) const {
    const Impl& m = *impl_;
    const double k = m.terrain.water_steps() > 0 ? 1.0 / double(m.terrain.water_steps()) : 0.0;
    const std::vector<double>& water = m.terrain.water_sum();
    for (std::size_t i = 0; i < water.size(); ++i) out.data[i] = float(water[i] * k);
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
    for (std::size_t i = 0; i < m.p.n; ++i) {
        if (!m.p.alive[i]) continue;
        pos.data.insert(pos.data.end(), {m.p.pos[i].x, m.p.pos[i].y, m.p.pos[i].z});
        vel.data.insert(vel.data.end(), {m.p.vel[i].x, m.p.vel[i].y, m.p.vel[i].z});
        rho.data.push_back(m.p.density[i]);
        pre.data.push_back(m.p.pterm[i] * m.p.density[i] * m.p.density[i]);
        sed.data.push_back(float(m.p.sediment[i]));
        acid.data.push_back(m.p.acidity[i]);
        age.data.push_back(float(m.p.age[i]));
    }
}

}  // namespace orogen::sph
