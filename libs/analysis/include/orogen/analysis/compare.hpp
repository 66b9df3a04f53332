// orogen/analysis/compare.hpp — a terrain's figures against references' (real DEMs'): the band each
// figure spans over the references, and a distance over all figures in units of the references' spread,
// as `orogen analyze --against` reports them ("which reference does this terrain resemble most?").
//
//   std::vector<const Figures*> refs = {&baspa, &rif, &kahurangi, &raukumara};
//   const Bands bands = reference_bands(refs);
//   bool ok = bands[std::size_t(FigureId::slope_median)].contains(mine[FigureId::slope_median].value);
//   const Distance d = distance(mine, rif, bands);
#pragma once

#include <orogen/analysis/figures.hpp>

#include <array>
#include <span>

namespace orogen::analysis {

/// What the references measured of one figure.
struct Band {
    double low = 0.0, high = 0.0;  ///< min and max over the references that measured it
    double spread = 0.0;  ///< their (population) standard deviation; 0 with fewer than two
    bool known = false;  ///< at least one reference measured it
    /// Whether `value` is finite and within [low, high] (false if no reference measured the figure).
    bool contains(double value) const;
};
using Bands = std::array<Band, figure_count>;

/// Each figure's band over `references` (figures a reference could not measure are left out of its band).
Bands reference_bands(std::span<const Figures* const> references);

struct Distance {
    double value = 0.0;  ///< root mean square of (a − b)/spread over the figures used
    std::size_t used = 0;  ///< figures both measured and the references spread over (spread > 0); 0: no distance
};

/// The distance between two terrains' figures in units of the references' spread.
Distance distance(const Figures& a, const Figures& b, const Bands& bands);

}  // namespace orogen::analysis
