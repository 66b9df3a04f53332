// uplift.cpp — the rock uplift's rates from its sources (see uplift.hpp).
#include <orogen/landscape/uplift.hpp>

#include <orogen/error.hpp>
#include <orogen/solvers/diffusion.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <sstream>

namespace orogen::landscape {

std::optional<OpenSides> parse_sides(const std::string& text) {
    OpenSides s{false, false, false, false};
    if (text == "none") return s;
    if (text == "all") return OpenSides{};
    for (char c : text) {
        switch (c) {
            case 'n': s.north = true; break;
            case 'e': s.east = true; break;
            case 's': s.south = true; break;
            case 'w': s.west = true; break;
            default: return std::nullopt;
        }
    }
    return s;
}

/// "edge" → nullopt (outlets keep their heights); a number → that height in metres.
std::optional<std::optional<double>> parse_base_level(const std::string& text) {
    if (text == "edge") return std::optional<double>{};
    double v = 0.0;
    const char* end = text.data() + text.size();
    const auto [p, ec] = std::from_chars(text.data(), end, v);
    if (ec != std::errc() || p != end || !std::isfinite(v)) return std::nullopt;
    return std::optional<double>{v};
}

std::int64_t UpliftGrid::sample(std::size_t k) const {
    if (!tiles) return std::int64_t(k);
    const TileRect own = tiles->owned();
    const auto x = std::int64_t(k % std::size_t(own.width)), y = std::int64_t(k / std::size_t(own.width));
    return (own.y0 + y) * tiles->grid_width() + own.x0 + x;
}

namespace {

/// The largest of every rank's `v` (exact), or `v` itself without tiles.
double largest(Tiling* tiles, double v) { return tiles ? tiles->reduce(v, Tiling::Reduce::max) : v; }

/// What the uplift helpers share: the sources, the terrain (this rank's tile when tiled) and the tiling.
struct UpliftInputs {
    UpliftSources src;  // copies: a history's rate function outlives the caller's arguments
    UpliftGrid grid;
    const Heightmap& hm;
    Tiling* tiles;
    std::size_t n;

    std::int64_t sample(std::size_t k) const { return grid.sample(k); }
    /// Smoothing: the crust bends (flexure), so uplift is spread wider than the plates' sharp relief. Four
    /// implicit diffusion steps with D·t = σ²/2 (volume-preserving: closed sides; backward Euler keeps the
    /// maximum principle, so the spread rate is never faster).
    void smooth(std::vector<double>& rate) const {
        const double sigma = src.smoothing;
        if (!(sigma > 0.0)) return;
        solvers::diffusion::Settings ds;
        ds.diffusivity = 1.0;
        solvers::diffusion::Solver blur = tiles ? solvers::diffusion::Solver(*tiles, hm.cell(), ds)
                                                : solvers::diffusion::Solver(hm.width(), hm.height(), hm.cell(), ds);
        for (int k = 0; k < 4; ++k) blur.step(rate.data(), 0.125 * sigma * sigma);
    }
    /// The uplift falls towards the open sides (the sides held at base level) over uplift_edge_taper
    /// metres, as a range's uplift falls to its foreland: rate × smoothstep(d/taper), d the distance to
    /// the nearest open side. Without it, full uplift beside a side held fixed raises a wall that short,
    /// straight rivers drain in parallel.
    void taper(std::vector<double>& rate) const {
        const double taper = src.edge_taper;
        if (!(taper > 0.0)) return;
        const OpenSides open = grid.open;
        const TileRect own = tiles ? tiles->owned() : TileRect{0, 0, hm.width(), hm.height()};
        const int W = tiles ? tiles->grid_width() : hm.width(), H = tiles ? tiles->grid_height() : hm.height();
        for (int y = 0; y < own.height; ++y)
            for (int x = 0; x < own.width; ++x)
                rate[std::size_t(y) * std::size_t(own.width) + std::size_t(x)] *=
                    edge_taper(own.x0 + x, own.y0 + y, W, H, hm.cell(), open, taper);
    }
    /// The fastest |rate + base| over every rank (m/yr).
    double fastest(const std::vector<double>& rate, double base) const {
        double fastest = 0.0;
        for (double r : rate) fastest = std::max(fastest, std::abs(r + base));
        return largest(tiles, fastest);
    }
};

/// Uplift (m/yr per sample): the uniform rate plus the layer read as metres accumulated over
/// uplift_layer_years, smoothed; refuses a rate faster than any measured range.
std::vector<double> steady_rate(const UpliftInputs& in) {
    const UpliftSources& src = in.src;
    const double uniform = src.uniform * 1e-3;  // mm/yr → m/yr
    std::vector<double> uplift(in.n, uniform);
    const std::string& layer = src.layer;
    if (layer.empty()) {
        in.taper(uplift);
        return uplift;
    }
    if (!in.hm.has_layer(layer)) throw BadInput(src.names + "layer: the input has no layer '" + layer + "'");
    const ConstGridView u = in.hm.layer(layer);
    const double years = src.layer_years;
    std::vector<double> rate(in.n);
    for (std::size_t i = 0; i < in.n; ++i) {
        if (!std::isfinite(u.data[i]))
            throw BadInput(src.names + "layer: layer '" + layer + "' holds a non-finite value at sample " +
                           std::to_string(in.sample(i)));
        rate[i] = double(u.data[i]) / years;
    }
    in.smooth(rate);
    for (std::size_t i = 0; i < in.n; ++i) uplift[i] += rate[i];
    in.taper(uplift);
    const double fastest = in.fastest(uplift, 0.0);
    if (fastest * 1e3 > kMaxUpliftMmYr) {
        std::ostringstream msg;
        msg << src.names << "layer_years: layer '" << layer << "' read over " << years << " years gives "
            << fastest * 1e3 << " mm/yr, faster than any measured range (at most " << kMaxUpliftMmYr
            << " mm/yr); give a longer " << src.names << "layer_years";
        throw BadInput(msg.str());
    }
    return uplift;
}

/// The history's frame times (years from the run's start), checked on rank 0 and shared with every rank.
std::vector<double> history_times(const UpliftSources& src, double run_years,
                                  const std::shared_ptr<const Series>& series, Tiling* tiles) {
    std::vector<double> times;
    std::string shared;
    if (series) {
        const std::size_t frames = series->size();
        if (frames < 2)
            throw BadInput("uplift_history: the series has " + std::to_string(frames) +
                           " frame(s); a rate needs at least two (the start and the end)");
        const double span = src.history_years > 0.0 ? src.history_years : run_years;
        const double t0 = series->times.front(), t1 = series->times.back();
        if (!(t1 > t0)) throw BadInput("uplift_history: the series' frames do not advance in time");
        for (std::size_t k = 0; k < frames; ++k) {
            times.push_back((series->times[k] - t0) / (t1 - t0) * span);
            if (k > 0 && !(times[k] > times[k - 1]))
                throw BadInput("uplift_history: frame " + std::to_string(k) + " is not later than frame " +
                               std::to_string(k - 1));
        }
        shared.assign(reinterpret_cast<const char*>(times.data()), times.size() * sizeof(double));
    }
    if (tiles) {
        tiles->share_from_rank0(shared);
        times.resize(shared.size() / sizeof(double));
        std::memcpy(times.data(), shared.data(), shared.size());
    }
    return times;
}

/// Uplift from a history (e.g. plates.timelapse): frame k's time, normalised so that the first frame is
/// year 0 of the run and the last is uplift_history_years (default: the run's years); between frames k and
/// k+1 the rate is their height change over the years between them. In a tiled run the series is rank
/// 0's (whole frames): rank 0 checks it and shares its times, and each interval's two frames are cut into
/// tiles for every rank to make its rate. Refuses an impossible rate before the run.
UpliftHistory history_rates(const UpliftInputs& in, const std::shared_ptr<const Series>& series, double run_years) {
    Tiling* tiles = in.tiles;
    UpliftHistory history;
    history.times = history_times(in.src, run_years, series, tiles);
    const int W = tiles ? tiles->grid_width() : in.hm.width(), H = tiles ? tiles->grid_height() : in.hm.height();
    auto frame = [series, tiles, W, H](std::size_t k) -> std::shared_ptr<const Heightmap> {  // collective when tiled
        std::shared_ptr<const Heightmap> f;
        if (series) {
            f = series->at(k).heightmap();
            if (!f || f->width() != W || f->height() != H)
                throw BadInput(
                    "uplift_history: frame " + std::to_string(k) + " is " +
                    (f ? std::to_string(f->width()) + " x " + std::to_string(f->height()) : "not a heightmap") +
                    ", the terrain " + std::to_string(W) + " x " + std::to_string(H));
        }
        return tiles ? tiles->scatter_from_rank0(f.get()) : f;
    };
    auto rate_of = [frame, times = history.times, in](std::size_t k) {
        const auto a = frame(k), b = frame(k + 1);
        const double years = times[k + 1] - times[k];
        std::vector<double> rate(in.n);
        for (std::size_t i = 0; i < in.n; ++i) {
            rate[i] = (double(b->heights()[i]) - double(a->heights()[i])) / years;
            if (!std::isfinite(rate[i]))
                throw BadInput("uplift_history: frame " + std::to_string(k + 1) +
                               " holds a non-finite height at sample " + std::to_string(in.sample(i)));
        }
        in.smooth(rate);
        in.taper(rate);
        return rate;
    };
    const double uniform = in.src.uniform * 1e-3;
    for (std::size_t k = 0; k + 1 < history.times.size(); ++k) {
        const double fastest = in.fastest(rate_of(k), uniform);
        if (fastest * 1e3 > kMaxUpliftMmYr) {
            std::ostringstream msg;
            msg << in.src.names << "history_years: frames " << k << " to " << k + 1 << " spread over "
                << history.times[k + 1] - history.times[k] << " years give " << fastest * 1e3
                << " mm/yr, faster than any measured range (at most " << kMaxUpliftMmYr << " mm/yr); give a longer "
                << in.src.names << "history_years";
            throw BadInput(msg.str());
        }
    }
    history.rate = rate_of;
    return history;
}

}  // namespace

std::vector<double> steady_uplift(const UpliftSources& sources, const UpliftGrid& grid) {
    const std::size_t n = grid.terrain.size();
    return steady_rate(UpliftInputs{sources, grid, grid.terrain, grid.tiles, n});
}

UpliftHistory uplift_history(const UpliftSources& sources, const UpliftGrid& grid,
                             const std::shared_ptr<const Series>& series, double run_years) {
    const std::size_t n = grid.terrain.size();
    return history_rates(UpliftInputs{sources, grid, grid.terrain, grid.tiles, n}, series, run_years);
}

}  // namespace orogen::landscape
