// uplift.hpp — where the rock uplift of a landscape model comes from, as rates per cell (m/yr):
// a uniform rate, plus a layer of the terrain read as metres gained over some years (the plates'
// 'uplift'), or the height change between the frames of a history (plates.timelapse); spread as the
// bending crust spreads it (flexure: smoothing) and tapered towards the sides held at base level.
// Shared by erode:stream-power and the uplift process of erode:evolve, so both make the same bits.
#pragma once

#include "stream_power.hpp"

#include <orogen/tiles.hpp>
#include <orogen/values.hpp>

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace orogen::landscape {

/// Fastest rock uplift measured in active ranges (Taiwan, Nanga Parbat, the Southern Alps: 5–10 mm/yr),
/// with a margin; a faster rate from a layer is an error in its scale.
inline constexpr double kMaxUpliftMmYr = 20.0;

/// The sides named by letters (n, e, s, w), "all" or "none"; nullopt for anything else.
std::optional<OpenSides> parse_sides(const std::string& text);
/// "edge" → a present nullopt (outlets keep their heights); a number → that height in metres; nullopt
/// (absent) for anything else.
std::optional<std::optional<double>> parse_base_level(const std::string& text);

/// The uplift's sources, in the spec's units. `names` prefixes the parameters' names in messages
/// ("uplift_" for erode:stream-power's uplift_layer, "" for the uplift process's layer).
struct UpliftSources {
    double uniform = 1.0;  ///< mm/yr
    std::string layer;  ///< a layer of the terrain read as uplift (m); "" = none
    double layer_years = 1e6;  ///< yr over which the layer's metres were gained
    double smoothing = 0.0;  ///< m: spread over about this distance (0 = as is)
    double edge_taper = 0.0;  ///< m: falls to zero over this distance towards the open sides
    double history_years = 0.0;  ///< yr the history's frames span (0: the run's years)
    std::string names = "uplift_";
};

/// The terrain the rates are for: the whole grid, or this rank's tile of it under `tiles`.
struct UpliftGrid {
    const Heightmap& terrain;
    Tiling* tiles = nullptr;
    OpenSides open;
    /// A sample's index in the whole grid, for messages.
    std::int64_t sample(std::size_t k) const;
};

/// The steady rate (m/yr per sample): the uniform rate plus the layer read over its years, smoothed,
/// tapered; throws BadInput for a rate faster than any measured range.
std::vector<double> steady_uplift(const UpliftSources& sources, const UpliftGrid& grid);

/// A history of heights (`series`, rank 0's: whole frames; null on the other ranks) as rates between its
/// frames over `run_years` (or sources.history_years), each rate smoothed and tapered as the steady one;
/// throws BadInput for a history that is too short, does not advance or is too fast. Collective when tiled.
UpliftHistory uplift_history(const UpliftSources& sources, const UpliftGrid& grid,
                             const std::shared_ptr<const Series>& series, double run_years);

}  // namespace orogen::landscape
