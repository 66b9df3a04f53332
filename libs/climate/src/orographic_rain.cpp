// The linear theory of orographic precipitation (orographic_rain.hpp).
#include <orogen/climate/orographic_rain.hpp>

#include <orogen/analysis/fft.hpp>
#include <orogen/parallel.hpp>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <stdexcept>
#include <string>

namespace orogen::climate {

namespace {

constexpr double kSecondsPerYear = 365.25 * 86400.0;
/// mm/s (kg m⁻² s⁻¹ of water) to m/yr.
constexpr double kMmPerSecondToMetresPerYear = kSecondsPerYear / 1000.0;
/// Padding of the coarse grid, in wind lengths U·(τ_c + τ_f): the rain a ridge makes decays downwind over
/// about one, so three leave e⁻³ of it to wrap around onto the upwind edge.
constexpr double kPaddingWindLengths = 3.0;

void check(const OrographicRain& r, int width, int height, double cell) {
    auto bad = [](const std::string& what) { throw std::invalid_argument("orographic rain: " + what); };
    if (width < 1 || height < 1) bad("the grid is empty");
    if (!(cell > 0.0) || !std::isfinite(cell)) bad("the cell size must be a positive number of metres");
    if (!(r.background >= 0.0) || !std::isfinite(r.background)) bad("the background rain must be ≥ 0 m/yr");
    if (!(r.wind_speed >= 0.0) || !std::isfinite(r.wind_speed)) bad("the wind speed must be ≥ 0 m/s");
    if (!std::isfinite(r.wind_from)) bad("the wind direction must be a number of degrees");
    if (!(r.wind_share > 0.0 && r.wind_share <= 1.0)) bad("the wind's share of the year must be in (0, 1]");
    if (!(r.condensation_time >= 0.0) || !(r.fallout_time >= 0.0) || !std::isfinite(r.condensation_time) ||
        !std::isfinite(r.fallout_time))
        bad("the condensation and fallout times must be ≥ 0 s");
    if (!(r.moist_stability >= 0.0) || !std::isfinite(r.moist_stability)) bad("N_m must be ≥ 0 1/s");
    if (!(r.vapour_scale_height >= 0.0) || !std::isfinite(r.vapour_scale_height)) bad("H_w must be ≥ 0 m");
    if (!(r.uplift_sensitivity >= 0.0) || !std::isfinite(r.uplift_sensitivity)) bad("C_w must be ≥ 0 kg/m³");
}

std::size_t padded_length(int n, int padding) {
    if (padding <= 0) return std::size_t(n);
    std::size_t p = 1;
    while (p < std::size_t(n) + 2 * std::size_t(padding)) p <<= 1;
    return p;
}

/// 1 at the map's edge falling to 0 over `length` cells (a half cosine): the padding's terrain.
double ramp(double distance, double length) {
    if (distance >= length) return 0.0;
    return 0.5 * (1.0 + std::cos(std::numbers::pi * distance / length));
}

/// The heights above the lowest on the nx × ny periodic grid: the map at [0, width) × [0, height), the rest
/// falling from the map's nearest edges to 0 (the lowest height) halfway across the padding.
std::vector<std::complex<double>> padded_terrain(const double* h, int width, int height, std::size_t nx, std::size_t ny,
                                                 double lowest) {
    std::vector<std::complex<double>> t(nx * ny, {0.0, 0.0});
    const auto W = std::size_t(width), H = std::size_t(height);
    const double gap_x = double(nx - W), gap_y = double(ny - H);
    for (std::size_t y = 0; y < H; ++y) {
        const double* row = h + y * W;
        for (std::size_t x = 0; x < W; ++x) t[y * nx + x] = row[x] - lowest;
        // Past the east edge, wrapping round to the west one.
        for (std::size_t x = W; x < nx; ++x) {
            const double from_east = double(x - W + 1), from_west = double(nx - x);
            const double len = 0.5 * (gap_x + 1.0);
            t[y * nx + x] = (row[W - 1] - lowest) * ramp(from_east, len) + (row[0] - lowest) * ramp(from_west, len);
        }
    }
    for (std::size_t y = H; y < ny; ++y) {
        const double from_south = double(y - H + 1), from_north = double(ny - y);
        const double len = 0.5 * (gap_y + 1.0);
        const double ws = ramp(from_south, len), wn = ramp(from_north, len);
        for (std::size_t x = 0; x < nx; ++x) t[y * nx + x] = t[(H - 1) * nx + x].real() * ws + t[x].real() * wn;
    }
    return t;
}

/// The wavenumber (rad/m) of transform index i of n samples `spacing` metres apart (numpy's fftfreq order).
double wavenumber(std::size_t i, std::size_t n, double spacing) {
    const double f = i < (n + 1) / 2 ? double(i) : double(i) - double(n);
    return 2.0 * std::numbers::pi * f / (double(n) * spacing);
}

/// Smith & Barstad's transfer function: P̂/ĥ, in mm/s per metre of terrain.
std::complex<double> transfer_at(double k, double l, const Wind& wind, const OrographicRain& r) {
    const double sigma = wind.east * k + wind.south * l;  // intrinsic frequency, 1/s
    if (sigma == 0.0) return {0.0, 0.0};  // ridges along the wind lift nothing
    const double s2 = sigma * sigma, n2 = r.moist_stability * r.moist_stability, k2 = k * k + l * l;
    const std::complex<double> i{0.0, 1.0};
    std::complex<double> airflow;
    if (s2 < n2) {  // buoyancy waves: m real, with σ's sign (energy going up)
        const double m = std::copysign(std::sqrt((n2 - s2) / s2 * k2), sigma);
        airflow = 1.0 - i * (r.vapour_scale_height * m);
    } else {  // evanescent: m = i·|m|, the lift decays with height
        airflow = 1.0 + r.vapour_scale_height * std::sqrt((s2 - n2) / s2 * k2);
    }
    return r.uplift_sensitivity * i * sigma /
        (airflow * (1.0 + i * (sigma * r.condensation_time)) * (1.0 + i * (sigma * r.fallout_time)));
}

}  // namespace

Wind wind_components(const OrographicRain& rain) {
    const double a = rain.wind_from * std::numbers::pi / 180.0;
    // From the west (270°) the air moves east; from the north (0°) it moves south, down the rows.
    return {-std::sin(a) * rain.wind_speed, std::cos(a) * rain.wind_speed};
}

std::vector<double> orographic_rain(const double* heights, int width, int height, double cell,
                                    const OrographicRain& rain, int padding, RainTransfer* transfer) {
    check(rain, width, height, cell);
    const std::size_t n = std::size_t(width) * std::size_t(height);
    double lowest = heights[0];
    for (std::size_t j = 0; j < n; ++j) {
        if (!std::isfinite(heights[j]))
            throw std::invalid_argument("orographic rain: height " + std::to_string(j) + " is not a finite number");
        lowest = std::min(lowest, heights[j]);
    }
    const std::size_t nx = padded_length(width, padding), ny = padded_length(height, padding);
    std::vector<std::complex<double>> t = padded_terrain(heights, width, height, nx, ny, lowest);
    analysis::fft2(t, nx, ny);
    const Wind wind = wind_components(rain);
    RainTransfer own;
    RainTransfer& kept = transfer ? *transfer : own;
    if (kept.nx != nx || kept.ny != ny || kept.cell != cell || !(kept.rain == rain) || kept.values.size() != nx * ny) {
        kept.values.resize(nx * ny);
        parallel_for(0, std::int64_t(ny), 16, [&](std::int64_t y0, std::int64_t y1) {
            for (auto y = std::size_t(y0); y < std::size_t(y1); ++y) {
                const double l = wavenumber(y, ny, cell);
                for (std::size_t x = 0; x < nx; ++x)
                    kept.values[y * nx + x] = transfer_at(wavenumber(x, nx, cell), l, wind, rain);
            }
        });
        kept.nx = nx, kept.ny = ny, kept.cell = cell, kept.rain = rain;
    }
    const std::complex<double>* const by = kept.values.data();
    parallel_for(0, std::int64_t(ny), 16, [&](std::int64_t y0, std::int64_t y1) {
        for (auto i = std::size_t(y0) * nx; i < std::size_t(y1) * nx; ++i) t[i] *= by[i];
    });
    analysis::fft2(t, nx, ny, true);
    // A share f of the year the moist wind rains P_0 + P_orographic (mm/s, here as m/yr), cut at zero in
    // the lee; the rest of the year other weather rains P_0 evenly.
    std::vector<double> out(n);
    const double f = rain.wind_share, p0 = rain.background;
    for (std::size_t y = 0; y < std::size_t(height); ++y)
        for (std::size_t x = 0; x < std::size_t(width); ++x) {
            const double windy = std::max(0.0, p0 + t[y * nx + x].real() * kMmPerSecondToMetresPerYear);
            out[y * std::size_t(width) + x] = (1.0 - f) * p0 + f * windy;
        }
    return out;
}

std::vector<double> orographic_rain_coarse(const double* heights, int width, int height, double cell,
                                           const OrographicRain& rain, double resolution) {
    std::vector<double> out;
    orographic_rain_coarse(heights, width, height, cell, rain, resolution, out);
    return out;
}

CoarseRainGrid coarse_rain_grid(int width, int height, double cell, const OrographicRain& rain, double resolution) {
    check(rain, width, height, cell);
    if (!(resolution > 0.0) || !std::isfinite(resolution))
        throw std::invalid_argument("orographic rain: the resolution must be a positive number of metres");
    CoarseRainGrid g;
    g.width = width;
    g.height = height;
    g.cell = cell;
    g.factor = std::max(1, int(std::min(resolution / cell, 1e6)));
    g.coarse_width = (width + g.factor - 1) / g.factor;
    g.coarse_height = (height + g.factor - 1) / g.factor;
    return g;
}

void add_block_sums(const CoarseRainGrid& g, const double* heights, int x0, int y0, int w, int h,
                    std::vector<double>& sums) {
    const int f = g.factor, cw = g.coarse_width;
    // Heights in whole 2^-10 m when a block holds several cells, so that every partial sum is a whole
    // number (exact below 2^53: blocks of 10^6 cells of 8 km) and any split adds up to the same bits.
    const double scale = f == 1 ? 1.0 : 1024.0;
    const int Y0 = y0 / f, Y1 = (y0 + h + f - 1) / f;
    parallel_for(Y0, Y1, 4, [&](std::int64_t b0, std::int64_t b1) {
        for (auto Y = int(b0); Y < int(b1); ++Y)
            for (int X = x0 / f; X < (x0 + w + f - 1) / f; ++X) {
                double sum = 0.0;
                for (int y = std::max(y0, Y * f); y < std::min(y0 + h, (Y + 1) * f); ++y)
                    for (int x = std::max(x0, X * f); x < std::min(x0 + w, (X + 1) * f); ++x) {
                        const double v = heights[std::size_t(y - y0) * std::size_t(w) + std::size_t(x - x0)];
                        sum += f == 1 ? v : std::nearbyint(v * scale);
                    }
                sums[std::size_t(Y) * std::size_t(cw) + std::size_t(X)] += sum;
            }
    });
}

std::vector<double> coarse_rain(const CoarseRainGrid& g, const OrographicRain& rain, std::vector<double> sums,
                                RainTransfer* transfer) {
    const int f = g.factor, cw = g.coarse_width, ch = g.coarse_height;
    const double scale = f == 1 ? 1.0 : 1024.0;
    for (int Y = 0; Y < ch; ++Y)  // block means (a partial block at the east or south edge has fewer cells)
        for (int X = 0; X < cw; ++X) {
            const int count = (std::min(g.height, (Y + 1) * f) - Y * f) * (std::min(g.width, (X + 1) * f) - X * f);
            double& v = sums[std::size_t(Y) * std::size_t(cw) + std::size_t(X)];
            v = v / (scale * count);
            if (!std::isfinite(v))
                throw std::invalid_argument("orographic rain: a height in block (" + std::to_string(X) + ", " +
                                            std::to_string(Y) + ") of " + std::to_string(f) + " x " +
                                            std::to_string(f) + " cells is not a finite number");
        }
    const double coarse_cell = g.cell * f;
    const double wind_length = rain.wind_speed * (rain.condensation_time + rain.fallout_time);
    const int padding =
        std::clamp(int(std::ceil(kPaddingWindLengths * wind_length / coarse_cell)), 1, std::max(cw, ch));
    return orographic_rain(sums.data(), cw, ch, coarse_cell, rain, padding, transfer);
}

void interpolate_rain(const CoarseRainGrid& g, const std::vector<double>& coarse, int x0, int y0, int w, int h,
                      std::vector<double>& out) {
    const int f = g.factor, cw = g.coarse_width, ch = g.coarse_height;
    out.resize(std::size_t(w) * std::size_t(h));
    // Bilinear between the coarse cells' centres (held at the edges); each column's pair of coarse
    // columns and weight computed once.
    struct Axis {
        int i0, i1;
        double t;
    };
    auto axis = [f](int i, int n) {
        const double c = std::clamp((i + 0.5) / f - 0.5, 0.0, double(n - 1));
        const int i0 = int(c);
        return Axis{i0, std::min(i0 + 1, n - 1), c - i0};
    };
    std::vector<Axis> columns(static_cast<std::size_t>(w));
    for (int x = 0; x < w; ++x) columns[std::size_t(x)] = axis(x0 + x, cw);
    parallel_for(0, h, 16, [&](std::int64_t r0, std::int64_t r1) {
        std::vector<double> across(static_cast<std::size_t>(cw));  // the row's rain between its two coarse rows
        for (auto y = int(r0); y < int(r1); ++y) {
            const Axis a = axis(y0 + y, ch);
            const double* top = coarse.data() + std::size_t(a.i0) * std::size_t(cw);
            const double* bottom = coarse.data() + std::size_t(a.i1) * std::size_t(cw);
            for (int X = 0; X < cw; ++X) across[std::size_t(X)] = top[X] + (bottom[X] - top[X]) * a.t;
            double* row = out.data() + std::size_t(y) * std::size_t(w);
            for (int x = 0; x < w; ++x) {
                const Axis& c = columns[std::size_t(x)];
                row[x] = across[std::size_t(c.i0)] + (across[std::size_t(c.i1)] - across[std::size_t(c.i0)]) * c.t;
            }
        }
    });
}

void orographic_rain_coarse(const double* heights, int width, int height, double cell, const OrographicRain& rain,
                            double resolution, std::vector<double>& out, RainTransfer* transfer) {
    const CoarseRainGrid g = coarse_rain_grid(width, height, cell, rain, resolution);
    std::vector<double> sums(std::size_t(g.coarse_width) * std::size_t(g.coarse_height), 0.0);
    add_block_sums(g, heights, 0, 0, width, height, sums);
    // A non-finite height makes its block's sum non-finite: then look for it, and name it, not its block
    // (the whole grid is searched only then, not every call).
    if (!std::all_of(sums.begin(), sums.end(), [](double v) { return std::isfinite(v); }))
        for (std::size_t j = 0; j < std::size_t(width) * std::size_t(height); ++j)
            if (!std::isfinite(heights[j]))
                throw std::invalid_argument("orographic rain: height " + std::to_string(j) + " is not a finite number");
    std::vector<double> r = coarse_rain(g, rain, std::move(sums), transfer);
    if (g.factor == 1) {
        out = std::move(r);
        return;
    }
    interpolate_rain(g, r, 0, 0, width, height, out);
}

}  // namespace orogen::climate
