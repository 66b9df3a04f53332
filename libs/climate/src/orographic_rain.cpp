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
std::complex<double> transfer(double k, double l, const Wind& wind, const OrographicRain& r) {
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
                                    const OrographicRain& rain, int padding) {
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
    parallel_for(0, std::int64_t(ny), 16, [&](std::int64_t y0, std::int64_t y1) {
        for (auto y = std::size_t(y0); y < std::size_t(y1); ++y) {
            const double l = wavenumber(y, ny, cell);
            for (std::size_t x = 0; x < nx; ++x) t[y * nx + x] *= transfer(wavenumber(x, nx, cell), l, wind, rain);
        }
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

void orographic_rain_coarse(const double* heights, int width, int height, double cell, const OrographicRain& rain,
                            double resolution, std::vector<double>& out) {
    check(rain, width, height, cell);
    if (!(resolution > 0.0) || !std::isfinite(resolution))
        throw std::invalid_argument("orographic rain: the resolution must be a positive number of metres");
    const int f = std::max(1, int(std::min(resolution / cell, 1e6)));
    const int cw = (width + f - 1) / f, ch = (height + f - 1) / f;
    // Block means (a partial block at the east or south edge averages the cells it has).
    std::vector<double> coarse(std::size_t(cw) * std::size_t(ch), 0.0);
    parallel_for(0, ch, 4, [&](std::int64_t Y0, std::int64_t Y1) {
        for (auto Y = int(Y0); Y < int(Y1); ++Y)
            for (int X = 0; X < cw; ++X) {
                double sum = 0.0;
                int count = 0;
                for (int y = Y * f; y < std::min(height, (Y + 1) * f); ++y)
                    for (int x = X * f; x < std::min(width, (X + 1) * f); ++x, ++count)
                        sum += heights[std::size_t(y) * std::size_t(width) + std::size_t(x)];
                coarse[std::size_t(Y) * std::size_t(cw) + std::size_t(X)] = sum / count;
            }
    });
    // A non-finite height makes its block's mean non-finite: name the height, not the block.
    for (std::size_t b = 0; b < coarse.size(); ++b)
        if (!std::isfinite(coarse[b]))
            for (std::size_t j = 0; j < std::size_t(width) * std::size_t(height); ++j)
                if (!std::isfinite(heights[j]))
                    throw std::invalid_argument("orographic rain: height " + std::to_string(j) +
                                                " is not a finite number");
    const double coarse_cell = cell * f;
    const double wind_length = rain.wind_speed * (rain.condensation_time + rain.fallout_time);
    const int padding =
        std::clamp(int(std::ceil(kPaddingWindLengths * wind_length / coarse_cell)), 1, std::max(cw, ch));
    std::vector<double> r = orographic_rain(coarse.data(), cw, ch, coarse_cell, rain, padding);
    if (f == 1) {
        out = std::move(r);
        return;
    }
    // Bilinear between the coarse cells' centres (held at the edges); each column's pair of coarse
    // columns and weight computed once.
    struct Axis {
        int i0, i1;
        double t;
    };
    auto axis = [f](int i, int n) {
        const double g = std::clamp((i + 0.5) / f - 0.5, 0.0, double(n - 1));
        const int i0 = int(g);
        return Axis{i0, std::min(i0 + 1, n - 1), g - i0};
    };
    std::vector<Axis> columns(static_cast<std::size_t>(width));
    for (int x = 0; x < width; ++x) columns[std::size_t(x)] = axis(x, cw);
    out.resize(std::size_t(width) * std::size_t(height));
    parallel_for(0, height, 16, [&](std::int64_t y0, std::int64_t y1) {
        std::vector<double> across(static_cast<std::size_t>(cw));  // the row's rain between its two coarse rows
        for (auto y = int(y0); y < int(y1); ++y) {
            const Axis a = axis(y, ch);
            const double* top = r.data() + std::size_t(a.i0) * std::size_t(cw);
            const double* bottom = r.data() + std::size_t(a.i1) * std::size_t(cw);
            for (int X = 0; X < cw; ++X) across[std::size_t(X)] = top[X] + (bottom[X] - top[X]) * a.t;
            double* row = out.data() + std::size_t(y) * std::size_t(width);
            for (int x = 0; x < width; ++x) {
                const Axis& c = columns[std::size_t(x)];
                row[x] = across[std::size_t(c.i0)] + (across[std::size_t(c.i1)] - across[std::size_t(c.i0)]) * c.t;
            }
        }
    });
}

}  // namespace orogen::climate
