// orogen/climate/orographic_rain.hpp — where the rain falls on a mountain range.
//
// The linear theory of orographic precipitation (Smith & Barstad 2004): moist
// air forced up the terrain by a steady wind condenses water at the rate
// C_w·(U·∇h) (mm/s), the cloud water takes τ_c to turn into hydrometeors and
// they take τ_f to fall, so the rain lands downwind of where it formed, and
// the lifted air's vertical structure (the moist buoyancy frequency N_m, the
// water vapour's scale height H_w) spreads it. In Fourier space the rain is
// one product with the terrain's transform:
//
//     P̂(k, l) = C_w·iσ·ĥ(k, l) / ((1 − i·H_w·m)·(1 + iσ·τ_c)·(1 + iσ·τ_f)),
//     σ = u·k + v·l,    m² = (N_m² − σ²)/σ²·(k² + l²),
//
// m the vertical wavenumber: real with the sign of σ where the lifted air
// makes waves (σ² < N_m²), positive imaginary where it decays (σ² > N_m²).
// The rain is then P = max(0, P_0 + P_orographic): wet windward slopes and
// crests, a dry lee (the rain shadow). No Coriolis term (ranges under a few
// hundred kilometres).
//
// Units: heights m, wind m/s, times s, C_w kg/m³; the rain rate comes out in
// kg m⁻² s⁻¹ = mm/s and is returned as mean annual rain, m/yr: the moist wind
// blows a share f of the year (`wind_share`), the rest of the year other
// weather rains P_0 evenly, so
//
//     P_year = (1 − f)·P_0 + f·max(0, P_0 + P_orographic):
//
// flat ground gets P_0, the lee no less than (1 − f)·P_0 (f = 1: a lee that
// the wind's rain alone waters, dry where the shadow is deep).
//
// Smith, R.B. & Barstad, I. (2004), A linear theory of orographic
// precipitation, J. Atmos. Sci. 61, 1377–1391.
#pragma once

#include <complex>
#include <cstddef>
#include <vector>

namespace orogen::climate {

struct OrographicRain {
    double background = 1.0;  ///< P_0, m/yr: the mean annual rain on flat ground
    double wind_speed = 10.0;  ///< m/s, the moist wind's
    double wind_from = 270.0;  ///< azimuth the wind blows from, ° clockwise from north (270: westerly)
    double wind_share = 0.1;  ///< f: share of the year the moist wind blows (the rest rains P_0 evenly)
    double condensation_time = 1000.0;  ///< τ_c, s: cloud water to hydrometeors (200–2000 s)
    double fallout_time = 1000.0;  ///< τ_f, s: hydrometeors to the ground (200–2000 s)
    double moist_stability = 0.005;  ///< N_m, 1/s: the moist buoyancy frequency (0–0.01)
    double vapour_scale_height = 2500.0;  ///< H_w, m: the water vapour's scale height (1–4 km)
    /// C_w = ρ_Sref·Γ_m/γ, kg/m³: water condensed per metre of lift (0.004–0.01; warm air more)
    double uplift_sensitivity = 0.0083;
    bool operator==(const OrographicRain&) const = default;
};

/// Smith & Barstad's transfer function P̂/ĥ on one padded grid, kept by a caller that asks for the rain
/// every step: it depends only on the grid, the cell and the settings (checked at each call; it is
/// computed again when one differs), not on the heights. Computing it was ~1.5 % of a rainy
/// stream-power run (a complex division and a square root per wavenumber, every step).
struct RainTransfer {
    std::size_t nx = 0, ny = 0;
    double cell = 0.0;
    OrographicRain rain;
    std::vector<std::complex<double>> values;  // nx × ny, row-major
};

/// Mean annual rain (m/yr) over a width × height grid of heights (m, row-major, row 0 the northern edge,
/// x east) with cells of `cell` metres. The transform is periodic: `padding` > 0 adds at least that many
/// cells around the map (rounding the size up to a power of two), over which the terrain falls smoothly
/// from the map's edges to its lowest height, so no rain shadow wraps around and the edges make no cliff;
/// padding = 0 takes the map itself as one period. Throws std::invalid_argument on a bad size or setting.
/// With a `transfer`, its kept function is used (and made first when it does not fit): the same bits.
std::vector<double> orographic_rain(const double* heights, int width, int height, double cell,
                                    const OrographicRain& rain, int padding, RainTransfer* transfer = nullptr);

/// The same on a coarser grid: blocks of cells averaged into cells of about `resolution` metres (a whole
/// number of cells, at least one), the rain computed there with padding of five wind lengths
/// U·(τ_c + τ_f), and interpolated back bilinearly. The rain varies over kilometres (the theory damps
/// wavelengths much under 2π·U·τ), so a 200–500 m grid gives the same field for a small share of the work.
std::vector<double> orographic_rain_coarse(const double* heights, int width, int height, double cell,
                                           const OrographicRain& rain, double resolution);
/// The same into `out` (resized to width × height): a caller that asks every step reuses its memory
/// (at 4097² a fresh 134 MB array a step cost more in page faults than the transforms).
void orographic_rain_coarse(const double* heights, int width, int height, double cell, const OrographicRain& rain,
                            double resolution, std::vector<double>& out, RainTransfer* transfer = nullptr);

/// orographic_rain_coarse in parts, for a caller that holds the grid in tiles (a run split across
/// processes): each tile adds its heights to the blocks' sums, the sums are added up (in any order:
/// they are whole numbers), and each tile takes the coarse rain from them and interpolates its cells.
/// The same bits as orographic_rain_coarse, whatever the split.
struct CoarseRainGrid {
    int width = 0, height = 0;  ///< the fine grid, cells
    double cell = 0.0;  ///< its cell, m
    int factor = 1;  ///< cells per block side
    int coarse_width = 0, coarse_height = 0;  ///< blocks
};
/// The blocks for a width × height grid at `resolution` metres. Throws std::invalid_argument on a bad
/// size, setting or resolution.
CoarseRainGrid coarse_rain_grid(int width, int height, double cell, const OrographicRain& rain, double resolution);
/// Adds the heights of the w × h window at (x0, y0) of the grid (row-major, `heights` the window's own)
/// to `sums` (coarse_width × coarse_height, zeroed before the first window), in units that make every
/// sum a whole number: 2^-10 m when a block holds several cells, metres when it holds one.
void add_block_sums(const CoarseRainGrid& g, const double* heights, int x0, int y0, int w, int h,
                    std::vector<double>& sums);
/// The rain (m/yr) on the coarse grid from the blocks' whole sums. Throws std::invalid_argument naming
/// the block if a sum is not finite.
std::vector<double> coarse_rain(const CoarseRainGrid& g, const OrographicRain& rain, std::vector<double> sums,
                                RainTransfer* transfer = nullptr);
/// The coarse rain interpolated bilinearly onto the w × h window at (x0, y0) (`out` resized to it).
void interpolate_rain(const CoarseRainGrid& g, const std::vector<double>& coarse, int x0, int y0, int w, int h,
                      std::vector<double>& out);

/// The wind's components: east (x) and south (down the rows, y), m/s.
struct Wind {
    double east, south;
};
Wind wind_components(const OrographicRain& rain);

}  // namespace orogen::climate
