// diffusion.hpp — hillslope diffusion, dh/dt = ∇·(D ∇h), solved implicitly by
// alternating directions so that any time step is stable.
//
// Soil creep moves material down-slope at a flux proportional to the slope,
// q = −D ∇h (Culling 1960; D in m²/yr, 10⁻³–10⁻¹ for soil-mantled hillslopes,
// Fernandes & Dietrich 1997, Roering et al. 1999). On a grid of vertices
// `cell` metres apart each step solves, one direction after the other, a
// tridiagonal system per row and per column (Thomas algorithm), so a step costs
// O(cells) whatever D·dt/cell² is:
//
//  * Scheme::implicit (default) — locally one-dimensional backward Euler:
//        (1 − r δxx) h* = hⁿ,   (1 − r δyy) hⁿ⁺¹ = h*,     r = D·dt/cell².
//    First order in time, and for every dt it keeps a maximum principle (no new
//    extremum, no overshoot at a scarp): what long geological steps need.
//  * Scheme::adi — Peaceman–Rachford (what fastscape does):
//        (1 − r/2 δxx) h* = (1 + r/2 δyy) hⁿ,   (1 − r/2 δyy) hⁿ⁺¹ = (1 + r/2 δxx) h*.
//    Second order in time; stable for every dt, but the shortest waves are
//    multiplied by ≈ −1 per step when r ≫ 1 (they ring rather than decay).
//
// Sides are either fixed (their vertices keep their height: a base level) or
// closed (no flux across them). Closed sides use the finite-volume form
// δxx h₀ = h₁ − h₀, so with every side closed Σh is conserved to round-off.
//
// Critical-slope (nonlinear) diffusion, q = −D ∇h / (1 − (|∇h|/Sc)²) (Roering,
// Kirchner & Dietrich 1999), is solved with the same sweeps and the
// diffusivity of each link taken from the slopes at the start of the step
// (lagged coefficients), the factor capped at `max_factor` so that slopes
// at or beyond Sc stay finite.
#pragma once

#include <orogen/tiles.hpp>

#include <cstddef>
#include <functional>
#include <vector>

namespace orogen::solvers::diffusion {

enum class Scheme {
    implicit,  ///< locally one-dimensional backward Euler (monotone, first order)
    adi,  ///< Peaceman–Rachford ADI (second order, can ring at r ≫ 1)
};

/// Which sides hold their height (fixed) rather than let nothing through (closed).
struct FixedSides {
    bool north = false, east = false, south = false, west = false;  ///< north = row 0, west = column 0
};

struct Settings {
    double diffusivity = 0.01;  ///< D, m²/yr (or m² per unit of the time step's unit)
    Scheme scheme = Scheme::implicit;
    FixedSides fixed;
    /// Sc for critical-slope diffusion (tan of the threshold angle, e.g. 1.25 ≈ 51°); 0 = linear.
    double critical_slope = 0.0;
    /// Largest factor 1/(1 − (S/Sc)²) a link may get (nonlinear only).
    double max_factor = 100.0;
};

/// Diffuses a width × height grid of heights (double, row-major, row 0 = north),
/// or one rank's tile of it in a tiled run (orogen/tiles.hpp).
/// Holds the scratch memory, so one Solver steps a grid many times without allocating.
class Solver {
public:
    Solver(int width, int height, double cell, const Settings& settings);
    /// This rank's tile of a tiled run: step() takes the tile's heights
    /// (owned().width × owned().height) and leaves there the bits the whole
    /// grid's solver gives on them. The sweeps' recurrences run across the
    /// tiles as Tiling::carry() chains (the eliminated coefficients one way,
    /// the solution back), and the edges a stencil reads come from the
    /// neighbours the same way, so step() is collective: every rank calls it
    /// with the same dt.
    Solver(Tiling& tiles, double cell, const Settings& settings);

    /// One step of `dt` (the time unit of D) on `heights` in place. Same bits
    /// for any thread count (each row and each column is solved by one thread)
    /// and any split into tiles.
    void step(double* heights, double dt);

    int width() const { return tw_; }
    int height() const { return th_; }

private:
    void linear_step(double* h, double dt);
    void nonlinear_step(double* h, double dt);
    /// Tiling::carry() over this solver's tile; with no tiling, the one tile:
    /// `advance` over every line at once.
    void carry(Tiling::Toward toward, std::vector<double>& values, int per_line,
               const std::function<void(int first, int count)>& advance);
    /// The rows just north and south of the tile (north_, south_) from `g` (the tile's values) on the
    /// neighbours; only where such a row exists in the whole grid are they read.
    void edge_rows(const double* g);
    /// The columns just west and east of the tile (west_, east_), likewise.
    void edge_columns(const double* g);

    Tiling* tiles_ = nullptr;
    int W_, H_;  // the whole grid, vertices
    int x0_, y0_;  // the tile's first vertex in it
    int tw_, th_;  // the tile
    double cell_;
    Settings settings_;
    std::vector<double> scratch_;  // h* between the two sweeps
    std::vector<double> scratch2_;  // nonlinear: the sweeps' eliminated coefficients c'
    std::vector<double> kx_, ky_;  // nonlinear: per-link diffusivity factors (see nonlinear_step)
    std::vector<double> carry_;  // the lines' carried values
    std::vector<double> north_, south_, west_, east_;  // the neighbours' edge lines
};

/// Σ heights over a grid (fixed order: the same double every time).
double total(const double* heights, std::size_t count);

}  // namespace orogen::solvers::diffusion
