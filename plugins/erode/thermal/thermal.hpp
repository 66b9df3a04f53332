// thermal.hpp — Olsen's thermal erosion (thesis §3.4), as a pure function of
// the previous state.
//
// Material slides from a cell to each lower neighbour whose height difference
// exceeds the talus threshold T (per neighbour: tan(talus)·distance, or one
// height difference in Olsen's original form). Olsen's rule moves
//     total = rate · softness · (d_max − T)        (metres)
// out of a cell, shared among the neighbours i with d_i > T in proportion to
// d_i. Written as outflow_i = F · d_i with one per-cell factor
// F = rate · softness · (d_max − T) / Σ d_i, the receiver gains F_a·(h_a − h_b)
// from each giver a, and the giver loses its total rate · softness · excess
// (= F·Σ d_i, one product instead of one per neighbour; equal to the sum of
// its pair terms up to float round-off), so material is conserved to float
// round-off and each step is a gather: the result does not depend on the
// order cells are visited, hence not on the thread count. (The thesis's code updated heights in place, so
// its result depended on the visiting order.)
#pragma once

#include <orogen/grid.hpp>

#include <cstdint>
#include <functional>
#include <string_view>

namespace orogen::thermal {

enum class Neighbourhood {
    von_neumann,  ///< 4 axis neighbours, distance = cell
    rotated,  ///< the thesis's rotated von Neumann: the 4 diagonals, distance = cell·√2.
    ///< Never moves material between the sub-lattices x+y even / odd, which
    ///< then drift apart: a diagonal hatching. Kept for the thesis's experiments.
    moore,  ///< all 8
};

enum class Hardness {
    constant,  ///< every cell moves material alike (softness 1)
    height,  ///< the thesis's height-aware hardness: softness = ((h_max − h)/(h_max − h_min))²
    layer,  ///< softness = 1 − clamp(layer, 0, 1) from a hardness layer
};

struct Settings {
    Neighbourhood neighbourhood = Neighbourhood::moore;
    /// Critical slope tan(talus angle), metres of drop per metre of horizontal
    /// distance. Used when talus_height < 0.
    double talus_slope = 0.7002075382097097;  // tan 35°
    /// Olsen's original form: one height difference (metres) for every
    /// neighbour, whatever its distance. Negative: use talus_slope.
    double talus_height = -1.0;
    /// Fraction of the excess above the threshold moved per step (Olsen: 0.5,
    /// the thesis's code: 0.01). At most 1.
    double rate = 0.5;
    Hardness hardness = Hardness::constant;
    /// Height range for Hardness::height (metres), fixed for a run so each
    /// step stays a pure function of the previous heights.
    float height_min = 0.0f, height_max = 1.0f;
};

/// Parse "von-neumann" | "rotated" | "moore"; throws orogen::BadInput otherwise.
Neighbourhood parse_neighbourhood(std::string_view name);

/// One step: out = thermal(in). `in` and `out` have the same size and are
/// either the same grid (in place) or do not overlap. `hardness`
/// (Hardness::layer only) holds in.size() values 0..1.
void step(ConstGridView in, GridView out, const Settings& settings, const float* hardness = nullptr);

/// `count` (1..kStepsPerSweep) steps from `in` to `out` in one sweep over the
/// grid, bit-identical to `count` calls of step(). `in` and `out` have the
/// same size and are either the same grid (in place) or do not overlap.
void steps(ConstGridView in, GridView out, int count, const Settings& settings, const float* hardness = nullptr);

/// Steps erode() does per sweep over the grid (temporal blocking: each row
/// is read from and written to memory once per kStepsPerSweep steps).
inline constexpr int kStepsPerSweep = 4;

/// `iterations` steps on `heights` in place, done kStepsPerSweep at a time
/// (the last sweep may do fewer); the result is bit-identical to
/// `iterations` calls of step(). `on_step(i, current)` is called with the
/// current heights after step i for every i that ends a sweep — every
/// kStepsPerSweep-th step and the last — for progress, cancellation and
/// finiteness checks.
void erode(GridView heights, std::int64_t iterations, const Settings& settings, const float* hardness = nullptr,
           const std::function<void(std::int64_t, ConstGridView)>& on_step = {});

/// The hardness (0..1) a cell of height h gets under Hardness::height.
inline float height_hardness(float h, float h_min, float h_max) {
    const float range = h_max - h_min;
    if (!(range > 0.0f)) return 0.0f;
    float t = (h_max - h) / range;
    t = t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
    return 1.0f - t * t;
}

}  // namespace orogen::thermal
