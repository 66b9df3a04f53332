// landscape_stats.hpp — the statistics geomorphologists use to tell a real
// mountain range from a synthetic one, computed on a heightmap (metres):
//
//  * slope: the gradient of Horn's (1981) 3×3 method, as GIS tools compute it;
//    median and share steeper than 40° (Montgomery & Brandon 2002);
//  * pits: interior cells with no lower neighbour of 8, as a share of them;
//  * concavity θ: −(slope of log S against log A) over channel cells, A and S
//    along D8 steepest descent on the pit-filled surface, log-binned medians
//    (Flint 1974; Tucker & Whipple 2002 — θ is m/n of the stream-power law);
//  * Hack's exponent h: L = c·A^h, L the longest flow path above a channel
//    cell (Hack 1957; Rigon et al. 1996), log-binned medians.
#pragma once

#include <orogen/landscape/flow.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace orogen::landscape {

struct Stats {
    double median_slope_deg = 0.0;
    double steeper_than_40 = 0.0;  ///< share of cells, 0..1
    double pit_share = 0.0;  ///< share of interior cells, 0..1
    double concavity = 0.0;  ///< θ from the slope–area fit
    double hack = 0.0;  ///< h from the length–area fit
    double relief = 0.0;  ///< max − min, m
    int concavity_bins = 0, hack_bins = 0;
};

/// Least-squares slope of y on x.
inline double fit_slope(const std::vector<double>& x, const std::vector<double>& y) {
    double mx = 0, my = 0;
    for (std::size_t i = 0; i < x.size(); ++i) mx += x[i], my += y[i];
    mx /= double(x.size()), my /= double(x.size());
    double sxy = 0, sxx = 0;
    for (std::size_t i = 0; i < x.size(); ++i) sxy += (x[i] - mx) * (y[i] - my), sxx += (x[i] - mx) * (x[i] - mx);
    return sxy / sxx;
}

inline double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    const auto mid = v.begin() + std::ptrdiff_t(v.size() / 2);
    std::nth_element(v.begin(), mid, v.end());
    return *mid;
}

/// Log-binned medians (bins of 0.2 in log10 A, at least `min_count` samples) and their fit slope.
inline double binned_fit(const std::vector<double>& log_a, const std::vector<double>& log_y, int min_count, int& bins) {
    const double lo = *std::min_element(log_a.begin(), log_a.end()), hi = *std::max_element(log_a.begin(), log_a.end());
    const int nb = std::max(1, int(std::ceil((hi - lo) / (0.2 * std::log(10.0)))));
    std::vector<std::vector<double>> xs(std::size_t(nb) + 1), ys(std::size_t(nb) + 1);
    for (std::size_t i = 0; i < log_a.size(); ++i) {
        const auto b = std::size_t((log_a[i] - lo) / (0.2 * std::log(10.0)));
        xs[b].push_back(log_a[i]);
        ys[b].push_back(log_y[i]);
    }
    std::vector<double> bx, by;
    for (std::size_t b = 0; b < xs.size(); ++b)
        if (int(xs[b].size()) >= min_count) bx.push_back(median(xs[b])), by.push_back(median(ys[b]));
    bins = int(bx.size());
    return bx.size() >= 2 ? fit_slope(bx, by) : 0.0;
}

/// `channel_area`: cells draining at least this many m² are channels.
inline Stats measure(const float* heights, int w, int h, double cell, double channel_area = 1e5) {
    Stats st;
    const std::size_t n = std::size_t(w) * std::size_t(h);
    auto at = [&](int x, int y) { return double(heights[std::size_t(y) * std::size_t(w) + std::size_t(x)]); };
    std::vector<double> slopes;
    slopes.reserve(n);
    std::size_t steep = 0, pits = 0, interior = 0;
    for (int y = 1; y + 1 < h; ++y)
        for (int x = 1; x + 1 < w; ++x) {
            const double dzdx = ((at(x + 1, y - 1) + 2 * at(x + 1, y) + at(x + 1, y + 1)) -
                                 (at(x - 1, y - 1) + 2 * at(x - 1, y) + at(x - 1, y + 1))) /
                (8 * cell);
            const double dzdy = ((at(x - 1, y + 1) + 2 * at(x, y + 1) + at(x + 1, y + 1)) -
                                 (at(x - 1, y - 1) + 2 * at(x, y - 1) + at(x + 1, y - 1))) /
                (8 * cell);
            const double deg = std::atan(std::hypot(dzdx, dzdy)) * 180.0 / std::numbers::pi;
            slopes.push_back(deg);
            steep += deg > 40.0 ? 1 : 0;
            bool lower = false;
            for (int k = 0; k < 8; ++k) lower = lower || at(x + landscape::kDx[k], y + landscape::kDy[k]) < at(x, y);
            pits += lower ? 0 : 1;
            ++interior;
        }
    st.median_slope_deg = median(slopes);
    st.steeper_than_40 = double(steep) / double(interior);
    st.pit_share = double(pits) / double(interior);
    const auto [lo, hi] = std::minmax_element(heights, heights + n);
    st.relief = double(*hi) - double(*lo);

    // Flow on the filled surface, all sides open.
    std::vector<double> filled(heights, heights + n);
    landscape::FlowRouter flow(w, h, cell, landscape::OpenSides{});
    flow.route(filled.data(), landscape::Depressions::fill);
    flow.accumulate();
    const auto& rcv = flow.receivers();
    const auto& area = flow.area();
    // Longest flow path above each cell (m), in reverse stack order (donors first).
    std::vector<double> length(n, 0.0);
    const auto& stack = flow.stack();
    for (std::size_t s = n; s-- > 0;) {
        const std::int32_t i = stack[s], r = rcv[std::size_t(i)];
        if (r != i)
            length[std::size_t(r)] = std::max(length[std::size_t(r)], length[std::size_t(i)] + flow.distance(i));
    }
    std::vector<double> la, ls, ll, lla;
    const double max_area = *std::max_element(area.begin(), area.end());
    for (std::size_t i = 0; i < n; ++i) {
        const std::int32_t r = rcv[i];
        if (r == std::int32_t(i) || area[i] < channel_area) continue;
        ll.push_back(std::log(length[i]));
        lla.push_back(std::log(area[i]));
        const double s = (filled[i] - filled[std::size_t(r)]) / flow.distance(std::int64_t(i));
        if (s <= 1e-6 || area[i] > 0.1 * max_area) continue;  // filled flats; the largest trunks (few cells)
        la.push_back(std::log(area[i]));
        ls.push_back(std::log(s));
    }
    if (la.size() > 10) st.concavity = -binned_fit(la, ls, 20, st.concavity_bins);
    if (lla.size() > 10) st.hack = binned_fit(lla, ll, 20, st.hack_bins);
    return st;
}

}  // namespace orogen::landscape
