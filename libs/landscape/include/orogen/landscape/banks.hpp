// banks.hpp — rivers that widen their valleys: lateral erosion of the banks
// (after Langston & Tucker 2018).
//
// A river cuts sideways as well as down: the water undercuts the bank on the
// outside of each bend, the bank falls in and is carried off, and over time
// the channel sweeps a valley floor wider than itself. On a grid whose cells
// (30 m) are wider than the rivers, a channel that only cuts down leaves a
// V notch one cell wide; real valleys at that cell size have rounded floors
// several cells across (docs/realism.md: the Laplacian at cells draining
// more than 1 km² is 8–16 /km in real ranges, 27–29 /km without this).
//
// Each incision step, every river cell i (one that drains somewhere) that
// was lowered by e_i metres lowers its banks — on each side of its flow the
// edge neighbour across it (a river along an axis), or the two edge
// neighbours flanking it, half each (a diagonal river: its diagonal
// neighbours lie √2 cells off its line, the edge ones half as far) — by
//
//     δ = κ·(1 − e^(−A_i/A_b))·e_i·w,    w = (1 ± b)/2,
//
// κ the bank erosion (Langston & Tucker's ratio of lateral to vertical
// erodibility, times the share of the bank the water reaches), A_b the
// drainage area over which the river is wide and deep enough to undercut its
// banks, and b the bend: 0 where the river runs straight on from its main
// donor (the donor draining the most), ½ at a 45° turn, 1 at 90° or more.
// The outer bank (on the side the water comes from) takes (1 + b)/2, the
// inner (1 − b)/2: bends migrate outward, as meanders do. A bank never falls
// below the river that cuts it (the one pushing hardest, where several do)
// plus the floor slope over one cell, and outlets stay. What falls in leaves with the river (detachment-limited, as
// the incision).
//
// A large river (draining more than A_w, banks.wide_area) pushes on past
// a bank it has cut down: where the cell straight across its flow, r = 1
// cell away (√2 across a diagonal flow), is within half a metre of its
// floor (the river plus the floor slope over r), the river's whole push on
// that side falls on the next cell out, 2r away, which stops at the river
// plus the floor slope over 2r. Its valley floor is then about five cells
// wide rather than three, as real floors widen downstream (10 m above
// rivers draining 1 km², real 30 m DEMs' valleys are 90–150 m wide;
// tools/figures/texture_figures.py). The cell across the river finds the push it
// passes on as it settles (lower_banks) and the cell beyond reads it from
// its neighbour (lower_relayed): a reach of two cells with a halo of one,
// and one more exchange between. Rivers draining more than
// banks.wider_area push on once more, through the second cell to a third
// (3r away, the floor slope over 3r): floors seven cells wide, with a
// fourth pass and exchange. With banks.widest_floor, larger rivers push on
// further still, two cells more each time the drainage area grows by
// wider_area / wide_area (nine cells from wider_area²/wide_area, …), a
// pass and an exchange each: real floors keep widening downstream (10 m
// above the rivers, the valleys of the Kahurangi DEM are about 130 m wide
// at 1 km² and 300–400 m at 100 km²: `orogen analyze`'s valley widening).
//
// Each pass reads only the heights before it and writes separate
// arrays, so the result does not depend on the order or the threads, and a
// tile with a halo of one cell computes its own cells exactly (tiled.cpp).
#pragma once

#include "flow.hpp"
#include "onset.hpp"

#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

namespace orogen::landscape {

struct Banks {
    double erosion = 0.0;  ///< κ, dimensionless (0: banks stand)
    double area = 1e6;  ///< A_b, m²
    double floor_slope = 0.0;  ///< tan of the angle at which a lowered bank still rises from its river
    double wide_area = 0.0;  ///< A_w, m²: rivers draining more push on through a bank at its floor (0: none)
    double wider_area = 0.0;  ///< m²: rivers draining more (and A_w) push on through the next cell too (0: none)
    /// cells: floors widen on past seven cells, two cells more each time the drainage area grows by
    /// wider_area / wide_area, up to this many (odd; 0 or 7: seven at most)
    int widest_floor = 0;
    bool any() const { return erosion > 0.0; }
    bool wide() const { return any() && wide_area > 0.0; }
    bool wider() const { return wide() && wider_area > 0.0; }
    /// The relay passes after the first: 0 (floors five cells wide at most), 1 (seven), 2 (nine), …
    int onward_passes() const { return !wider() ? 0 : widest_floor > 7 ? (widest_floor - 5) / 2 : 1; }
    /// The drainage area (m²) from which a river's push travels k passes onward (k ≥ 1): its floor 5 + 2k
    /// cells wide.
    double onward_area(int k) const { return wider_area * std::pow(wider_area / wide_area, double(k - 1)); }
};

/// What each settled bank passes on to the cell beyond it (window-indexed): `push` (m) towards its
/// neighbour at direction code `out` (−1: nothing), which it may lower to `floor` (m) and no further, and
/// which passes it on `onward` more times (a river draining banks.onward_area(k): k) if it gets down to it.
struct BankRelay {
    std::vector<double> push, floor;
    std::vector<std::int8_t> out, onward;
    void size_to(std::size_t n) {
        if (push.size() == n && floor.size() == n && out.size() == n && onward.size() == n) return;
        push.assign(n, 0.0);
        floor.assign(n, 0.0);
        out.assign(n, -1);
        onward.assign(n, 0);
    }
};

/// 1 − e^(−A/A_b) for a drainage area A (m²): from a table when A is a whole number of cells below
/// 2^16 (as the incision's A^m: most cells drain few cells), else onset(). Built once per model.
class BankAreaFactor {
public:
    BankAreaFactor(const Banks& banks, double cell);
    double operator()(double area) const {
        const double c = area * inv_a0_;
        if (c < double(table_.size() - 1)) {
            const auto ci = std::size_t(c + 0.5);
            if (double(ci) * a0_ == area) return table_[ci];
        }
        return onset(area * inv_ab_);  // not a whole number of cells (rain-weighted areas)
    }

private:
    std::vector<double> table_;
    double a0_, inv_a0_, inv_ab_;
};

/// A window of `width` × `height` cells (row-major) in which the cells of
/// [x0, x1) × [y0, y1) are computed, their neighbours read (a tile's halo, or
/// the whole grid with the window's edge the grid's).
struct BankWindow {
    int width = 0, height = 0;
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

/// First pass: each computed cell's push on its banks (m): `right` on its
/// right looking downstream (the cell at direction (dir + 2) mod 8 for an axis
/// flow, half each on (dir + 1) and (dir + 3) for a diagonal one; kDx/kDy
/// codes), `left` on its left ((dir + 6); (dir + 5) and (dir + 7)); dir[i] = −1
/// for a root, which pushes nothing. `incised` the cell's lowering by the incision (m), `area` its
/// drainage area (m²). Both arrays are sized to the window (zeros when they
/// are not yet); the computed cells are written, the others kept (a tile's
/// halo, which the exchange after this pass fills).
void bank_pushes(const Banks& banks, const BankAreaFactor& factor, const BankWindow& w, const std::int8_t* dir,
                 const double* area, const double* incised, std::vector<double>& right, std::vector<double>& left);

/// The pushes bank_pushes wrote (window-indexed), as lower_banks reads them.
struct BankPushes {
    const double* right = nullptr;
    const double* left = nullptr;
};

/// Second pass (`flow`: the window's directions, areas and outlets, D8Flow): lowers each computed cell by
/// what its neighbours push on it,
/// not below the one pushing hardest plus banks.floor_slope over one cell; `outlet` cells (window-indexed, or null)
/// stay. With banks.wide() and a `relay` (sized to the window), also fills it for the computed cells: a
/// cell straight across a river draining at least banks.wide_area (`area`), left within half a metre of
/// its floor, passes that river's push on that side onward (banks.hpp). Returns the volume removed over
/// the computed cells, m³.
double lower_banks(const Banks& banks, const BankWindow& w, const D8Flow& flow, const BankPushes& pushes, double cell,
                   double* heights, std::vector<double>& scratch, BankRelay* relay = nullptr);

/// Third pass (banks.wide()): lowers each computed cell to the lowest that a neighbour passing a push
/// on towards it brings it (`relay` as lower_banks filled it, a tile's halo exchanged), not below that
/// push's floor; outlets stay. With `next` (banks.wider(); sized to the window), also fills it: a cell
/// brought within half a metre of the floor by a push with passes onward left passes it on, straight on,
/// its floor one step higher, one pass fewer left (the next pass, lower_relayed again on `next`). Visits
/// only the cells a relay points at (found from the relay: few, the large rivers' banks), so a pass costs
/// little beyond a scan of `relay.out`. Returns the volume removed, m³.
double lower_relayed(const Banks& banks, const BankWindow& w, const BankRelay& relay, const std::uint8_t* outlet,
                     double cell, double* heights, BankRelay* next = nullptr);

/// The three passes after one incision over a whole grid, with their working arrays kept between steps
/// (the whole-grid Model and the banks process).
class BankEroder {
public:
    /// `flow` each cell's direction to its receiver (kDx/kDy, −1 at a root), drainage area (m²) and whether
    /// it is an outlet (which stays); `lowering` what the incision lowered each cell by (m, ≥ 0); lowers
    /// `heights`.
    void erode(const Banks& banks, int width, int height, double cell, const D8Flow& flow, const double* lowering,
               double* heights);

private:
    std::optional<BankAreaFactor> factor_;  // 1 − e^(−A/A_b), built at the first step
    std::vector<double> right_, left_, scratch_;
    BankRelay relay_, relay2_;  // what a bank down to its floor passes on; what the second cell out passes on
};

}  // namespace orogen::landscape
