// hydraulic.hpp — Olsen's four-step hydraulic erosion automaton (thesis
// §3.5.1, fig. 3.18), as a pure function of the previous state.
//
// Each step:
//   1. rain: every cell gets `rain` metres of water;
//   2. dissolve: water turns solubility · water · softness metres of terrain
//      into sediment; softness is the thesis's steepness hardness (1 − |n_y|)³
//      (n the unit surface normal: flat ground does not dissolve), 1, or
//      1 − a hardness layer;
//   3. flow: with altitude a = height + water, a cell with lower 4-neighbours
//      moves min(water, a − ā) (ā the mean altitude of it and its lower
//      neighbours: Olsen's two cases, level out or drain completely) to them
//      in proportion to each altitude drop, carrying sediment in proportion;
//   4. evaporate: water shrinks by the factor (1 − evaporation); sediment above
//      capacity · water is deposited.
// Water and sediment are state that carries from step to step (the thesis's
// code reset them every iteration). A receiver gains the pair term
// F_a·(a_a − a_b) from each giver a; the giver loses its total F_a·Σ drops
// (equal to the sum of its pair terms up to round-off), so terrain +
// sediment and water are conserved to round-off and each step is
// independent of the order of visiting cells (hence of the thread count).
#pragma once

#include <orogen/grid.hpp>

#include <cstdint>
#include <functional>

namespace orogen::hydraulic {

enum class Hardness {
    steepness,  ///< the thesis's (1 − |n_y|)³: steep ground dissolves, flat ground does not
    constant,  ///< softness 1 everywhere
    layer,  ///< softness 1 − clamp(layer, 0, 1)
};

struct Settings {
    double rain = 0.01;  ///< metres of water added to every cell per step (Olsen's Kr)
    double solubility = 0.01;  ///< metres of terrain dissolved per metre of water per step (Ks)
    double evaporation = 0.5;  ///< fraction of water evaporating per step (Ke), 0..1
    double capacity = 0.05;  ///< metres of sediment a metre of water holds (Kc)
    Hardness hardness = Hardness::steepness;
};

/// The state the automaton evolves. All views the same size.
struct State {
    GridView height;  ///< terrain, m
    GridView water;  ///< water column, m
    GridView sediment;  ///< dissolved material, m of terrain
};
struct ConstState {
    ConstGridView height, water, sediment;
};

/// One step: out = hydraulic(in). Buffers must not overlap. `hardness`
/// (Hardness::layer only) holds one value 0..1 per cell.
void step(const ConstState& in, const State& out, const Settings& settings, const float* hardness = nullptr);

/// `iterations` steps on `state` in place (double-buffered internally);
/// `on_step(i, current)` runs after step i (1-based).
void erode(const State& state, std::int64_t iterations, const Settings& settings, const float* hardness = nullptr,
           const std::function<void(std::int64_t, const ConstState&)>& on_step = {});

/// The water (m) each cell of `in` sends to its lower neighbours in the next
/// step (after rain and dissolving; before evaporation): where the water
/// runs, for the node's `flow` layer. Same rules as step().
void outflow(const ConstState& in, const Settings& settings, const float* hardness, GridView flow);

/// The thesis's steepness hardness 1 − (1 − |n_y|)³ (1 on flat ground, which does
/// not dissolve, falling toward 0 on cliffs)
/// of each cell, from the same slopes step() uses: the node's `hardness` layer.
void steepness_hardness(ConstGridView height, GridView out);

}  // namespace orogen::hydraulic
