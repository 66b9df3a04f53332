// stream_power.hpp — landscape evolution by detachment-limited fluvial
// incision against rock uplift, with hillslope diffusion between the rivers:
//
//     ∂h/∂t = U − K·A^m·S^n + D·∇²h
//
// h elevation (m), t time (yr), U rock uplift rate (m/yr), A drainage area
// (m²), S the slope to the receiver (m/m), K erodibility (m^(1−2m)/yr for
// n = 1), D hillslope diffusivity (m²/yr).
//
// Each step of dt years: uplift every cell but the outlets (h* = h + U·dt);
// route water (flow.hpp: D8, pits resolved over the basin graph); accumulate
// drainage area; with D > 0, one implicit alternating-direction diffusion
// step (diffusion.hpp) with open sides fixed and closed sides closed; then
// solve the incision implicitly in stack order (Braun & Willett 2013), the
// receiver's new height known before its donors':
//
//     h_i' − h_i* + K·dt·A_i^m·((h_i' − h_r')/L)^n = 0,
//
// for n = 1 directly, h_i' = h_r' + (h_i* − h_r')/(1 + F) with F = K·dt·A^m/L; for
// n ≠ 1 by Newton's method on x = h_i' − h_r' (converges from x = h_i* − h_r'
// for n ≥ 1; safeguarded for n < 1). The scheme is stable for any dt, and a
// cell never drops below its receiver. A cell at or below its receiver's new
// height (a lake in Depressions::route, or a reach dammed by faster uplift
// downstream) is not eroded. Diffusion comes before the incision so that the
// step ends with every eroded cell above its receiver: the next routing then
// finds no pits (diffusing last left hundreds a step, docs/benchmarks.md).
//
// Every part is a pure function of the previous heights with a fixed visiting
// order, so the result is the same on any number of threads.
#pragma once

#include "banks.hpp"
#include "floodplain.hpp"
#include "flow.hpp"
#include "glaciers.hpp"
#include "rock.hpp"

#include <orogen/climate/orographic_rain.hpp>

#include <orogen/solvers/diffusion.hpp>
#include <orogen/solvers/threshold_slopes.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <vector>

namespace orogen::landscape {

/// A cell's rain over the background rain, as the drainage area weighs it: in whole 2^-20, so that
/// areas summed in any order (a tiled run's tiles) are exact and the same bits (a grid of 2^32 cells
/// at 1000 times the background stays below 2^53 units).
inline double rain_weight(double rain, double inv_background) {
    constexpr double unit = 1048576.0;  // 2^20
    return std::nearbyint(rain * inv_background * unit) / unit;
}
/// The rain (m/yr) in place turned into each cell's weight (rain_weight), and back (as weighed).
inline void rain_to_weights(std::vector<double>& rain, double background) {
    const double inv = 1.0 / background;
    for (double& v : rain) v = rain_weight(v, inv);
}
inline std::vector<double> weights_to_rain(std::vector<double> weights, double background) {
    for (double& v : weights) v *= background;
    return weights;
}

struct Settings {
    double erodibility = 2e-5;  ///< K, m^(1−2m)/yr (n = 1)
    double area_exponent = 0.45;  ///< m
    double slope_exponent = 1.0;  ///< n
    double diffusivity = 0.0;  ///< D, m²/yr (0: no hillslope diffusion)
    OpenSides open;
    Depressions depressions = Depressions::fill;
    /// > 0: drainage area by multiple flow directions (Freeman 1991), water split among the lower
    /// neighbours in proportion to slope^mfd_exponent (needs Depressions::fill); 0: D8.
    /// The incision follows the steepest receiver either way.
    double mfd_exponent = 0.0;
    /// G of Yuan et al. (2019), dimensionless, ≥ 0: a share of the sediment flux settles on its way down,
    ///     ∂h/∂t = U − K·A^m·S^n + (G/A)·Qs,   Qs = ∫_A (U − ∂h/∂t) dA  (m³/yr, over the cell and its donors).
    /// 0: detachment-limited (every grain leaves the map; the old solver, unchanged). At steady state
    /// Qs = U·A, so channels carry (1 + G)·U of incision: S = ((1 + G)·U/K)^(1/n)·A^(−m/n).
    double deposition = 0.0;
    /// A_c, m² (0: none): the drainage area at which rivers take over from hillslopes. Incision is
    /// K·A^m·(1 − e^(−A/A_c))·S^n: below about A_c the water runs over the slope as sheet wash and
    /// hardly cuts (channel heads at 10³–10⁵ m², Montgomery & Dietrich 1988, 1992), so hillslopes are
    /// shaped by creep (and, after the run, by landslides: erode:thermal) rather than by D8 lines one cell wide; above a few A_c the
    /// factor is 1 and the law is unchanged.
    double channel_area = 0.0;
    /// Sub-steps per step (≥ 1): the step's routing and drainage area serve this many sub-steps of
    /// uplift, creep, incision and landslides of dt/substeps each. Creep for a whole coarse step
    /// works on the slots the last incision left (U·dt deep) and the incision clears what it moved
    /// into them at once; sub-steps make that error small at the price of the cheap parts only
    /// (docs/landscape.md, "The time step is part of a calibration").
    int substeps = 1;
    /// The rock (rock.hpp): landslides at a threshold angle and beds of varying strength. With
    /// rock.angle > 0, after each step's incision whatever stands steeper than its rock's landslide
    /// angle slides away (threshold_slopes.hpp: the rivers carry the debris off, as in ranges that
    /// erode fast; Burbank et al. 1996, Montgomery & Brandon 2002), so hillslopes end planar at the
    /// threshold and the divides between them sharp.
    Beds rock;
    /// Rivers that widen their valleys (banks.hpp): with banks.any(), after each incision every river
    /// lowers the two cells across its flow by a share of its own lowering, the outer bank of a bend
    /// the most (lateral erosion, Langston & Tucker 2018).
    Banks banks;
    /// Floodplains (floodplain.hpp): with floodplain.any(), after the banks every cell within a large
    /// river's floodplain half-width W(A) is lowered to its nearest such river plus a gentle slope. Not tiled.
    Floodplain floodplain;
    /// Valley glaciers (glaciers.hpp): with glaciers.any(), ice gathers above the ELA, flows down the
    /// flow graph, erodes K_g·Q^m_g·S^n in the same implicit sweep as the rivers and carves U-shaped
    /// troughs. Detachment-limited only (deposition = 0), and not tiled.
    Glaciers glaciers;
    /// Rain that follows the relief (orographic_rain.hpp): with orographic_rain, each step computes
    /// the rain a steady moist wind leaves on the current heights (Smith & Barstad 2004) on a grid of
    /// about rain_resolution metres, and each cell adds rain/background of its area to the drainage
    /// area, so K is the erodibility under the background rain. Not tiled.
    bool orographic_rain = false;
    climate::OrographicRain rain;
    double rain_resolution = 250.0;  ///< m
};

/// Uplift that varies in time as well as in space: a piecewise-constant rate
/// field between frame times (years from the start of the run, increasing,
/// first 0). rate(k) gives interval k's rate (m/yr, one per cell), for
/// t in [times[k], times[k+1]); after the last time there is no history uplift.
/// It is asked for each interval once, in order, when the run reaches it.
struct UpliftHistory {
    std::vector<double> times;
    std::function<std::vector<double>(std::size_t)> rate;
};

/// Rock uplift of `years` at `rate` (m/yr) for every cell but the outlets (base level): added to the
/// heights `h` and to what each cell has received, `uplifted` (m); n cells.
void add_uplift(const double* rate, const std::uint8_t* outlets, double years, double* h, double* uplifted,
                std::int64_t n);

/// Throws std::invalid_argument unless the history's times increase.
void check_history(const UpliftHistory& history);

/// The history's uplift over the years [t0, t1]: the rate is piecewise
/// constant in time, so it is the sum over the intervals the step overlaps of
/// rate × overlap (exact for a step that spans frames). Calls add(rate,
/// overlap) per interval, in order; `rate`/`rate_k` keep the last interval's
/// rate (n values), asked of history.rate once when the run reaches it.
template <typename Add>
void for_history_intervals(const UpliftHistory& history, std::size_t& rate_k, std::vector<double>& rate, std::size_t n,
                           double t0, double t1, Add&& add) {
    const auto& T = history.times;
    for (std::size_t k = 0; k + 1 < T.size(); ++k) {
        const double overlap = std::min(t1, T[k + 1]) - std::max(t0, T[k]);
        if (!(overlap > 0.0)) continue;
        if (rate_k != k) {
            rate = history.rate(k);
            if (rate.size() != n)
                throw std::invalid_argument("stream_power: an uplift history rate is not the grid's size");
            rate_k = k;
        }
        add(rate.data(), overlap);
    }
}

/// What the implicit incision reads: the law's constants and the flow graph's arrays (flow.hpp), with
/// each cell's factors. The same for the whole-grid Model and for the stream-power process.
struct Incision {
    int width = 0;
    double cell = 0.0;  ///< m
    double erodibility = 2e-5, area_exponent = 0.45, slope_exponent = 1.0;  ///< K, m, n
    double inv_channel_area = 0.0;  ///< 1/A_c (inverse_channel_area), 0 for none
    const double* pow_table = nullptr;  ///< area_power_table(cell, m, inv_channel_area)
    const double* area = nullptr;  ///< drainage area, m²
    const std::int32_t* receivers = nullptr;
    const std::int32_t* stack = nullptr;  ///< receivers before donors
    std::span<const std::int64_t> chunks;  ///< independent groups of outlet basins (FlowRouter::chunks)
    const double* rock_k = nullptr;  ///< each cell's erodibility factor (rock_at), or null: 1
    const double* ice_f = nullptr;  ///< each cell's glacial K_g·dt·Q^m_g/L^n (glaciers), or null
};

/// The implicit incision of one step of `dt` years over heights `h`, detachment-limited: each outlet
/// basin group by one thread, in stack order (see the file's comment).
void incise(const Incision& in, double dt, double* h);

/// Incision with deposition's working arrays, kept between steps (allocated at the first).
struct DepositionScratch {
    std::vector<double> hs, pq, sums, tree, x;
    std::vector<std::int32_t> pos;
    std::vector<std::uint8_t> active;
    std::vector<double> chunk_out;
    std::vector<int> chunk_passes;
};
struct Deposited {
    double sediment_out = 0.0;  ///< m³ that left the map through the outlets
    int passes = 0;  ///< the most up-and-down passes an outlet basin needed
};
/// Incision with deposition (Yuan et al. 2019) of G = `deposition` over heights `h` (n cells); `d8`:
/// the tree's area is the drainage area (else summed over the receiver tree, with MFD routing).
Deposited incise_with_deposition(const Incision& in, double deposition, bool d8, double dt, double* h, std::size_t n,
                                 DepositionScratch& scratch);

/// The state of one landscape: heights (double, m) and the flow graph of the last step.
class Model {
public:
    /// `heights` width × height, metres; `uplift` per cell (m/yr) or empty (none).
    /// With every side closed the lowest start cell is the outlet.
    Model(int width, int height, double cell, std::vector<double> heights, std::vector<double> uplift,
          const Settings& settings);

    /// One step of `dt` years. Returns the pits found (before they were resolved).
    std::int64_t step(double dt);
    /// Run `years` in steps of `dt` (the last one shorter); on_step(step, steps) after each.
    void run(double years, double dt, const std::function<void(std::int64_t, std::int64_t)>& on_step = {});

    /// Adds a time-varying uplift to the per-cell rate given to the constructor; the run's clock
    /// starts at 0 and advances by each step's dt.
    void set_uplift_history(UpliftHistory history);
    /// Years simulated so far.
    double time() const { return time_; }
    /// With deposition: the sediment (m³) that left the map through the outlets in the last step.
    double sediment_out() const { return sediment_out_; }
    /// With deposition: the most up-and-down passes an outlet basin needed in the last step.
    int deposition_passes() const { return deposition_passes_; }

    /// Glaciers: each cell's ice flux in the last step (m³/yr); empty without glaciers.
    const std::vector<double>& ice_flux() const { return ice_; }
    /// With orographic rain: the rain of the last step (m/yr); empty otherwise.
    std::vector<double> rain() const;
    /// Route and accumulate over the current heights without eroding (for the output layers).
    void route_only();

    const std::vector<double>& heights() const { return h_; }
    /// Rock uplift each cell received so far (m): the uplift rates and the history times the years (0 for outlets).
    const std::vector<double>& uplifted() const { return uplifted_; }
    std::vector<double>& heights() { return h_; }
    const FlowRouter& flow() const { return flow_; }
    /// χ (m) of every cell for reference area a0 (m²): ∫ (a0/A)^(m/n) dx from the outlet upstream.
    std::vector<double> chi(double a0 = 1.0) const;
    /// Index of the first non-finite height, or −1.
    std::int64_t first_non_finite() const;
    const Settings& settings() const { return settings_; }

private:
    Incision incision() const;  // what incise() and incise_with_deposition() read, from this model
    void incise(double dt);
    void glacial_factors(double dt);  // ice_ and ice_f_ over this step's flow graph
    void incise_with_deposition(double dt);
    void erode_banks();  // after the incision: banks.hpp, against the heights saved in bank_before_
    void add_history_uplift(double t0, double t1);
    void accumulate(const double* routed);  // D8 or multiple-flow area over the routed heights
    void update_rain();  // orographic rain over the current heights, and each cell's weight

    int width_, height_;
    double cell_;
    Settings settings_;
    std::vector<double> h_, uplift_, uplifted_;
    FlowRouter flow_;
    std::vector<double> pow_table_;  // (c·cell²)^m for c cells of drainage area, c < 2^16
    std::unique_ptr<solvers::diffusion::Solver> diffusion_;
    std::vector<double> rock_slopes_, rock_k_;  // the rock each cell shows this step (rock_at), or empty
    RockMemo rock_memo_;  // the bed and slice each cell showed (rock_at)
    solvers::threshold::Scratch slope_scratch_;  // the landslide limit's working grids, kept between steps
    std::vector<double> bed_offset_;  // each cell's Beds::offset (the dip's and the folds' part), once
    std::vector<double> bank_before_;  // banks: heights before the incision, then its lowering
    std::vector<std::int8_t>
        bank_dir_;  // banks, floodplains: each cell's direction to its receiver (kDx/kDy), −1 at a root
    BankEroder banks_;
    std::vector<double> floodplain_nearest_, floodplain_floor_;  // floodplains: scratch
    std::vector<double> ice_, ice_f_;  // glaciers: each cell's ice flux (m³/yr) and its K_g·dt·Q^m_g/L^n
    std::vector<double> rain_weight_;  // orographic rain over the background rain, by cell
    climate::RainTransfer rain_transfer_;  // the rain's transfer function, the same every step
    double time_ = 0.0, sediment_out_ = 0.0;
    UpliftHistory history_;
    std::size_t history_k_ = std::size_t(-1);  // the interval whose rate is in history_rate_
    std::vector<double> history_rate_;
    // Deposition scratch (allocated when deposition > 0), by stack position: the uplifted, diffused
    // height h*, (p, q) of h' = p + q·h'_receiver, the sums over donors of their flux's affine
    // coefficients (Σα, Σβ: V_d = α + β·h'), the tree's area (MFD), the linearisation point (n ≠ 1),
    // whether the cell incises; and by cell its stack position.
    DepositionScratch deposition_;
    int deposition_passes_ = 0;
};

/// A^m for drainage areas of fewer than this many cells comes from a table:
/// areas are exact multiples of cell² (whole numbers of cells), and most cells
/// drain few cells, so the per-cell pow() becomes a lookup.
inline constexpr std::int64_t kPowTable = 1 << 16;

/// A^m·(1 − e^(−A/A_c)) (Settings::channel_area; inv_ac = 1/A_c, 0 for none) for one area.
inline double channel_area_power(double a, double m, double inv_ac) {
    const double am = std::pow(a, m);
    return inv_ac > 0.0 ? am * -std::expm1(-a * inv_ac) : am;
}

/// A^m·(1 − e^(−A/A_c)) for a drainage area `a` (m²): table[c] is the value for c
/// whole cells of a0 m² (inv_a0 = 1/a0); other areas below the table's last (rain-weighted ones) with
/// onset() for the factor (and sqrt for m = 1/2); channel_area_power() for the largest.
inline double area_power(double a, const double* table, double inv_a0, double a0, double m, double inv_ac) {
    const double c = a * inv_a0;
    if (c < double(kPowTable - 1)) {
        const auto ci = std::int64_t(c + 0.5);
        if (double(ci) * a0 == a) return table[ci];
        const double am = m == 0.5 ? std::sqrt(a) : std::pow(a, m);  // sqrt: a pow's time in a tenth
        return inv_ac > 0.0 ? am * onset(a * inv_ac) : am;
    }
    return channel_area_power(a, m, inv_ac);
}

/// The implicit incision of one cell for n ≠ 1: x = h_i' − h_r' in (0, Δ]
/// (Δ = h_i* − h_r' > 0) solving x − Δ + F·x^n = 0, by Newton's method.
inline double incised_drop(double delta, double F, double n) {
    double x = delta;
    for (int it = 0; it < 60; ++it) {
        const double xn1 = std::pow(x, n - 1.0);
        const double gx = x - delta + F * xn1 * x;
        const double dg = 1.0 + n * F * xn1;
        double next = x - gx / dg;
        if (next <= 0.0) next = 0.5 * x;  // n < 1: the concave residual can overshoot past zero
        if (next > delta) next = delta;
        const bool done = std::abs(next - x) <= 1e-12 * delta;
        x = next;
        if (done) break;
    }
    return x;
}

/// channel_area_power(c·cell², m, inv_ac) for c = 0 … kPowTable − 1 cells: area_power()'s table.
std::vector<double> area_power_table(double cell, double m, double inv_ac);
/// 1/A_c of the settings, or 0 without a channel area.
inline double inverse_channel_area(const Settings& s) { return s.channel_area > 0.0 ? 1.0 / s.channel_area : 0.0; }
/// The hillslope diffusion a step applies: implicit, open sides fixed, closed sides closed.
solvers::diffusion::Settings hillslope_settings(const Settings& settings);

/// The share of the uplift vertex (x, y) of a width × height grid (cells of `cell` m) keeps when the
/// uplift falls to zero towards the open sides over `taper` metres: smoothstep(d/taper), d the distance
/// (m) to the nearest open side; 1 with no open side or taper ≤ 0.
inline double edge_taper(int x, int y, int width, int height, double cell, const OpenSides& open, double taper) {
    if (!(taper > 0.0)) return 1.0;
    double d = taper;
    if (open.west) d = std::min(d, x * cell);
    if (open.east) d = std::min(d, (width - 1 - x) * cell);
    if (open.north) d = std::min(d, y * cell);
    if (open.south) d = std::min(d, (height - 1 - y) * cell);
    const double s = d / taper;
    return s * s * (3.0 - 2.0 * s);
}

/// The outlet with every side closed: the lowest cell (lowest index among equals).
std::int64_t lowest_cell(const std::vector<double>& heights);

/// Bytes per cell a Model needs (heights, uplift, flow graph, diffusion scratch), for the memory check.
inline constexpr std::size_t kBytesPerCell = 8 + 8 + 8 + 8 + 4 + 4 + 4 + 4 + 1 + 1 + 8 + 16 + 6;
/// Extra bytes per cell with deposition > 0 (seven doubles, a position and a flag of scratch).
inline constexpr std::size_t kBytesPerCellDeposition = 7 * 8 + 4 + 1;
/// Extra bytes per cell with orographic rain: each cell's weight (the coarse grid and its transform are small).
inline constexpr std::size_t kBytesPerCellRain = 8;

}  // namespace orogen::landscape
