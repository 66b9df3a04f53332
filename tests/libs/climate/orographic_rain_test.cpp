// Orographic rain (Smith & Barstad 2004) against closed forms: one Fourier mode of terrain gives one
// mode of rain, whose amplitude and phase the theory states in each limit; a hill's rain shadow; the
// padding; the coarse grid; threads; bad input.
#include <orogen/climate/orographic_rain.hpp>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

namespace {

using orogen::climate::OrographicRain;
constexpr double kPi = std::numbers::pi;
constexpr double kMmPerSecondToMetresPerYear = 365.25 * 86400.0 / 1000.0;

/// One period of h = A·cos(k·x + l·y) on a width × height grid (x east, y south, cell metres).
struct Mode {
    int width = 64, height = 32;
    double cell = 500.0, amplitude = 300.0;
    int cycles_x = 3, cycles_y = 2;
    double k() const { return 2 * kPi * cycles_x / (width * cell); }
    double l() const { return 2 * kPi * cycles_y / (height * cell); }
    double phase(int x, int y) const { return k() * x * cell + l() * y * cell; }
    std::vector<double> heights() const {
        std::vector<double> h(std::size_t(width) * height);
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) h[std::size_t(y) * width + x] = 1000.0 + amplitude * std::cos(phase(x, y));
        return h;
    }
};

/// Rain with a background so large that nothing is cut at zero: the storm rate's orographic part, mm/s.
std::vector<double> storm_part(const Mode& mode, OrographicRain r) {
    r.background = 1e4;
    r.wind_share = 0.5;
    const auto h = mode.heights();
    auto p = orogen::climate::orographic_rain(h.data(), mode.width, mode.height, mode.cell, r, 0);
    // P_year = (1 − f)·P_0 + f·(P_0 + P_orographic) where nothing is cut.
    for (double& v : p) v = (v - r.background) / r.wind_share / kMmPerSecondToMetresPerYear;
    return p;
}

/// |P − want| over the grid, relative to want's amplitude.
template <typename Want>
double worst(const Mode& mode, const std::vector<double>& p, double amplitude, Want want) {
    double e = 0.0;
    for (int y = 0; y < mode.height; ++y)
        for (int x = 0; x < mode.width; ++x)
            e = std::max(e, std::abs(p[std::size_t(y) * mode.width + x] - want(x, y)) / amplitude);
    return e;
}

OrographicRain upslope_only() {
    OrographicRain r;
    r.condensation_time = r.fallout_time = 0.0;
    r.vapour_scale_height = 0.0;
    return r;
}

TEST(OrographicRain, WithoutDelaysOrDepthItIsTheUpslopeModel) {
    // τ_c = τ_f = 0, H_w = 0: P = C_w·(U·∇h), the wind's lift of the air at the ground, at every cell.
    const Mode mode;
    for (double from : {270.0, 0.0, 225.0, 100.0}) {
        OrographicRain r = upslope_only();
        r.wind_from = from;
        const auto wind = orogen::climate::wind_components(r);
        const double sigma = wind.east * mode.k() + wind.south * mode.l();
        const double amp = r.uplift_sensitivity * mode.amplitude * std::abs(sigma);
        const auto p = storm_part(mode, r);
        EXPECT_LT(worst(mode, p, amp,
                        [&](int x, int y) {
                            return -r.uplift_sensitivity * mode.amplitude * sigma * std::sin(mode.phase(x, y));
                        }),
                  1e-9)
            << "wind from " << from << "°";
    }
}

TEST(OrographicRain, TheWindBlowsFromTheAzimuthItIsGiven) {
    // A westerly moves air east (+x), a northerly south (down the rows).
    OrographicRain r;
    r.wind_from = 270.0;
    EXPECT_NEAR(orogen::climate::wind_components(r).east, r.wind_speed, 1e-12);
    EXPECT_NEAR(orogen::climate::wind_components(r).south, 0.0, 1e-12);
    r.wind_from = 0.0;
    EXPECT_NEAR(orogen::climate::wind_components(r).south, r.wind_speed, 1e-12);
}

TEST(OrographicRain, DelaysCarryTheRainDownwindAndWeakenIt) {
    // Each delay τ multiplies the mode by 1/(1 + iστ): amplitude 1/√(1 + σ²τ²), shifted downwind by
    // atan(στ) of phase.
    const Mode mode;
    OrographicRain r = upslope_only();
    r.condensation_time = 600.0;
    r.fallout_time = 1500.0;
    const auto wind = orogen::climate::wind_components(r);
    const double sigma = wind.east * mode.k() + wind.south * mode.l();
    const double gain = 1.0 / std::sqrt((1 + std::pow(sigma * 600.0, 2)) * (1 + std::pow(sigma * 1500.0, 2)));
    const double lag = std::atan(sigma * 600.0) + std::atan(sigma * 1500.0);
    const double amp = r.uplift_sensitivity * mode.amplitude * sigma * gain;
    const auto p = storm_part(mode, r);
    EXPECT_LT(worst(mode, p, amp, [&](int x, int y) { return amp * std::cos(mode.phase(x, y) + kPi / 2 - lag); }),
              1e-9);
    // The wettest cell sits downwind of the steepest windward slope (phase −π/2 there).
    EXPECT_GT(lag, 0.3);
}

TEST(OrographicRain, EvanescentLiftDecaysWithTheVapoursDepth) {
    // N_m = 0: every mode decays with height, m = i·|k|, and the rain is divided by 1 + H_w·|k|.
    const Mode mode;
    OrographicRain r = upslope_only();
    r.moist_stability = 0.0;
    r.vapour_scale_height = 3000.0;
    const double kk = std::hypot(mode.k(), mode.l());
    const auto wind = orogen::climate::wind_components(r);
    const double sigma = wind.east * mode.k() + wind.south * mode.l();
    const double amp = r.uplift_sensitivity * mode.amplitude * sigma / (1.0 + 3000.0 * kk);
    const auto p = storm_part(mode, r);
    EXPECT_LT(worst(mode, p, amp, [&](int x, int y) { return -amp * std::sin(mode.phase(x, y)); }), 1e-9);
}

TEST(OrographicRain, BuoyancyWavesTiltTheRainUpwind) {
    // σ² < N_m²: m = sgn(σ)·√((N_m² − σ²)/σ²·K²) is real and 1/(1 − i·H_w·m) shifts the rain upwind
    // by atan(H_w·m) with amplitude 1/√(1 + H_w²m²).
    Mode mode;
    mode.cycles_x = 1;
    mode.cycles_y = 0;
    mode.width = 128;
    mode.cell = 1000.0;
    OrographicRain r = upslope_only();
    r.wind_speed = 5.0;
    r.moist_stability = 0.01;
    r.vapour_scale_height = 2000.0;
    const double sigma = r.wind_speed * mode.k();
    ASSERT_LT(sigma, r.moist_stability);
    const double m = std::sqrt((0.01 * 0.01 - sigma * sigma) / (sigma * sigma) * mode.k() * mode.k());
    const double amp = r.uplift_sensitivity * mode.amplitude * sigma / std::sqrt(1 + std::pow(2000.0 * m, 2));
    const double lead = std::atan(2000.0 * m);
    const auto p = storm_part(mode, r);
    EXPECT_LT(worst(mode, p, amp, [&](int x, int y) { return amp * std::cos(mode.phase(x, y) + kPi / 2 + lead); }),
              1e-9);
}

/// A round hill of `peak` metres, `radius` metres across (Gaussian σ), centred on a size × size map.
std::vector<double> hill(int size, double cell, double peak, double radius) {
    std::vector<double> h(std::size_t(size) * size);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const double dx = (x - size / 2) * cell, dy = (y - size / 2) * cell;
            h[std::size_t(y) * size + x] = 200.0 + peak * std::exp(-(dx * dx + dy * dy) / (2 * radius * radius));
        }
    return h;
}

TEST(OrographicRain, AHillIsWetToWindwardAndDryInItsLee) {
    const int n = 160;
    const double cell = 500.0;
    const auto h = hill(n, cell, 1500.0, 8000.0);
    OrographicRain r;  // a westerly, blowing all year: the lee gets only what the wind brings
    r.wind_share = 1.0;
    const auto p = orogen::climate::orographic_rain(h.data(), n, n, cell, r, 64);
    const int c = n / 2;
    const auto at = [&](int x, int y) { return p[std::size_t(y) * n + x]; };
    // Along the hill's west–east line: wettest on the windward flank, driest in the lee.
    int wettest = 0, driest = 0;
    for (int x = 0; x < n; ++x) {
        if (at(x, c) > at(wettest, c)) wettest = x;
        if (at(x, c) < at(driest, c)) driest = x;
    }
    EXPECT_LT(wettest, c + 4) << "the wettest cell is on the upwind side of (or just past) the summit";
    EXPECT_GT(driest, c) << "the driest cell is in the lee";
    EXPECT_GT(at(wettest, c), 2.0 * r.background);
    EXPECT_LT(at(driest, c), 0.5 * r.background);
    EXPECT_GE(at(driest, c), 0.0);
    // Far upwind the rain is near the background (the buoyancy waves the hill makes lean a little
    // rain upwind; without them, N_m = 0, the rest is the evanescent lift's slow tail).
    const double rise = at(wettest, c) - r.background;
    EXPECT_LT(std::abs(at(2, c) - r.background), 0.1 * rise);
    OrographicRain still = r;
    still.moist_stability = 0.0;
    EXPECT_LT(std::abs(orogen::climate::orographic_rain(h.data(), n, n, cell, still, 64)[std::size_t(c) * n + 2] -
                       r.background),
              0.03 * rise);
    // An easterly gives the mirror image, to rounding.
    OrographicRain east = r;
    east.wind_from = 90.0;
    std::vector<double> mirrored(h.size());
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) mirrored[std::size_t(y) * n + x] = h[std::size_t(y) * n + (n - 1 - x)];
    const auto q = orogen::climate::orographic_rain(mirrored.data(), n, n, cell, east, 64);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
            ASSERT_NEAR(q[std::size_t(y) * n + (n - 1 - x)], p[std::size_t(y) * n + x], 1e-9 * r.background)
                << x << ", " << y;
    // Blowing a share f of the year, the rest of the year raining the background evenly: exactly
    // (1 − f)·P_0 + f·(the all-year field), so the lee keeps at least (1 − f)·P_0.
    OrographicRain some = r;
    some.wind_share = 0.3;
    const auto s = orogen::climate::orographic_rain(h.data(), n, n, cell, some, 64);
    for (std::size_t i = 0; i < s.size(); ++i) {
        ASSERT_NEAR(s[i], 0.7 * r.background + 0.3 * p[i], 1e-12 * r.background) << i;
        ASSERT_GE(s[i], 0.7 * r.background - 1e-12);
    }
}

TEST(OrographicRain, FlatGroundGetsTheBackgroundWhateverItsHeight) {
    // The padding falls to the map's lowest height: a plateau makes no cliff at its edges.
    std::vector<double> h(48 * 40, 2500.0);
    OrographicRain r;
    r.background = 1.7;
    for (int padding : {0, 8, 100}) {
        const auto p = orogen::climate::orographic_rain(h.data(), 48, 40, 30.0, r, padding);
        for (double v : p) ASSERT_NEAR(v, 1.7, 1e-12) << "padding " << padding;
    }
}

TEST(OrographicRain, ACoarseGridGivesNearlyTheFineField) {
    const int n = 250;
    const double cell = 100.0;
    const auto h = hill(n, cell, 1200.0, 4000.0);
    OrographicRain r;
    r.wind_from = 250.0;
    const auto fine = orogen::climate::orographic_rain_coarse(h.data(), n, n, cell, r, cell);
    const auto same = orogen::climate::orographic_rain_coarse(h.data(), n, n, cell, r, cell * 1.5);  // still 1:1
    ASSERT_EQ(fine, same);
    const auto coarse = orogen::climate::orographic_rain_coarse(h.data(), n, n, cell, r, 500.0);  // 5 cells a block
    double peak = 0.0, err = 0.0;
    for (std::size_t i = 0; i < fine.size(); ++i) {
        peak = std::max(peak, fine[i]);
        err = std::max(err, std::abs(fine[i] - coarse[i]));
    }
    EXPECT_GT(peak, 2.0 * r.background);
    EXPECT_LT(err, 0.05 * peak) << "peak " << peak;
}

TEST(OrographicRain, TheSameBitsOnOneAndTwoThreads) {
    const auto h = hill(300, 90.0, 2000.0, 5000.0);
    std::vector<double> runs[2];
    for (int threads : {1, 2}) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
        runs[threads - 1] = orogen::climate::orographic_rain_coarse(h.data(), 300, 300, 90.0, OrographicRain{}, 250.0);
    }
    EXPECT_EQ(runs[0], runs[1]);
}

TEST(OrographicRain, AKeptTransferGivesTheSameBitsAndFollowsItsSettings) {
    // A RainTransfer kept across calls: the same bits as none, for other heights, another wind, another
    // grid (each made afresh when it does not fit), and back again.
    const auto a = hill(300, 90.0, 2000.0, 5000.0), b = hill(300, 90.0, 1200.0, 3000.0);
    const auto c = hill(200, 90.0, 1500.0, 4000.0);
    OrographicRain west, north;
    north.wind_from = 0.0;
    orogen::climate::RainTransfer kept;
    struct Call {
        const std::vector<double>* h;
        int side;
        const OrographicRain* rain;
    };
    for (const Call& call : {Call{&a, 300, &west}, Call{&b, 300, &west}, Call{&b, 300, &north}, Call{&c, 200, &north},
                             Call{&a, 300, &west}}) {
        std::vector<double> with, without;
        orogen::climate::orographic_rain_coarse(call.h->data(), call.side, call.side, 90.0, *call.rain, 250.0, with,
                                                &kept);
        orogen::climate::orographic_rain_coarse(call.h->data(), call.side, call.side, 90.0, *call.rain, 250.0, without);
        ASSERT_EQ(with, without) << call.side << " " << call.rain->wind_from;
        EXPECT_EQ(kept.rain, *call.rain);
    }
}

TEST(OrographicRain, TilesAddingTheirBlocksGetTheWholeGridsBits) {
    // A 101 x 77 grid in blocks of 4 cells, cut into three windows whose edges cross blocks; their sums
    // added in two orders, each window's rain interpolated on its own: the whole grid's, bit for bit.
    const int w = 101, h = 77;
    const double cell = 90.0;
    std::vector<double> z(std::size_t(w) * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            z[std::size_t(y) * w + x] =
                1500.0 * std::exp(-((x - 50.0) * (x - 50.0) + (y - 30.0) * (y - 30.0)) / 300.0) + 0.1234567 * x -
                0.0087 * y * y;
    OrographicRain r;
    r.wind_from = 300.0;
    const auto whole = orogen::climate::orographic_rain_coarse(z.data(), w, h, cell, r, 360.0);
    const auto g = orogen::climate::coarse_rain_grid(w, h, cell, r, 360.0);
    ASSERT_EQ(g.factor, 4);
    struct Win {
        int x0, y0, w, h;
    };
    const Win wins[] = {{0, 0, 47, 77}, {47, 0, 54, 30}, {47, 30, 54, 47}};
    auto cut = [&](const Win& v) {
        std::vector<double> out(std::size_t(v.w) * v.h);
        for (int y = 0; y < v.h; ++y)
            for (int x = 0; x < v.w; ++x) out[std::size_t(y) * v.w + x] = z[std::size_t(v.y0 + y) * w + v.x0 + x];
        return out;
    };
    for (const int order : {0, 1}) {
        std::vector<double> sums(std::size_t(g.coarse_width) * g.coarse_height, 0.0);
        for (int k = 0; k < 3; ++k) {
            const Win& v = wins[order ? 2 - k : k];
            const auto part = cut(v);
            orogen::climate::add_block_sums(g, part.data(), v.x0, v.y0, v.w, v.h, sums);
        }
        const auto coarse = orogen::climate::coarse_rain(g, r, sums);
        for (const Win& v : wins) {
            std::vector<double> mine;
            orogen::climate::interpolate_rain(g, coarse, v.x0, v.y0, v.w, v.h, mine);
            for (int y = 0; y < v.h; ++y)
                for (int x = 0; x < v.w; ++x)
                    ASSERT_EQ(mine[std::size_t(y) * v.w + x], whole[std::size_t(v.y0 + y) * w + v.x0 + x])
                        << "order " << order << " at " << v.x0 + x << ", " << v.y0 + y;
        }
    }
    // A non-finite height names its block.
    z[std::size_t(40) * w + 9] = std::nan("");
    std::vector<double> sums(std::size_t(g.coarse_width) * g.coarse_height, 0.0);
    orogen::climate::add_block_sums(g, z.data(), 0, 0, w, h, sums);
    try {
        orogen::climate::coarse_rain(g, r, sums);
        FAIL() << "a NaN height was taken";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("block (2, 10)"), std::string::npos) << e.what();
    }
}

TEST(OrographicRain, BadInputIsRefusedSayingWhat) {
    std::vector<double> h(16 * 16, 100.0);
    OrographicRain r;
    h[37] = std::nan("");
    try {
        orogen::climate::orographic_rain(h.data(), 16, 16, 30.0, r, 4);
        FAIL() << "a NaN height was taken";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("height 37"), std::string::npos) << e.what();
    }
    try {  // on the coarse grid too (4 cells a block): the height's own index, not its block's
        orogen::climate::orographic_rain_coarse(h.data(), 16, 16, 30.0, r, 120.0);
        FAIL() << "a NaN height was taken on the coarse grid";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("height 37"), std::string::npos) << e.what();
    }
    h[37] = 100.0;
    r.wind_share = 0.0;
    EXPECT_THROW(orogen::climate::orographic_rain(h.data(), 16, 16, 30.0, r, 4), std::invalid_argument);
    r = {};
    EXPECT_THROW(orogen::climate::orographic_rain(h.data(), 16, 16, 0.0, r, 4), std::invalid_argument);
    EXPECT_THROW(orogen::climate::orographic_rain_coarse(h.data(), 16, 16, 30.0, r, -1.0), std::invalid_argument);
    r.wind_speed = -3.0;
    EXPECT_THROW(orogen::climate::orographic_rain(h.data(), 16, 16, 30.0, r, 4), std::invalid_argument);
}

}  // namespace
