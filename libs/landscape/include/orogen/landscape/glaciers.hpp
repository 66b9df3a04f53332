// glaciers.hpp — valley glaciers in the landscape model: ice that gathers
// above the equilibrium-line altitude flows down the valleys, deepens them
// faster than rivers do and widens them into U-shaped troughs.
//
// The ice follows the river network (a "river of ice", as in the flux
// routing of glacial landscape models, e.g. Braun et al. 1999): each cell
// adds its surface mass balance
//
//     b(z) = min(γ·(z − ELA), b_max)        (m of ice per year)
//
// over its area to the ice it receives, and passes on what is left,
// Q_i = max(0, Q_in + b(z_i)·cell²) (m³/yr); below the ELA the ablation eats
// the flux until the glacier ends. Where the flux is a glacier's (Q ≥
// glacier_flux; thinner ice, the snow on the slopes and the peaks, is frozen
// to the rock and erodes nothing) the bed is eroded as
//
//     E = K_g·Q^{m_g}·S^n
//
// (sliding and abrasion grow with the ice flux, Humphrey & Raymond 1994),
// solved with the river's incision in the same implicit sweep, so it is
// stable for any dt. Glaciers are as wide as their flux asks (W ∝ Q^0.4,
// Bahr 1997's width–flux scaling): each glacier cell c holds the cells
// across its flow within its half-width R = R0·(Q/10⁶ m³/yr)^0.4 below the
// trough
//
//     h ≤ h_c − S_c·s + (tan θ_w / (2R))·p²,
//
// s the distance along the ice's flow (downstream positive, within one
// cell of c's cross-section), p across it, S_c the bed's slope down to c's
// receiver: a parabola across the valley whose walls reach the angle θ_w at
// the glacier's margin, following the glacier's own gradient down the
// valley. The rock above it is plucked from the trough's sides. That turns
// V-shaped river valleys into U-shaped troughs, and the heads, where the ice
// starts, into cirques.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

namespace orogen::landscape {

struct Glaciers {
    double ela = 0.0;  ///< equilibrium-line altitude, m
    double balance_gradient = 0.0;  ///< γ, (m of ice/yr) per m above the ELA; 0: no glaciers
    double max_balance = 2.0;  ///< b_max, m/yr
    double erodibility = 0.0;  ///< K_g, m^(1 − 3·m_g)·yr^(m_g − 1) for n = 1
    double flux_exponent = 0.5;  ///< m_g
    double half_width = 400.0;  ///< R0, m: the half-width of a glacier carrying 10⁶ m³/yr
    double wall_slope = 0.84;  ///< tan θ_w at the glacier's margin
    /// m³/yr: the ice flux from which the ice is a glacier that slides, erodes its bed and carves a
    /// trough; below it, the snow and firn on the slopes and the peaks erode nothing (they are thin and
    /// frozen to the rock: horns and arêtes stand above the glaciers)
    double glacier_flux = 2e5;
    bool any() const { return balance_gradient > 0.0; }
    /// b(z), m/yr.
    double balance(double z) const { return std::min(balance_gradient * (z - ela), max_balance); }
    /// R, m, for an ice flux q (m³/yr).
    double half_width_for(double q) const;
};

/// The ice flux (m³/yr) of every cell over a flow graph: `stack` lists the cells receivers first,
/// `receiver[i]` is i's receiver (itself at an outlet or pit), `heights` the surface (m).
void ice_flux(const Glaciers& glaciers, const double* heights, const std::int32_t* stack, const std::int32_t* receiver,
              std::size_t count, double cell, std::vector<double>& flux);

/// Holds every cell within a glacier's half-width below its trough (width × height grid, row-major;
/// `flux` from ice_flux, `receiver` the flow graph's). Reads the glacier cells' heights from before the
/// carving, so the result does not depend on the order the glaciers are visited. Returns the volume
/// removed (m³).
double carve_troughs(const Glaciers& glaciers, double* heights, const std::vector<double>& flux,
                     const std::int32_t* receiver, int width, int height, double cell);

}  // namespace orogen::landscape
