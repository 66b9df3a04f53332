// integrator.hpp — a simulation's state and the WCSPH sub-step that advances it (SPlisHSPlasH's time step):
// sort by cell (Neighbourhood), density pass, force pass, integrate (motion, terrain contact, erosion
// exchange), settle (the exchange applied to the terrain). sph.cpp is the public face (Simulation).
#pragma once

#include "kernels.hpp"
#include "neighbourhood.hpp"
#include "particles.hpp"
#include "sph.hpp"
#include "terrain_boundary.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace orogen::sph {

/// The fluid's constants, derived from Settings (float: the SPH loops run in single precision).
struct FluidConstants {
    float mass = 0, volume = 0;  ///< of a particle: kg, m³ (a cube of the spacing 2r)
    float rho0 = 0, B = 0, c0 = 0;  ///< rest density kg/m³, Tait's stiffness Pa, sound speed m/s
    float visc_eps = 0;  ///< 0.01 (h/2)², m²: keeps Π finite at r → 0
    float alpha_c_hs = 0;  ///< α c0 h/2, m²/s: Monaghan's viscosity coefficient

    static FluidConstants from(const Settings& s, float h);
};

struct Simulation::Impl {
    Impl(ConstGridView terrain, const Settings& settings, std::size_t capacity);

    Settings s;
    CubicSpline kernel;
    FluidConstants fluid;
    TerrainBoundary terrain;
    WallTable walls;
    Particles p;
    Neighbourhood cells;

    Counts counts;
    std::int64_t substeps = 0;
    double t = 0.0;
    double removed = 0.0;  // m³ of sediment gone over open edges
    float max_acc = 0.0f;  // m/s², the largest acceleration of the last force pass

    void density_pass();
    void side_walls(double x, double z, double ground, const double nrm[3], float& phi, Vec3& push) const;
    void force_pass();
    bool integrate(float dt);
    void settle();
    void settle_serial();
    void lift_all();
    float speed_max() const;

private:
    /// One particle of integrate(): the motion, the terrain contact, the map's edges, the erosion exchange.
    /// Returns false if the particle went non-finite.
    struct StepConstants;
    bool integrate_particle(std::size_t i, const StepConstants& k);
    double erosion_take(std::size_t i, const double vt[3], double ny, const StepConstants& k) const;

    // settle()'s steps and state (see integrator.cpp).
    struct Deferred;
    std::vector<int> row_owner;  // per terrain row: the chunk that owns it, -1 none, -2 shared
};

}  // namespace orogen::sph
