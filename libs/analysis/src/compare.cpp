// Reference bands and the distance between terrains' figures (compare.hpp).
#include <orogen/analysis/compare.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

namespace orogen::analysis {

bool Band::contains(double value) const { return known && std::isfinite(value) && value >= low && value <= high; }

Bands reference_bands(std::span<const Figures* const> references) {
    Bands bands;
    for (std::size_t f = 0; f < figure_count; ++f) {
        std::vector<double> values;
        for (const Figures* r : references)
            if (r->values[f].ok()) values.push_back(r->values[f].value);
        Band& band = bands[f];
        if (values.empty()) continue;
        band.known = true;
        band.low = *std::min_element(values.begin(), values.end());
        band.high = *std::max_element(values.begin(), values.end());
        if (values.size() < 2) continue;
        double mean = 0.0;
        for (double v : values) mean += v;
        mean /= double(values.size());
        double variance = 0.0;
        for (double v : values) variance += (v - mean) * (v - mean);
        band.spread = std::sqrt(variance / double(values.size()));
    }
    return bands;
}

Distance distance(const Figures& a, const Figures& b, const Bands& bands) {
    Distance d;
    double sum = 0.0;
    for (std::size_t f = 0; f < figure_count; ++f) {
        if (!a.values[f].ok() || !b.values[f].ok() || !(bands[f].spread > 0.0)) continue;
        const double z = (a.values[f].value - b.values[f].value) / bands[f].spread;
        sum += z * z;
        ++d.used;
    }
    if (d.used > 0) d.value = std::sqrt(sum / double(d.used));
    return d;
}

}  // namespace orogen::analysis
