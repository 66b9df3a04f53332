// Figures of the drainage network, as terrain_stats.py routes it: priority-flood fill with ε = 1e-4·cell
// (Barnes, Lehman & Mulla 2014) from every edge sample (and every sample beside a hole), D8 steepest
// descent on the filled heights (O'Callaghan & Mark 1984), drainage area accumulated from the highest
// cell down. On it: concavity θ and steepness k_sn (slope–area), Hack's exponent, drainage density,
// the network's share, hillslope length and channel sinuosity; the valleys along the channels (valleys.cpp).
#include "detail.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <queue>

namespace orogen::analysis::detail {

namespace {

/// terrain_stats.py fits θ only when more than this many channel cells qualify.
constexpr std::size_t minimum_channel_cells = 51;

struct Routing {
    std::vector<double> filled;  ///< m
    std::vector<std::int64_t> receiver;  ///< −1: none (outlet, hole, or no lower neighbour)
    std::vector<double> slope;  ///< to the receiver, m/m (0 without one)
    std::vector<double> distance;  ///< to the receiver, m
    std::vector<std::size_t> order;  ///< valid cells from the highest filled height down
};

Routing route(const Terrain& t) {
    const std::size_t n = t.size();
    const int w = t.width, h = t.height;
    Routing r;
    r.filled = t.z;

    // Priority flood: a min-heap on (height, row-major index) — the order of terrain_stats.py's heap
    // of (h, y, x) tuples, so ties pop alike and the filled heights agree bit for bit.
    using Entry = std::pair<double, std::size_t>;
    std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
    std::vector<std::uint8_t> done(n, 0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = t.at(x, y);
            if (!t.valid[i]) {
                done[i] = 1;  // holes take no part
                continue;
            }
            bool seed = x == 0 || y == 0 || x == w - 1 || y == h - 1;
            for (int dy = -1; dy <= 1 && !seed; ++dy)
                for (int dx = -1; dx <= 1 && !seed; ++dx) seed = !t.valid[t.at(x + dx, y + dy)];
            if (seed) {
                done[i] = 1;
                queue.emplace(r.filled[i], i);
            }
        }
    const double eps = 1e-4 * t.cell;
    while (!queue.empty()) {
        const auto [level, i] = queue.top();
        queue.pop();
        const int x = int(i % std::size_t(w)), y = int(i / std::size_t(w));
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int xx = x + dx, yy = y + dy;
                if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
                const std::size_t j = t.at(xx, yy);
                if (done[j]) continue;
                done[j] = 1;
                if (r.filled[j] <= level + eps) r.filled[j] = level + eps;
                queue.emplace(r.filled[j], j);
            }
    }

    // D8: the neighbour of steepest positive descent, the first in (dy, dx) row order on ties.
    r.receiver.assign(n, -1);
    r.slope.assign(n, 0.0);
    r.distance.assign(n, 0.0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = t.at(x, y);
            if (!t.valid[i]) continue;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int xx = x + dx, yy = y + dy;
                    if ((dx == 0 && dy == 0) || xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
                    const std::size_t j = t.at(xx, yy);
                    if (!t.valid[j]) continue;
                    const double d = std::hypot(double(dy), double(dx)) * t.cell;
                    const double s = (r.filled[i] - r.filled[j]) / d;
                    if (s > r.slope[i]) {
                        r.slope[i] = s;
                        r.receiver[i] = std::int64_t(j);
                        r.distance[i] = d;
                    }
                }
        }

    r.order.reserve(t.samples);
    for (std::size_t i = 0; i < n; ++i)
        if (t.valid[i]) r.order.push_back(i);
    // A receiver is strictly lower, so any descending order handles donors first; the index breaks
    // ties so the order (and every sum along it) is one.
    std::sort(r.order.begin(), r.order.end(), [&](std::size_t a, std::size_t b) {
        return r.filled[a] != r.filled[b] ? r.filled[a] > r.filled[b] : a < b;
    });
    return r;
}

std::string number(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", v);
    return text;
}

std::string area_text(double m2) {
    char text[32];
    std::snprintf(text, sizeof text, "%g km²", m2 / 1e6);
    return text;
}

}  // namespace

void measure_drainage(const Terrain& t, const Options& o, Figures& f) {
    if (t.width < 3 || t.height < 3) {
        const std::string why = "the terrain (" + std::to_string(t.width) + "x" + std::to_string(t.height) +
            ") is too small to route water over (needs at least 3x3)";
        for (FigureId id :
             {FigureId::concavity, FigureId::steepness, FigureId::hack_exponent, FigureId::drainage_density,
              FigureId::network_share, FigureId::hillslope_length, FigureId::channel_sinuosity,
              FigureId::channel_curvature, FigureId::valley_width, FigureId::valley_widening})
            f[id].why_not = why;
        return;
    }
    const Routing r = route(t);
    const std::size_t n = t.size();

    // Drainage area (m²) and the longest flow path upstream (m), donors before receivers.
    std::vector<double> area(n, t.cell * t.cell), length(n, 0.0);
    for (std::size_t i : r.order) {
        const std::int64_t j = r.receiver[i];
        if (j < 0) continue;
        area[std::size_t(j)] += area[i];
        length[std::size_t(j)] = std::max(length[std::size_t(j)], length[i] + r.distance[i]);
    }
    measure_valleys(t, o, area, f);

    // Slope–area over the channel cells (terrain_stats.py: A > 1 km² and S > 1e-4; without the cells the
    // fill raised unless o.fit_filled_cells).
    std::vector<double> ca, cs, cl, la, ls, ll;
    for (std::size_t i = 0; i < n; ++i)
        if (t.valid[i] && area[i] > o.channel_area && r.slope[i] > o.channel_min_slope &&
            (o.fit_filled_cells || !(r.filled[i] > t.z[i]))) {
            ca.push_back(area[i]);
            cs.push_back(r.slope[i]);
            cl.push_back(length[i]);
            la.push_back(std::log(area[i]));
            ls.push_back(std::log(r.slope[i]));
            ll.push_back(std::log(std::max(length[i], t.cell)));
        }
    if (ca.size() < minimum_channel_cells) {
        const std::string why = "only " + std::to_string(ca.size()) + " channel cells (draining more than " +
            area_text(o.channel_area) + ", slope above " + number(o.channel_min_slope) +
            (o.fit_filled_cells ? "" : ", not filled") + "); the fit needs " + std::to_string(minimum_channel_cells) +
            ": the terrain's rivers are too short";
        f[FigureId::concavity].why_not = why;
        f[FigureId::steepness].why_not = why;
        f[FigureId::hack_exponent].why_not = why;
    } else {
        f.slope_area_fit = fit_line(la, ls);
        f[FigureId::concavity].value = -f.slope_area_fit.slope;
        f.slope_area = log_bins(ca, cs, 10, 3);
        // k_sn: ln S + θ_ref ln A is ln k_sn on a steady-state channel of concavity θ_ref; its mean is the
        // intercept of the fit with the slope held at −θ_ref.
        double sum = 0.0;
        for (std::size_t k = 0; k < la.size(); ++k) sum += ls[k] + o.reference_concavity * la[k];
        f[FigureId::steepness].value = std::exp(sum / double(la.size()));
        f.hack_fit = fit_line(la, ll);
        f[FigureId::hack_exponent].value = f.hack_fit.slope;
        f.hack = log_bins(ca, cl, 10, 3);
    }

    // Channel sinuosity: from each channel cell, follow the receivers until the flow path is at least
    // sinuosity_reach long; its length over the straight distance between its ends. Reaches that leave the
    // map (or end in a hole) sooner are not counted.
    {
        double sum = 0.0;
        std::size_t reaches = 0;
        const std::size_t w = std::size_t(t.width);
        for (std::size_t i = 0; i < n; ++i) {
            if (!t.valid[i] || !(area[i] > o.channel_area)) continue;
            std::size_t j = i;
            double along = 0.0;
            while (along < o.sinuosity_reach && r.receiver[j] >= 0) {
                along += r.distance[j];
                j = std::size_t(r.receiver[j]);
            }
            if (along < o.sinuosity_reach) continue;
            const double dx = double(j % w) - double(i % w), dy = double(j / w) - double(i / w);
            const double straight = std::hypot(dx, dy) * t.cell;
            if (!(straight > 0.0)) continue;
            sum += along / straight;
            ++reaches;
        }
        if (reaches == 0)
            f[FigureId::channel_sinuosity].why_not = "no channel (draining more than " + area_text(o.channel_area) +
                ") runs " + number(o.sinuosity_reach) + " m before it leaves the terrain";
        else f[FigureId::channel_sinuosity].value = sum / double(reaches);
    }

    // The network: cells draining more than 0.1 km².
    std::size_t network = 0;
    double network_length = 0.0;
    for (std::size_t i = 0; i < n; ++i)
        if (t.valid[i] && area[i] > o.network_area) {
            ++network;
            network_length += r.distance[i];
        }
    f[FigureId::network_share].value = 100.0 * double(network) / double(t.samples);
    const double measured_area = double(t.samples) * t.cell * t.cell;  // m²
    if (network == 0) {
        const std::string why = "no cell drains more than " + area_text(o.network_area) + " (the terrain covers " +
            area_text(measured_area) + ")";
        f[FigureId::drainage_density].why_not = why;
        f[FigureId::hillslope_length].why_not = why;
        return;
    }
    f[FigureId::drainage_density].value = network_length / measured_area * 1000.0;  // 1/m → 1/km

    // Hillslope length: receivers before donors (the order reversed); −1 = flows off without meeting the network.
    std::vector<double> to_network(n, -1.0);
    double sum = 0.0;
    std::size_t hillslope = 0;
    for (auto it = r.order.rbegin(); it != r.order.rend(); ++it) {
        const std::size_t i = *it;
        if (area[i] > o.network_area) {
            to_network[i] = 0.0;
            continue;
        }
        const std::int64_t j = r.receiver[i];
        if (j < 0 || to_network[std::size_t(j)] < 0.0) continue;
        to_network[i] = to_network[std::size_t(j)] + r.distance[i];
        sum += to_network[i];
        ++hillslope;
    }
    if (hillslope == 0) {
        f[FigureId::hillslope_length].why_not = "no sample off the network drains into it";
        return;
    }
    f[FigureId::hillslope_length].value = sum / double(hillslope);
}

}  // namespace orogen::analysis::detail
