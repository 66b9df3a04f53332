// orogen/timelapse.hpp — heightmap snapshots every k steps, handed on as a series.
//
// An eroder or the plate simulation that a user wants to watch records its
// heightmap every `timelapse_every` steps into the side value
// `NAME.timelapse` (a series of heightmaps: the input, every k-th step and
// the last one). render:terrain maps over it frame by frame and export:video
// encodes the frames: a time-lapse of a mountain being carved.
//
//   registry.add({ ..., .side_outputs = {timelapse_output()},
//                  .params = {..., timelapse_param()}, .check = [](CheckContext& c) { check_timelapse(c, steps); } });
//   Timelapse lapse(ctx.integer("timelapse_every"), seconds_per_step);
//   lapse.record(0, *hm);                 // the input
//   ... each step: lapse.record(step, *hm);
//   lapse.finish(steps, *hm);             // the last state, once
//   out.side["timelapse"] = lapse.series();
#pragma once

#include <orogen/node.hpp>
#include <orogen/values.hpp>

#include <cstdint>
#include <memory>
#include <vector>

namespace orogen {

/// The parameter `timelapse_every` (steps between snapshots, 0 = none).
Param timelapse_param();
/// The side value `timelapse` (a series of heightmaps).
SideOutput timelapse_output();
/// Refuses, at parameter `timelapse_every`, snapshots of `steps` steps that
/// would not fit in half of this machine's memory (saying how much they need).
void check_timelapse(CheckContext& ctx, std::int64_t steps);

/// Snapshots of a heightmap (its heights and, when present, its `water`
/// layer: what a render of the frame needs).
class Timelapse {
public:
    /// `every` steps between snapshots (0: records nothing); a step lasts
    /// `seconds_per_step` of the series' clock (1 for automata that count steps).
    Timelapse(std::int64_t every, double seconds_per_step);
    /// In a tiled run (orogen/tiles.hpp): record() and finish() take this
    /// rank's tile and are collective (every rank calls them with the same
    /// steps, which the snapshots' choice depends on only); rank 0 gathers each
    /// snapshot of the whole grid and holds the series, the other ranks hold
    /// none. The frames are the bytes one process records.
    Timelapse(std::int64_t every, double seconds_per_step, Tiling& tiles);

    bool enabled() const { return every_ > 0; }
    /// Records `terrain` if `step` is 0 or has crossed a multiple of `every`
    /// since the last snapshot (callbacks that come every few steps still
    /// give one snapshot per k steps).
    void record(std::int64_t step, const Heightmap& terrain);
    /// The same from views: heights and an optional water layer of the same size
    /// (for solvers whose current state lives in their own buffers).
    void record(std::int64_t step, ConstGridView heights, const float* water = nullptr);
    /// The same from grids that hold the tile with a margin (a solver's grown
    /// tile): the tile's first vertex at (x0, y0) of `held` (and of `water`).
    void record(std::int64_t step, ConstGridView held, const float* water, int x0, int y0);
    /// Whether record(step, ...) takes a snapshot now.
    bool due(std::int64_t step) const { return enabled() && (last_ < 0 || step / every_ > last_ / every_); }
    /// Records the final state unless `step` was just recorded.
    void finish(std::int64_t step, const Heightmap& terrain);
    std::size_t size() const { return frames_.size(); }
    /// The snapshots as a series (empty if disabled).
    std::shared_ptr<Series> series() const;

private:
    void take(std::int64_t step, ConstGridView heights, const float* water, int x0 = 0, int y0 = 0);
    std::int64_t every_;
    Tiling* tiles_ = nullptr;
    double seconds_per_step_;
    std::int64_t last_ = -1;
    std::vector<double> times_;
    std::vector<Value> frames_;
};

}  // namespace orogen
