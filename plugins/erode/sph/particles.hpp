// particles.hpp — the particle arrays (structure of arrays) that the neighbourhood search sorts and the
// integrator advances.
#pragma once

#include "sph.hpp"

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace orogen::sph {

/// A cell's candidates are copied in whole blocks of kSlack floats (a row of a few cells: memcpy's call
/// costs more than the copy): up to kSlack − 1 floats past a run are read and written, so the source
/// arrays and the candidate buffers have that much slack at the end (what is written past a run is then
/// overwritten by the next run or the padding).
constexpr std::size_t kSlack = 8;

inline bool finite3(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// `n` particles, dead ones flagged until the next compaction (Neighbourhood::sort drops them).
struct Particles {
    std::size_t cap = 0, n = 0, live = 0;
    std::vector<Vec3> pos, vel, acc;
    std::vector<float> density, pterm;  // pterm = p/ρ²
    std::vector<double> sediment, exchange;  // m³ carried; m³ taken up this sub-step (<0 = dropped)
    std::vector<float> acidity;
    std::vector<std::int32_t> age, lifespan;
    std::vector<std::uint8_t> alive;
    std::vector<Vec3> wall_push;  // WallTable's area · the terrain's normal under each particle (this sub-step)
    // x, y, z (m), vx, vy, vz (m/s) of the particles in sorted order, written by Neighbourhood::sort: within a
    // sub-step the neighbour passes and integrate() read positions and velocities here (a cell's candidates
    // are then 9 contiguous runs to copy per component); integrate() writes pos and vel.
    std::array<std::vector<float>, 6> soa;

    /// Room for `capacity` particles (memory reserved up front: see Simulation::bytes_per_particle).
    void reserve(std::size_t capacity) {
        cap = capacity;
        pos.resize(capacity);
        vel.resize(capacity);
        acc.resize(capacity);
        density.resize(capacity + kSlack);
        wall_push.resize(capacity);
        pterm.resize(capacity + kSlack);  // kSlack: the candidate gathering's slack
        sediment.resize(capacity);
        exchange.resize(capacity);
        acidity.resize(capacity);
        age.resize(capacity);
        lifespan.resize(capacity);
        alive.resize(capacity);
        for (auto& a : soa) a.resize(capacity + kSlack);
    }

    void kill(std::size_t i) {
        alive[i] = 0;
        --live;
    }
};

}  // namespace orogen::sph
