// dambreak.hpp — Martin & Moyce's (1952) collapsing water column and a resting tank, in 3-D with side walls,
// as the SPH validation test (sph_physics_test.cpp) and the figure program (sph_validation.cpp) run them.
//
// The tank is the map: a flat terrain (the floor) whose closed edges are the walls, the column of width a
// and height 2a against the back wall x = 0, filling the tank's width. The solver is erode:sph's as the node
// runs it (Settings' defaults: kernel support 4·radius, the terrain and wall boundary terms, CFL 0.4 sub-steps
// from Simulation::advance, Monaghan's α = 0.05), with two choices made for the experiment: the speed of
// sound c0 = 10·√(2g·2a) (ten times the fastest the collapse can reach; the erosion's 20 m/s is that for
// 1 m of water) and no floor friction (their plate was smooth and wetted; friction is erode:sph's model of a
// rough bed, not part of the fluid).
#pragma once

#include "sph.hpp"

#include <orogen/grid.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <vector>

namespace orogen::sph_validation {

// Martin, J. C. & Moyce, W. J. (1952), "Part IV. An experimental study of the collapse of liquid columns on a
// rigid horizontal plane", Phil. Trans. R. Soc. Lond. A 244(882), 312–324: the column of width a and height
// n²a with n² = 2 (a = 2.25 in). Table 2: the surge front Z = x/a against T = n·t·√(g/a) = t·√(2g/a).
struct FrontPoint {
    double T, Z;
};
inline constexpr FrontPoint kMartinMoyceFront[] = {{0.41, 1.11}, {0.84, 1.22}, {1.19, 1.44}, {1.43, 1.67}, {1.63, 1.89},
                                                   {1.83, 2.11}, {1.98, 2.33}, {2.20, 2.56}, {2.32, 2.78}, {2.51, 3.00},
                                                   {2.65, 3.22}, {2.83, 3.44}, {2.98, 3.67}};
// Table 6: the residual column's height at the back wall η = h/(n²a) = h/(2a) against τ = t·√(g/a).
struct HeightPoint {
    double tau, eta;
};
inline constexpr HeightPoint kMartinMoyceHeight[] = {
    {0.56, 0.94}, {0.77, 0.89}, {0.93, 0.83}, {1.08, 0.78}, {1.28, 0.72}, {1.46, 0.67}, {1.66, 0.61}, {1.84, 0.56},
    {2.00, 0.50}, {2.21, 0.44}, {2.45, 0.39}, {2.70, 0.33}, {3.06, 0.28}, {3.44, 0.22}, {4.20, 0.17}};

constexpr double kGravity = 9.81;

/// Fill [0, nx·s] × [0, ny·s] × [0, nz·s] with particles on the fluid's rest lattice (spacing s).
inline void fill_block(sph::Simulation& sim, int nx, int ny, int nz, double s) {
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i)
                if (!sim.add({float((i + 0.5) * s), float((j + 0.5) * s), float((k + 0.5) * s)}, {}, 0.0f, 0))
                    throw std::runtime_error("fill_block: the particle budget is full");
}

/// erode:sph's settings for a fluid of spacing s whose fastest speed is about √(2g·depth).
inline sph::Settings fluid_settings(double s, double depth) {
    sph::Settings set;  // the node's defaults: cfl 0.4, α 0.05, closed boundary
    set.radius = s / 2.0;
    set.sound_speed = 10.0 * std::sqrt(2.0 * kGravity * depth);
    set.friction = 0.0;
    set.erode = false;
    return set;
}

/// A flat floor of (w·cell) × (d·cell) m whose edges (closed) are the tank's walls.
struct Floor {
    std::vector<float> h;
    ConstGridView view;
    Floor(int cells_x, int cells_z, double cell)
        : h(std::size_t(cells_x + 1) * std::size_t(cells_z + 1), 0.0f), view(h.data(), cells_x + 1, cells_z + 1, cell) {
    }
};

/// Martin & Moyce's column: `across` particles over its width a (m), 2·across high, `deep` across the tank,
/// in a tank 5a long.
class DamBreak {
public:
    /// `tweak` changes the settings before the simulation starts (sph_validation's sensitivity runs).
    template <typename Tweak = void (*)(sph::Settings&)>
    DamBreak(
        double a, int across, int deep, Tweak tweak = [](sph::Settings&) {})
        : a_(a), s_(a / across), deep_(deep), floor_(5 * across, deep, a / across),
          sim_(floor_.view, tweaked(fluid_settings(a / across, 2.0 * a), tweak),
               std::size_t(across) * 2 * across * deep) {
        fill_block(sim_, across, 2 * across, deep, s_);
    }

    sph::Simulation& sim() { return sim_; }
    double spacing() const { return s_; }
    double a() const { return a_; }
    /// t = T·√(a/2g), s.
    double time_of_T(double T) const { return T * std::sqrt(a_ / (2.0 * kGravity)); }
    /// t = τ·√(a/g), s.
    double time_of_tau(double tau) const { return tau * std::sqrt(a_ / kGravity); }
    double T() const { return sim_.time() / time_of_T(1.0); }

    /// Run to time t (s) in node steps of at most `step` s (each CFL-split by advance()).
    void run_to(double t, double step = 0.01) {
        while (sim_.time() < t * (1.0 - 1e-12)) sim_.advance(std::min(step, t - sim_.time()), ++steps_);
    }

    /// The surge front Z = x/a: in each slice of the tank one spacing wide (z), the leading particle's edge
    /// (its x + s/2); the median over the slices (a lone splash in one slice does not move it).
    double front() const {
        std::vector<double> lead(std::size_t(deep_), 0.0);
        for (const sph::Vec3& q : sim_.positions()) {
            const auto k = std::size_t(std::clamp(int(q.z / s_), 0, deep_ - 1));
            lead[k] = std::max(lead[k], double(q.x) + s_ / 2.0);
        }
        return median(lead) / a_;
    }
    /// The residual column's height at the back wall η = h/(2a): in each slice, the top particle's edge
    /// (y + s/2) among those within one spacing of the wall; the median over the slices.
    double height() const {
        std::vector<double> top(std::size_t(deep_), 0.0);
        for (const sph::Vec3& q : sim_.positions()) {
            if (q.x > s_) continue;
            const auto k = std::size_t(std::clamp(int(q.z / s_), 0, deep_ - 1));
            top[k] = std::max(top[k], double(q.y) + s_ / 2.0);
        }
        return median(top) / (2.0 * a_);
    }

private:
    template <typename Tweak>
    static sph::Settings tweaked(sph::Settings set, Tweak tweak) {
        tweak(set);
        return set;
    }
    static double median(std::vector<double> v) {
        std::sort(v.begin(), v.end());
        const std::size_t n = v.size();
        return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    }

    double a_, s_;
    int deep_;
    Floor floor_;
    sph::Simulation sim_;
    std::int64_t steps_ = 0;
};

/// Layer means of a resting tank's pressure against ρ·g·depth.
struct Layer {
    double depth;  ///< mean depth below the free surface, m
    double pressure;  ///< mean pressure, Pa
    double expect;  ///< ρ0·g·depth, Pa
    int count;
};

/// A tank nx × nz particles wide filled ny deep, walls on every side, settled for `settle` s; its layers
/// (2 spacings thick) from one spacing under the free surface down to the floor, over the whole width
/// (the wall particles included: the walls carry the boundary term).
struct RestingTank {
    Floor floor;
    sph::Simulation sim;
    double s;
    RestingTank(int nx, int ny, int nz, double spacing)
        : floor(nx, nz, spacing), sim(floor.view, settings(spacing, ny * spacing), std::size_t(nx) * ny * nz),
          s(spacing) {
        fill_block(sim, nx, ny, nz, s);
    }
    static sph::Settings settings(double s, double depth) {
        sph::Settings set = fluid_settings(s, depth);
        set.viscosity = 0.5;  // settles in fewer sound crossings; the hydrostatic state does not depend on it
        return set;
    }
    /// The free surface: half a spacing above the mean height of the top layer's particles.
    double surface() const {
        const auto pos = sim.positions();
        double top = 0.0;
        for (const auto& q : pos) top = std::max(top, double(q.y));
        double sum = 0.0;
        int n = 0;
        for (const auto& q : pos)
            if (double(q.y) > top - 0.5 * s) sum += q.y, ++n;
        return sum / n + 0.5 * s;
    }
    std::vector<Layer> layers() const {
        const auto pos = sim.positions();
        const auto p = sim.pressures();
        const double top = surface();
        const int count = int((top - s) / (2.0 * s));
        std::vector<Layer> out(std::size_t(std::max(count, 0)), Layer{0, 0, 0, 0});
        for (std::size_t i = 0; i < pos.size(); ++i) {
            const double depth = top - double(pos[i].y);
            if (depth < s) continue;
            const int l = std::min(count - 1, int((depth - s) / (2.0 * s)));
            Layer& L = out[std::size_t(l)];
            L.depth += depth;
            L.pressure += p[i];
            ++L.count;
        }
        for (Layer& L : out) {
            L.depth /= std::max(L.count, 1);
            L.pressure /= std::max(L.count, 1);
            L.expect = 1000.0 * kGravity * L.depth;
        }
        return out;
    }
};

}  // namespace orogen::sph_validation
