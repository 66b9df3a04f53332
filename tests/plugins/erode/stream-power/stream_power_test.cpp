// Tests of the stream-power landscape model's core: the analytical steady
// state, a 1-D river against the implicit scheme and against the travelling
// knickpoint of the kinematic wave, depression handling (every cell drains to
// an outlet, no loops, the outlet's area is the map's), and determinism.
#include <orogen/landscape/basin_join.hpp>
#include "noise_terrain.hpp"
#include <orogen/landscape/stream_power.hpp>

#include <orogen/random.hpp>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <numeric>
#include <set>
#include <vector>

namespace {

using namespace orogen;
using namespace orogen::landscape;

using test::noise;

/// Least-squares slope and intercept of y on x.
std::pair<double, double> fit(const std::vector<double>& x, const std::vector<double>& y) {
    const double n = double(x.size());
    const double mx = std::accumulate(x.begin(), x.end(), 0.0) / n, my = std::accumulate(y.begin(), y.end(), 0.0) / n;
    double sxy = 0.0, sxx = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) sxy += (x[i] - mx) * (y[i] - my), sxx += (x[i] - mx) * (x[i] - mx);
    return {sxy / sxx, my - sxy / sxx * mx};
}

struct SteadyCase {
    double n;
    double k;
};

class SteadyState : public ::testing::TestWithParam<SteadyCase> {};

TEST_P(SteadyState, ChannelsObeyTheAnalyticalSlopeAreaRelation) {
    // Uniform U and K, no diffusion: at steady state every channel has
    // S = (U/K)^(1/n) A^(−m/n). The model starts from noise and runs 60 Myr (drainage divides settle slowly for n < 1).
    const int w = 81, h = 61;
    const double cell = 50.0, U = 1e-3;
    Settings s;
    s.erodibility = GetParam().k;
    s.area_exponent = 0.5 * GetParam().n;  // m/n = 0.5
    s.slope_exponent = GetParam().n;
    s.diffusivity = 0.0;
    s.open = {true, false, true, false};  // rivers run north and south
    Model model(w, h, cell, noise(w, h, 1, 10.0), std::vector<double>(std::size_t(w) * h, U), s);
    model.run(6e7, 2e5);
    // Slopes of the final heights to the last step's receivers (the heights no longer change).
    const auto& f = model.flow();
    const auto& hh = model.heights();
    std::vector<double> la, ls;
    int channels = 0;
    double worst = 0.0;
    for (std::size_t i = 0; i < hh.size(); ++i) {
        const double a = f.area()[i];
        const std::int32_t r = f.receivers()[i];
        if (r == std::int32_t(i) || a < 10 * cell * cell) continue;
        const double slope = (hh[i] - hh[std::size_t(r)]) / f.distance(std::int64_t(i));
        const double expected =
            std::pow(U / s.erodibility, 1.0 / s.slope_exponent) * std::pow(a, -s.area_exponent / s.slope_exponent);
        worst = std::max(worst, std::abs(slope / expected - 1.0));
        la.push_back(std::log(a));
        ls.push_back(std::log(slope));
        ++channels;
    }
    ASSERT_GT(channels, 200);
    EXPECT_LT(worst, 0.02) << "largest relative deviation from S = (U/K)^(1/n) A^(-m/n)";
    const auto [slope, intercept] = fit(la, ls);
    EXPECT_NEAR(-slope, 0.5, 0.01) << "concavity m/n from the slope-area fit";
    EXPECT_NEAR(std::exp(intercept), std::pow(U / s.erodibility, 1.0 / s.slope_exponent),
                0.02 * std::pow(U / s.erodibility, 1.0 / s.slope_exponent));
}

INSTANTIATE_TEST_SUITE_P(StreamPower, SteadyState,
                         ::testing::Values(SteadyCase{1.0, 1e-5}, SteadyCase{2.0, 1e-7}, SteadyCase{0.7, 3e-5}),
                         [](const auto& info) { return "n" + std::to_string(int(info.param.n * 10)); });

TEST(StreamPower, AChannelAreaScalesIncisionByOneMinusExpOfAreaOverIt) {
    // Settings::channel_area A_c: at steady state U = K·A^m·(1 − e^(−A/A_c))·S, so
    // S = (U/K)·(A^m·(1 − e^(−A/A_c)))^(−1): channels near their heads (A ~ A_c) are steeper than the
    // plain law's, large rivers (A ≫ A_c) obey it. No creep, so nothing else sets the slopes.
    const int w = 81, h = 61;
    const double cell = 50.0, U = 1e-3;
    Settings s;
    s.erodibility = 1e-5;
    s.area_exponent = 0.5;
    s.diffusivity = 0.0;
    s.channel_area = 20 * cell * cell;
    s.open = {true, false, true, false};
    Model model(w, h, cell, noise(w, h, 1, 10.0), std::vector<double>(std::size_t(w) * h, U), s);
    model.run(6e7, 2e5);
    const auto& f = model.flow();
    const auto& hh = model.heights();
    double worst = 0.0, steepest_ratio = 0.0;
    int cells = 0;
    for (std::size_t i = 0; i < hh.size(); ++i) {
        const double a = f.area()[i];
        const std::int32_t r = f.receivers()[i];
        if (r == std::int32_t(i) || a < 2 * cell * cell) continue;
        const double slope = (hh[i] - hh[std::size_t(r)]) / f.distance(std::int64_t(i));
        const double plain = U / s.erodibility * std::pow(a, -s.area_exponent);
        const double expected = plain / (1.0 - std::exp(-a / s.channel_area));
        worst = std::max(worst, std::abs(slope / expected - 1.0));
        steepest_ratio = std::max(steepest_ratio, slope / plain);
        ++cells;
    }
    ASSERT_GT(cells, 500);
    EXPECT_LT(worst, 0.02) << "largest relative deviation from S = (U/K)(A^m (1 - exp(-A/A_c)))^-1";
    EXPECT_GT(steepest_ratio, 5.0) << "small catchments must be steeper than the plain law's";
}

TEST(StreamPower, SubStepsBringACoarseStepToTheFineStepsTerrain) {
    // Creep for a whole coarse step works on the slots the last incision left; with Settings::substeps
    // the step's routing serves sub-steps of uplift, creep and incision, and the terrain of dt = 3e4 in
    // 6 sub-steps must lie much nearer that of dt = 5e3 than dt = 3e4 alone does. One sub-step is the
    // plain step, bit for bit.
    const int w = 96, h = 96;
    const double cell = 30.0, U = 1e-3;
    Settings s;
    s.erodibility = 1e-6;
    s.area_exponent = 0.7;
    s.diffusivity = 0.6;
    s.channel_area = 3e4;
    auto run = [&](double dt, int substeps) {
        Settings t = s;
        t.substeps = substeps;
        Model model(w, h, cell, noise(w, h, 3, 20.0), std::vector<double>(std::size_t(w) * h, U), t);
        model.run(6e5, dt);
        return model.heights();
    };
    auto rms = [](const std::vector<double>& a, const std::vector<double>& b) {
        double sum = 0.0;
        for (std::size_t i = 0; i < a.size(); ++i) sum += (a[i] - b[i]) * (a[i] - b[i]);
        return std::sqrt(sum / double(a.size()));
    };
    const auto fine = run(5e3, 1), coarse = run(3e4, 1), substepped = run(3e4, 6);
    const double coarse_error = rms(coarse, fine), substepped_error = rms(substepped, fine);
    EXPECT_GT(coarse_error, 1.0) << "m: the coarse step must differ from the fine one for this test to mean anything";
    RecordProperty("coarse_rms_m", std::to_string(coarse_error));
    RecordProperty("substepped_rms_m", std::to_string(substepped_error));
    EXPECT_LT(substepped_error, 0.35 * coarse_error)
        << "coarse " << coarse_error << " m, sub-stepped " << substepped_error << " m (RMS from dt = 5e3)";
    {
        Settings t = s;
        Model plain(w, h, cell, noise(w, h, 3, 20.0), std::vector<double>(std::size_t(w) * h, U), t);
        plain.run(6e5, 3e4);
        EXPECT_EQ(plain.heights(), coarse) << "substeps = 1 is the plain step";
    }
}

TEST(Landslides, AfterEveryStepNoHillslopeStandsSteeperThanItsThreshold) {
    // Fast uplift and no creep would steepen the hillslopes without end; landslides hold every vertex at
    // most S_c·d above each neighbour (D8 distances), and the rivers still reach steady state below it.
    const int w = 71, h = 53;
    const double cell = 30.0, U = 2e-3;
    Settings s;
    s.erodibility = 2e-5;
    s.area_exponent = 0.5;
    s.diffusivity = 0.0;
    s.channel_area = 3e4;
    s.rock.angle = 32.0 * M_PI / 180.0;
    Model model(w, h, cell, noise(w, h, 4, 10.0), std::vector<double>(std::size_t(w) * h, U), s);
    Settings plain = s;
    plain.rock.angle = 0.0;
    Model unlimited(w, h, cell, noise(w, h, 4, 10.0), std::vector<double>(std::size_t(w) * h, U), plain);
    model.run(2e6, 2e4);
    unlimited.run(2e6, 2e4);
    const double sc = std::tan(s.rock.angle);
    auto steepest = [&](const std::vector<double>& z) {
        double worst = 0.0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        const int nx = x + dx, ny = y + dy;
                        if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
                        const double d = cell * std::hypot(double(dx), double(dy));
                        worst = std::max(worst, (z[std::size_t(y) * w + x] - z[std::size_t(ny) * w + nx]) / d);
                    }
        return worst;
    };
    EXPECT_LE(steepest(model.heights()), sc * (1.0 + 1e-12));
    EXPECT_GT(steepest(unlimited.heights()), 1.5 * sc) << "without landslides the same run must be far steeper";
    EXPECT_EQ(model.first_non_finite(), -1);
}

TEST(Beds, ABedDipsTowardsItsAzimuthAndKeepsItsStrength) {
    Beds beds;
    beds.thickness = 40.0;
    beds.dip_slope = std::tan(30.0 * M_PI / 180.0);
    beds.dip_east = std::sin(120.0 * M_PI / 180.0);  // dipping towards azimuth 120° (east-south-east)
    beds.dip_south = -std::cos(120.0 * M_PI / 180.0);
    beds.seed = 9;
    int differ = 0;
    for (int k = 0; k < 200; ++k) {
        const double z = -500.0 + 7.3 * k, x = 13.0 * k, y = 5000.0 - 11.0 * k, along = 250.0;
        // The same bed lies tan(dip)·along lower, `along` metres towards the dip.
        EXPECT_EQ(beds.strength(z, x, y),
                  beds.strength(z - beds.dip_slope * along, x + along * beds.dip_east, y + along * beds.dip_south));
        const double s = beds.strength(z, x, y);
        EXPECT_GE(s, 0.0);
        EXPECT_LT(s, 1.0);
        differ += beds.strength(z, x, y) != beds.strength(z + beds.thickness, x, y);  // the next bed up
    }
    EXPECT_GT(differ, 190) << "beds a thickness apart must (almost always) differ in strength";
    beds.erodibility_contrast = 9.0;
    EXPECT_DOUBLE_EQ(beds.erodibility_factor(0.0), 3.0);  // the weakest: √contrast times the average K
    EXPECT_DOUBLE_EQ(beds.erodibility_factor(1.0), 1.0 / 3.0);
    beds.angle = 35.0 * M_PI / 180.0;
    beds.angle_spread = 10.0 * M_PI / 180.0;
    EXPECT_NEAR(beds.landslide_slope(0.0), std::tan(25.0 * M_PI / 180.0), 1e-12);
    EXPECT_NEAR(beds.landslide_slope(1.0), std::tan(45.0 * M_PI / 180.0), 1e-12);
}

TEST(Beds, FoldsBendTheOutcropsWithinTheirAmplitudeAndRunAlongTheStrike) {
    // Beds dipping 20° towards 30°, folded by up to 400 m in folds 4 km across. On a level surface a planar
    // bed crops out along the strike as a straight band; a folded one bends in and out of it.
    Beds beds;
    beds.thickness = 100.0;
    beds.dip_slope = std::tan(20.0 * M_PI / 180.0);
    beds.dip_east = std::sin(30.0 * M_PI / 180.0);
    beds.dip_south = -std::cos(30.0 * M_PI / 180.0);
    beds.seed = 5;
    const double strike_e = -beds.dip_south, strike_s = beds.dip_east;  // along the strike
    auto classes_along_strike = [&] {
        std::set<int> seen;
        for (int k = 0; k < 400; ++k)
            seen.insert(beds.bed_class(300.0, 15000.0 + 50.0 * k * strike_e, 15000.0 + 50.0 * k * strike_s));
        return seen.size();
    };
    EXPECT_EQ(classes_along_strike(), 1u) << "a planar bed's outcrop runs straight along the strike";
    EXPECT_EQ(beds.fold(1234.0, 5678.0), 0.0);

    beds.fold_amplitude = 400.0;
    beds.fold_wavelength = 4000.0;
    EXPECT_GE(classes_along_strike(), 4u) << "folds carry the outcrop across several beds along the strike";
    double sum2 = 0.0, step_across = 0.0, step_along = 0.0, biggest_cell_step = 0.0;
    const int n = 4000;
    for (int k = 0; k < n; ++k) {
        const double x = 37.0 * k, y = 60000.0 - 23.0 * k - 9.0 * (k % 17) * 100.0;
        const double f = beds.fold(x, y);
        ASSERT_LE(std::abs(f), beds.fold_amplitude) << "at " << x << ", " << y;
        sum2 += f * f;
        // The folds' axes run along the strike: the surfaces change faster across them (along the dip).
        const double d = 1000.0;
        step_across += std::abs(beds.fold(x + d * beds.dip_east, y + d * beds.dip_south) - f);
        step_along += std::abs(beds.fold(x + d * strike_e, y + d * strike_s) - f);
        // Smooth: one 30 m cell moves a surface by a small part of the amplitude.
        biggest_cell_step = std::max(biggest_cell_step, std::abs(beds.fold(x + 30.0, y) - f));
    }
    const double rms = std::sqrt(sum2 / n);
    EXPECT_GT(rms, 0.15 * beds.fold_amplitude) << "the folds must have some height";
    EXPECT_GT(step_across, 1.8 * step_along) << "folds three times as long as they are wide";
    EXPECT_LT(biggest_cell_step, 0.05 * beds.fold_amplitude);
    // The beds still dip, with the folds' lift added: the same bed lies tan(dip)·along lower `along` metres
    // towards the dip, and as much higher as the folds lift it more there.
    for (int k = 0; k < 200; ++k) {
        const double z = -500.0 + 7.3 * k, x = 13.0 * k, y = 5000.0 - 11.0 * k, along = 250.0;
        const double x2 = x + along * beds.dip_east, y2 = y + along * beds.dip_south;
        EXPECT_EQ(beds.bed_class(z, x, y),
                  beds.bed_class(z - beds.dip_slope * along + (beds.fold(x2, y2) - beds.fold(x, y)), x2, y2));
    }
}

TEST(Beds, UnevenBedsRunFromOneMinusToOnePlusTheSpreadTimesTheThickness) {
    Beds beds;
    beds.thickness = 100.0;
    beds.seed = 7;
    for (int k = -3000; k < 3000; ++k) {
        const double q = 3.7 * k;
        ASSERT_EQ(beds.bed_at(q), std::int64_t(std::floor(q / beds.thickness))) << "even beds at " << q;
    }
    beds.thickness_spread = 0.8;
    // Walk up through 100 km of beds, half a metre at a time: each bed follows the one below, and its
    // thickness is within (1 ± spread)·thickness; thin and thick ones both occur, averaging the thickness.
    const double step = 0.5;
    std::int64_t bed = beds.bed_at(-50000.0);
    double base = -50000.0, thinnest = 1e9, thickest = 0.0, total = 0.0;
    int beds_seen = 0;
    for (double q = -50000.0 + step; q < 50000.0; q += step) {
        const std::int64_t next = beds.bed_at(q);
        if (next == bed) continue;
        ASSERT_EQ(next, bed + 1) << "at " << q;
        if (beds_seen++ > 0) {
            thinnest = std::min(thinnest, q - base), thickest = std::max(thickest, q - base);
            total += q - base;
        }
        bed = next, base = q;
    }
    EXPECT_GE(thinnest, 20.0 - step);
    EXPECT_LE(thickest, 180.0 + step);
    EXPECT_LT(thinnest, 40.0) << "the spread must show";
    EXPECT_GT(thickest, 160.0);
    EXPECT_NEAR(total / (beds_seen - 1), beds.thickness, 5.0);
}

TEST(Beds, FaultsStepTheBedsAcrossTheirTracesAndDieAwayFromThem) {
    Beds beds;
    beds.thickness = 100.0;
    beds.seed = 11;
    beds.fold_amplitude = 300.0;
    EXPECT_EQ(beds.fault(1234.0, 5678.0), 0.0);
    beds.fault_spacing = 3000.0;
    beds.fault_throw = 300.0;
    // Along a 60 km line, a metre at a time: the lift changes smoothly (one fault's steepest slope is 0.77
    // throw per half-length, 0.15 m per m here) but for steps at the faults' traces, each at most the throw.
    int steps = 0;
    double biggest_step = 0.0, biggest_lift = 0.0;
    double before = beds.fault(0.0, 12345.0);
    for (double x = 1.0; x < 60000.0; x += 1.0) {
        const double lift = beds.fault(x, 12345.0 + 0.2 * x);
        const double change = std::abs(lift - before);
        if (change > 0.35) ++steps, biggest_step = std::max(biggest_step, change);
        biggest_lift = std::max(biggest_lift, std::abs(lift));
        before = lift;
    }
    // ~0.4 traces cross a line per km at one 1.5–4.5 km fault per 9 km².
    EXPECT_GE(steps, 8);
    EXPECT_LE(steps, 60);
    EXPECT_LE(biggest_step, beds.fault_throw);
    EXPECT_GT(biggest_step, 0.3 * beds.fault_throw);
    EXPECT_GT(biggest_lift, 0.1 * beds.fault_throw);
    // A block's offsets, drawn from a table of faults once, are Beds::offset's to the bit, on any block.
    beds.dip_slope = 0.3;
    beds.thickness_spread = 0.5;
    for (const auto [x0, y0] : {std::pair{0, 0}, std::pair{37, 101}, std::pair{-250, 400}}) {
        const int width = 150, height = 90;
        const double cell = 30.0;
        std::vector<double> offsets;
        bed_offsets(beds, {std::size_t(width * height), width, x0, y0, cell}, offsets);
        for (int i = 0; i < width * height; ++i)
            ASSERT_EQ(offsets[std::size_t(i)], beds.offset((x0 + i % width) * cell, (y0 + i / width) * cell))
                << "cell " << i << " of the block at " << x0 << ", " << y0;
    }
}

TEST(Beds, FaciesDriftABedsStrengthAlongItSmoothlyAndByTheirShare) {
    // Flat-lying beds 100 m thick: walking east through one bed (rock height 50 m), its strength is one
    // class without facies; with them it drifts over the facies length, a few classes per 30 m cell at
    // most, and by no more than its share of the whole range.
    Beds beds;
    beds.thickness = 100.0;
    beds.seed = 6;
    const double own = beds.strength(50.0, 0.0, 0.0);
    auto walk = [&](auto&& each) {
        for (int c = 0; c < 1000; ++c) each(30.0 * c, beds.bed_class(50.0, 30.0 * c, 4321.0));
    };
    std::set<int> seen;
    walk([&](double, int k) { seen.insert(k); });
    EXPECT_EQ(seen.size(), 1u) << "without facies a bed is one strength along its whole outcrop";

    beds.facies_length = 2000.0;
    beds.facies_share = 1.0;
    seen.clear();
    int previous = -1, largest_step = 0;
    walk([&](double, int k) {
        ASSERT_GE(k, 0);
        ASSERT_LT(k, Beds::kStrengths);
        if (previous >= 0) largest_step = std::max(largest_step, std::abs(k - previous));
        previous = k;
        seen.insert(k);
    });
    EXPECT_GT(seen.size(), 40u) << "over 30 km (15 facies lengths) the bed's strength must range widely";
    // Smooth: a 30 m step (1/67 of a lattice cell) moves the class by a few at most; an edge would jump by
    // up to the whole range.
    EXPECT_LE(largest_step, 12) << "a facies changes smoothly, without edges";

    // The facies move strength along a bed; they do not make the rock stronger or weaker on the whole: over
    // many beds and places the classes stay evenly spread, for any share (a plain blend of the lattice
    // draws would crowd them to the middle, half as many in the outer eighths). A small share keeps a bed
    // near its own strength.
    double drift_small = 0.0, drift_full = 0.0;
    for (const double share : {0.25, 0.6, 1.0}) {
        beds.facies_share = share;
        int bins[8] = {};
        double drift = 0.0;
        // 3000 beds, each at 10 places 2.5 lattice cells apart (nearly independent draws).
        for (int bed = 0; bed < 3000; ++bed)
            for (int p = 0; p < 10; ++p) {
                const double z = 100.0 * bed + 50.0, x = 5000.0 * p + 11.0 * (bed % 100), y = 3000.0 + 7.0 * bed;
                const int k = beds.bed_class(z, x, y);
                ASSERT_GE(k, 0);
                ASSERT_LT(k, Beds::kStrengths);
                ++bins[k * 8 / Beds::kStrengths];
                beds.facies_length = 0.0;
                drift += std::abs(k - beds.bed_class(z, x, y));
                beds.facies_length = 2000.0;
            }
        for (int b = 0; b < 8; ++b)
            EXPECT_NEAR(bins[b], 30000 / 8, 30000 / 8 * 0.1) << "share " << share << ", eighth " << b;
        if (share == 0.25) drift_small = drift;
        if (share == 1.0) drift_full = drift;
    }
    EXPECT_LT(drift_small, 0.4 * drift_full);
    // Two beds drift apart, not together: the drift is drawn for each bed.
    int differ = 0;
    for (int c = 0; c < 1000; ++c) {
        const double x = 30.0 * c;
        const double a = beds.strength(50.0, x, 0.0) - beds.strength(50.0, 0.0, 0.0);
        const double b = beds.strength(150.0, x, 0.0) - beds.strength(150.0, 0.0, 0.0);
        differ += std::abs(a - b) > 2.0 / Beds::kStrengths;
    }
    EXPECT_GT(differ, 500);
}

TEST(Beds, EachCellTakesItsOwnBedsSlopeAndErodibility) {
    // rock_at draws the beds of a step into a table; every cell must get what bed_class says of it, at any
    // height, for even and uneven beds, and a height that is not finite must not reach past the table.
    Beds beds;
    beds.thickness = 40.0;
    beds.dip_slope = 0.2;
    beds.angle = 0.6;
    beds.angle_spread = 0.3;
    beds.erodibility_contrast = 4.0;
    beds.seed = 3;
    const int width = 64, height = 48;
    const std::size_t n = std::size_t(width * height);
    std::vector<double> heights(n), uplifted(n), offsets, slopes, factors;
    for (std::size_t i = 0; i < n; ++i) {
        heights[i] = 1500.0 * std::sin(0.37 * double(i)) + 0.5 * double(i);
        uplifted[i] = 100.0 + 0.01 * double(i);
    }
    heights[17] = std::numeric_limits<double>::quiet_NaN();
    // The last: beds 4 m thick with facies 100 m across would make a table of 250,000 corners for 3,072
    // cells; each cell draws its own instead.
    struct Case {
        double thickness, spread, facies;
    };
    for (const auto [thickness, spread, facies] :
         {Case{40.0, 0.0, 0.0}, Case{40.0, 0.9, 0.0}, Case{40.0, 0.9, 700.0}, Case{4.0, 0.5, 100.0}}) {
        beds.thickness = thickness;
        beds.thickness_spread = spread;
        beds.facies_length = facies;  // lattice cells of 700 m: a block of 64 × 48 cells of 30 m spans several
        beds.facies_share = 0.6;
        bed_offsets(beds, {n, width, 5, 9, 30.0}, offsets);
        rock_at(beds, {n, width, 5, 9, 30.0}, {heights.data(), uplifted.data(), offsets.data()}, slopes, factors);
        ASSERT_EQ(slopes.size(), n);
        ASSERT_EQ(factors.size(), n);
        for (std::size_t i = 0; i < n; ++i) {
            if (i == 17) continue;
            const double x = (5 + int(i) % width) * 30.0, y = (9 + int(i) / width) * 30.0;
            const double s = beds.strength(heights[i] - uplifted[i], x, y);
            ASSERT_EQ(slopes[i], beds.landslide_slope(s)) << "cell " << i << ", spread " << spread << ", " << facies;
            ASSERT_EQ(factors[i], beds.erodibility_factor(s))
                << "cell " << i << ", spread " << spread << ", " << facies;
        }
    }
}

TEST(Beds, JointBlocksStandUpToTheSpreadSteeperThanTheirBedAndTileAlike) {
    // One rock (no beds) and bedded rock: each cell's landslide slope is its bed's times 1 + spread·u, u in
    // [0, 1) from the cell's place in the whole grid and its cell-deep slice of rock; the same for a cell
    // whichever block of the grid (tile) it is computed in.
    for (const double thickness : {0.0, 40.0}) {
        Beds beds;
        beds.thickness = thickness;
        beds.angle = 0.6;
        beds.angle_spread = thickness > 0.0 ? 0.2 : 0.0;
        beds.block_spread = 0.5;
        beds.seed = 4;
        const int width = 80, height = 60;
        const std::size_t n = std::size_t(width * height);
        std::vector<double> heights(n), uplifted(n, 0.0), offsets, slopes, factors;
        for (std::size_t i = 0; i < n; ++i) heights[i] = 900.0 * std::cos(0.011 * double(i)) + 0.3 * double(i);
        bed_offsets(beds, {n, width, 0, 0, 30.0}, offsets);
        rock_at(beds, {n, width, 0, 0, 30.0}, {heights.data(), uplifted.data(), offsets.data()}, slopes, factors);
        ASSERT_EQ(slopes.size(), n) << "joint blocks vary the slope even in one rock";
        double lowest_share = 1.0, highest_share = 0.0, sum = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            const double x = double(int(i) % width) * 30.0, y = double(int(i) / width) * 30.0;
            const double bed = beds.landslide_slope(beds.strength(heights[i], x, y));
            const double share = slopes[i] / bed - 1.0;
            ASSERT_GE(share, -1e-12) << "cell " << i << ": no block is weaker than its bed";
            ASSERT_LT(share, beds.block_spread + 1e-12) << "cell " << i;
            lowest_share = std::min(lowest_share, share), highest_share = std::max(highest_share, share);
            sum += share;
        }
        EXPECT_LT(lowest_share, 0.02);
        EXPECT_GT(highest_share, 0.48);
        EXPECT_NEAR(sum / double(n), 0.25, 0.02) << "u uniform in [0, 1)";
        // The right half of the grid as its own block (a tile) gives its cells the same slopes.
        const int half = width / 2;
        std::vector<double> h2, u2, o2, s2, f2;
        for (int y = 0; y < height; ++y)
            for (int x = half; x < width; ++x) h2.push_back(heights[std::size_t(y * width + x)]), u2.push_back(0.0);
        bed_offsets(beds, {h2.size(), width - half, half, 0, 30.0}, o2);
        rock_at(beds, {h2.size(), width - half, half, 0, 30.0}, {h2.data(), u2.data(), o2.data()}, s2, f2);
        for (int y = 0; y < height; ++y)
            for (int x = half; x < width; ++x)
                ASSERT_EQ(s2[std::size_t(y * (width - half) + x - half)], slopes[std::size_t(y * width + x)])
                    << "cell " << x << ", " << y;
    }
}

TEST(Beds, ARememberedRockIsTheRockDrawnAfresh) {
    // With a RockMemo a cell still in last call's bed and block slice keeps its slope and factor; every
    // call must give what a call without one gives, as the heights fall through beds and slices at
    // different rates (some by a bed a call, some by less than a slice), for even and uneven beds, facies
    // with and without their table of corners, a height that turns NaN and back, and a memo handed empty
    // arrays.
    struct Case {
        double thickness, spread, facies;
    };
    for (const auto [thickness, spread, facies] : {Case{40.0, 0.0, 0.0}, Case{40.0, 0.9, 0.0}, Case{40.0, 0.9, 700.0},
                                                   Case{4.0, 0.5, 100.0}, Case{0.0, 0.0, 0.0}}) {
        Beds beds;
        beds.thickness = thickness;
        beds.thickness_spread = spread;
        beds.facies_length = facies;
        beds.facies_share = 0.6;
        beds.dip_slope = 0.2;
        beds.angle = 0.6;
        beds.angle_spread = thickness > 0.0 ? 0.3 : 0.0;
        beds.erodibility_contrast = 4.0;
        beds.block_spread = 0.5;
        beds.seed = 11;
        const int width = 50, height = 40;
        const std::size_t n = std::size_t(width * height);
        std::vector<double> heights(n), uplifted(n), offsets, slopes, factors, fresh_slopes, fresh_factors;
        for (std::size_t i = 0; i < n; ++i) {
            heights[i] = 1200.0 * std::sin(0.21 * double(i)) + 0.7 * double(i);
            uplifted[i] = 50.0 + 0.02 * double(i);
        }
        bed_offsets(beds, {n, width, 3, 7, 30.0}, offsets);
        RockMemo memo;
        for (int call = 0; call < 12; ++call) {
            for (std::size_t i = 0; i < n; ++i) heights[i] -= double(i % 7) * (i % 3 == 0 ? 9.0 : 0.4);
            heights[29] = call == 4 ? std::numeric_limits<double>::quiet_NaN() : 100.0 - call;
            if (call == 8) slopes.clear(), factors.clear();  // arrays the memo did not fill: drawn afresh
            rock_at(beds, {n, width, 3, 7, 30.0}, {heights.data(), uplifted.data(), offsets.data()}, slopes, factors,
                    &memo);
            rock_at(beds, {n, width, 3, 7, 30.0}, {heights.data(), uplifted.data(), offsets.data()}, fresh_slopes,
                    fresh_factors);
            ASSERT_EQ(slopes.size(), fresh_slopes.size());
            ASSERT_EQ(factors.size(), fresh_factors.size());
            for (std::size_t i = 0; i < n; ++i) {
                if (i == 29 && call == 4) continue;
                ASSERT_EQ(slopes[i], fresh_slopes[i]) << "call " << call << ", cell " << i << ", " << thickness;
                if (!factors.empty())
                    ASSERT_EQ(factors[i], fresh_factors[i]) << "call " << call << ", cell " << i << ", " << thickness;
            }
        }
    }
}

TEST(Beds, StrongBedsStandSteeperThanWeakOnes) {
    // Flat-lying beds 60 m thick under a rising block: after the run, hillslopes in strong rock are steeper
    // than in weak rock (their landslide angle is higher, their rivers slower).
    const int w = 81, h = 61;
    const double cell = 30.0, U = 1e-3;
    Settings s;
    s.erodibility = 1e-5;
    s.area_exponent = 0.5;
    s.diffusivity = 0.01;
    s.channel_area = 2e4;
    s.rock.angle = 33.0 * M_PI / 180.0;
    s.rock.angle_spread = 10.0 * M_PI / 180.0;
    s.rock.erodibility_contrast = 4.0;
    s.rock.thickness = 60.0;
    s.rock.seed = 3;
    Model model(w, h, cell, noise(w, h, 6, 10.0), std::vector<double>(std::size_t(w) * h, U), s);
    model.run(3e6, 3e4);
    const auto& z = model.heights();
    const auto& up = model.uplifted();
    double steep[2] = {0, 0};
    int count[2] = {0, 0};
    for (int y = 1; y + 1 < h; ++y)
        for (int x = 1; x + 1 < w; ++x) {
            const std::size_t i = std::size_t(y) * w + x;
            const double strength = s.rock.strength(z[i] - up[i], x * cell, y * cell);
            if (strength > 0.3 && strength < 0.7) continue;
            const double gx = (z[i + 1] - z[i - 1]) / (2 * cell), gy = (z[i + w] - z[i - w]) / (2 * cell);
            steep[strength >= 0.7] += std::hypot(gx, gy);
            ++count[strength >= 0.7];
        }
    ASSERT_GT(count[0], 200);
    ASSERT_GT(count[1], 200);
    EXPECT_GT(steep[1] / count[1], 1.15 * steep[0] / count[0]) << "strong beds must hold steeper slopes";
}

TEST(Beds, LandslidesAndBedsGiveTheSameBitsOnOneAndTwoThreads) {
    const int w = 97, h = 71;
    std::vector<double> results[2];
    for (int t = 0; t < 2; ++t) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(t + 1));
        Settings s;
        s.erodibility = 1e-5;
        s.area_exponent = 0.5;
        s.diffusivity = 0.05;
        s.rock.angle = 30.0 * M_PI / 180.0;
        s.rock.angle_spread = 8.0 * M_PI / 180.0;
        s.rock.erodibility_contrast = 3.0;
        s.rock.thickness = 25.0;
        s.rock.dip_slope = 0.4;
        s.rock.dip_east = 0.6;
        s.rock.dip_south = 0.8;
        s.rock.seed = 17;
        Model model(w, h, 30.0, noise(w, h, 8, 50.0), std::vector<double>(std::size_t(w) * h, 1.5e-3), s);
        model.run(6e5, 3e4);
        results[t] = model.heights();
    }
    EXPECT_EQ(0, std::memcmp(results[0].data(), results[1].data(), results[0].size() * sizeof(double)));
}

TEST(Glaciers, IceGathersAboveTheElaAndMeltsBelowIt) {
    // A straight valley of 40 cells, cell 0 the outlet, rising 25 m a cell: each cell adds
    // b(z)·cell² to the ice it receives and the flux never goes below zero.
    const int n = 40;
    const double cell = 100.0;
    Glaciers g;
    g.ela = 600.0;
    g.balance_gradient = 0.01;
    g.max_balance = 2.0;
    std::vector<double> z(n);
    std::vector<std::int32_t> stack(n), receiver(n);
    for (int i = 0; i < n; ++i) z[i] = 25.0 * i, stack[i] = i, receiver[i] = std::max(0, i - 1);
    std::vector<double> q;
    ice_flux(g, z.data(), stack.data(), receiver.data(), n, cell, q);
    double expected = 0.0;
    for (int i = n - 1; i >= 0; --i) {
        expected = std::max(0.0, expected + std::min(0.01 * (z[i] - 600.0), 2.0) * cell * cell);
        EXPECT_DOUBLE_EQ(q[i], expected) << i;
    }
    EXPECT_GT(q[24], 0.0) << "ice flows below the ELA (cell 24, 600 m) until ablation eats it";
    EXPECT_EQ(q[0], 0.0);
    EXPECT_DOUBLE_EQ(q[39], 2.0 * cell * cell) << "the top gains at most b_max";
}

TEST(Glaciers, AGlacierTurnsAVShapedValleyIntoAParabolicTrough) {
    // A V-shaped valley running south (walls at 35°, floor falling 5 % a cell); a glacier of 4e6 m³/yr
    // down its axis. Across the valley, within the glacier's half-width, the walls end on the parabola
    // h_c + tan θ_w/(2R)·p²; beyond it and on the floor nothing changes.
    const int w = 61, h = 30, axis = 30;
    const double cell = 50.0, wall = std::tan(35.0 * M_PI / 180.0);
    Glaciers g;
    g.half_width = 400.0;
    g.wall_slope = std::tan(40.0 * M_PI / 180.0);
    std::vector<double> z(std::size_t(w) * h), q(z.size(), 0.0);
    std::vector<std::int32_t> receiver(z.size());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = std::size_t(y) * w + x;
            z[i] = 2000.0 - 0.05 * cell * y + wall * cell * std::abs(x - axis);
            receiver[i] = y + 1 < h ? std::int32_t(i + w) : std::int32_t(i);
        }
    for (int y = 0; y < h; ++y) q[std::size_t(y) * w + axis] = 4e6;
    const auto before = z;
    const double removed = carve_troughs(g, z.data(), q, receiver.data(), w, h, cell);
    const double R = g.half_width_for(4e6), a = g.wall_slope / (2.0 * R);
    EXPECT_NEAR(R, 400.0 * std::pow(4.0, 0.4), 1e-9);
    double expected_removed = 0.0;
    for (int y = 0; y + 1 < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = std::size_t(y) * w + x;
            const double p = cell * std::abs(x - axis);
            const double floor = before[std::size_t(y) * w + axis];
            const double want = p <= R ? std::min(before[i], floor + a * p * p) : before[i];
            EXPECT_NEAR(z[i], want, 1e-9) << x << "," << y;
            expected_removed += before[i] - want;
        }
    EXPECT_NEAR(removed, expected_removed * cell * cell, 1e-3);
    // The trough is wider than the V at the same depth: 100 m above the floor the V is 2·100/tan 35° wide.
    const int y = 10;
    int v_width = 0, u_width = 0;
    for (int x = 0; x < w; ++x) {
        const double floor = before[std::size_t(y) * w + axis];
        v_width += before[std::size_t(y) * w + x] < floor + 100.0;
        u_width += z[std::size_t(y) * w + x] < floor + 100.0;
    }
    EXPECT_GE(u_width, 2 * v_width) << "a U is at least twice as wide as the V it was";
}

TEST(Glaciers, WithTheElaAboveTheSummitsTheRunIsTheRiversAlone) {
    const int w = 65, h = 49;
    Settings s;
    s.erodibility = 1e-5;
    s.area_exponent = 0.5;
    s.diffusivity = 0.02;
    Settings iced = s;
    iced.glaciers.ela = 1e5;
    iced.glaciers.balance_gradient = 0.01;
    iced.glaciers.erodibility = 1e-4;
    Model rivers(w, h, 50.0, noise(w, h, 2, 100.0), std::vector<double>(std::size_t(w) * h, 1e-3), s);
    Model glaciers(w, h, 50.0, noise(w, h, 2, 100.0), std::vector<double>(std::size_t(w) * h, 1e-3), iced);
    rivers.run(2e5, 2e4);
    glaciers.run(2e5, 2e4);
    EXPECT_EQ(0, std::memcmp(rivers.heights().data(), glaciers.heights().data(), rivers.heights().size() * 8));
}

TEST(Glaciers, GlaciatedValleysEndDeeperAndWiderAndTheBitsHoldOnTwoThreads) {
    // A rising block with valleys: 300 kyr with glaciers (ELA 600 m) against rivers alone. Above the ELA
    // the glaciated valleys are cut deeper (lower mean height) and their floors are wider.
    const int w = 81, h = 61;
    const double cell = 60.0;
    std::vector<double> start(std::size_t(w) * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            start[std::size_t(y) * w + x] = 1200.0 * std::sin(M_PI * y / (h - 1)) +
                150.0 * std::abs(std::sin(0.25 * x)) + 5.0 * random::uniform(4, x, y);
    Settings s;
    s.erodibility = 5e-6;
    s.area_exponent = 0.5;
    s.diffusivity = 0.05;
    s.open = {true, false, true, false};
    Settings iced = s;
    iced.glaciers.ela = 600.0;
    iced.glaciers.balance_gradient = 0.007;
    iced.glaciers.erodibility = 2e-6;
    iced.glaciers.glacier_flux = 1e5;
    Model rivers(w, h, cell, start, std::vector<double>(start.size(), 5e-4), s);
    rivers.run(3e5, 2e4);
    std::vector<double> runs[2];
    std::size_t ice_cells = 0;
    for (int t = 0; t < 2; ++t) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(t + 1));
        Model glaciers(w, h, cell, start, std::vector<double>(start.size(), 5e-4), iced);
        glaciers.run(3e5, 2e4);
        runs[t] = glaciers.heights();
        ice_cells = std::size_t(
            std::count_if(glaciers.ice_flux().begin(), glaciers.ice_flux().end(), [](double q) { return q > 0.0; }));
    }
    EXPECT_EQ(0, std::memcmp(runs[0].data(), runs[1].data(), runs[0].size() * 8)) << "1 and 2 threads";
    ASSERT_GT(ice_cells, std::size_t(200));
    double sum_r = 0.0, sum_g = 0.0;
    int cells = 0;
    for (std::size_t i = 0; i < start.size(); ++i)
        if (rivers.heights()[i] > 600.0) sum_r += rivers.heights()[i], sum_g += runs[0][i], ++cells;
    ASSERT_GT(cells, 500);
    EXPECT_LT(sum_g / cells, sum_r / cells - 20.0) << "the glaciers must lower the high ground by tens of metres";
}

TEST(StreamPower, TheRockUpliftIsCountedApartFromTheErosion) {
    // uplifted(): U·t on every cell but the outlets (held at base level), whatever the rivers did; the
    // node writes it as the layer 'uplifted' and the surface's own change, heights − start − uplifted,
    // as 'eroded' (negative where the rivers and creep removed rock).
    const int w = 41, h = 31;
    const double cell = 30.0, U = 2e-3, years = 1e5;
    Settings s;
    s.erodibility = 5e-5;
    s.diffusivity = 0.01;
    s.open = {true, false, true, false};
    const std::vector<double> start = noise(w, h, 7, 5.0);
    Model model(w, h, cell, start, std::vector<double>(std::size_t(w) * h, U), s);
    model.run(years, 1e4);
    const auto& up = model.uplifted();
    const auto& z = model.heights();
    ASSERT_EQ(up.size(), z.size());
    double removed = 0.0;
    for (std::size_t i = 0; i < z.size(); ++i) {
        if (model.flow().is_outlet(std::int64_t(i))) {
            EXPECT_EQ(up[i], 0.0) << i;
            continue;
        }
        EXPECT_NEAR(up[i], U * years, 1e-9) << i;
        removed += z[i] - start[i] - up[i];
    }
    EXPECT_LT(removed, -100.0) << "the rivers must have removed rock: the surface's own change is negative";
}

// A river along one row: outlet at the west end, every cell drains all the
// cells east of it. Settings for the 1-D tests.
Settings river_settings(double n) {
    Settings s;
    s.erodibility = n == 1.0 ? 2e-5 : 4e-6;
    s.area_exponent = 0.4;
    s.slope_exponent = n;
    s.diffusivity = 0.0;
    s.open = {false, false, false, true};
    return s;
}

TEST(StreamPower, OneStepOfARiverEqualsTheImplicitSchemeSolvedByHand) {
    for (double n : {1.0, 2.0, 0.6}) {
        const int w = 200;
        const double cell = 25.0, U = 2e-3, dt = 5e4;
        std::vector<double> h0(w);
        for (int x = 0; x < w; ++x) h0[std::size_t(x)] = 0.3 * cell * x + 5.0 * std::sin(0.3 * x) + 2.0 * x * 0.0;
        for (int x = 1; x < w; ++x) h0[std::size_t(x)] = std::max(h0[std::size_t(x)], h0[std::size_t(x - 1)] + 0.5);
        const Settings s = river_settings(n);
        Model model(w, 1, cell, h0, std::vector<double>(std::size_t(w), U), s);
        model.step(dt);
        // By hand: h_x' solves h' − (h + U dt) + K dt A^m ((h' − h'_{x−1})/cell)^n = 0, by bisection.
        std::vector<double> expect(w);
        expect[0] = h0[0];
        for (int x = 1; x < w; ++x) {
            const double area = double(w - x) * cell * cell;
            const double F = s.erodibility * dt * std::pow(area, s.area_exponent);
            const double top = h0[std::size_t(x)] + U * dt, base = expect[std::size_t(x - 1)];
            double lo = base, hi = top;
            for (int it = 0; it < 200; ++it) {
                const double mid = 0.5 * (lo + hi);
                const double g = mid - top + F * std::pow((mid - base) / cell, n);
                (g > 0 ? hi : lo) = mid;
            }
            expect[std::size_t(x)] = 0.5 * (lo + hi);
        }
        for (int x = 0; x < w; ++x)
            ASSERT_NEAR(model.heights()[std::size_t(x)], expect[std::size_t(x)],
                        1e-7 * (1.0 + std::abs(expect[std::size_t(x)])))
                << "n = " << n << ", x = " << x;
    }
}

TEST(StreamPower, AKnickpointTravelsUpstreamAtTheKinematicWaveSpeed) {
    // n = 1, no uplift: dh/dt = −K A^m dh/dx is a wave moving upstream at c(x) = K A(x)^m.
    // A river at steady state for uplift U0 sees its outlet drop by 100 m at t = 0 (the
    // equivalent: raise every other cell by 100 m); after time t the knickpoint stands
    // where ∫ dx / c from the outlet equals t.
    const int w = 400;
    const double cell = 50.0;
    Settings s = river_settings(1.0);
    std::vector<double> h0(w);
    const double U0 = 1e-4;
    h0[0] = 0.0;
    for (int x = 1; x < w; ++x) {
        const double area = double(w - x) * cell * cell;
        h0[std::size_t(x)] = h0[std::size_t(x - 1)] + cell * U0 / (s.erodibility * std::pow(area, s.area_exponent));
    }
    std::vector<double> start = h0;
    for (int x = 1; x < w; ++x) start[std::size_t(x)] += 100.0;
    Model model(w, 1, cell, start, std::vector<double>(std::size_t(w), U0), s);
    const double t = 2e6;
    model.run(t, 2e3);
    // Where the analytical knickpoint stands.
    double travel = 0.0;
    int expected = 0;
    for (int x = 1; x < w; ++x) {
        const double area = double(w - x) * cell * cell;
        travel += cell / (s.erodibility * std::pow(area, s.area_exponent));
        if (travel > t) break;
        expected = x;
    }
    ASSERT_GT(expected, 20);
    ASSERT_LT(expected, w - 20);
    // Where the model's stands: the cell where the drop has reached half its 100 m.
    int found = 0;
    for (int x = 1; x < w; ++x)
        if (model.heights()[std::size_t(x)] - h0[std::size_t(x)] < 50.0) found = x;
    EXPECT_NEAR(found, expected, 5) << "knickpoint position, cells";
    // Well downstream of it the river is back at its old profile; well upstream nothing has moved yet
    // (the implicit upwind scheme smears the front over about sqrt(distance · cell)).
    for (int x = 1; x < expected - 50; ++x) EXPECT_NEAR(model.heights()[std::size_t(x)], h0[std::size_t(x)], 2.0) << x;
    for (int x = expected + 50; x < w; ++x)
        EXPECT_NEAR(model.heights()[std::size_t(x)], start[std::size_t(x)], 2.0) << x;
}

/// Follows receivers from every cell; checks each reaches an outlet within size() hops.
void expect_every_cell_drains(const FlowRouter& f) {
    const auto& r = f.receivers();
    for (std::size_t i = 0; i < f.size(); ++i) {
        std::int64_t c = std::int64_t(i);
        std::size_t hops = 0;
        while (!f.is_outlet(c) && hops <= f.size()) c = r[std::size_t(c)], ++hops;
        ASSERT_TRUE(f.is_outlet(c)) << "cell " << i << " never reaches an outlet (a loop or a sink)";
        if (!f.is_outlet(std::int64_t(i))) {
            // A receiver is a neighbour.
            const std::int64_t d = r[i] - std::int64_t(i), W = f.width();
            const bool neighbour =
                d == 1 || d == -1 || d == W || d == -W || d == W + 1 || d == W - 1 || d == -W + 1 || d == -W - 1;
            ASSERT_TRUE(neighbour) << "cell " << i;
        }
    }
    // The stack holds each cell once, receivers before donors.
    std::vector<std::int64_t> position(f.size(), -1);
    for (std::size_t s = 0; s < f.size(); ++s) {
        ASSERT_EQ(position[std::size_t(f.stack()[s])], -1);
        position[std::size_t(f.stack()[s])] = std::int64_t(s);
    }
    for (std::size_t i = 0; i < f.size(); ++i) {
        if (!f.is_outlet(std::int64_t(i))) ASSERT_LT(position[std::size_t(r[i])], position[i]);
    }
}

TEST(FlowRouting, NoiseWithClosedSidesDrainsEverythingToTheOneOutlet) {
    for (Depressions mode : {Depressions::fill, Depressions::route}) {
        const int w = 123, h = 97;
        const double cell = 30.0;
        auto hts = noise(w, h, 42, 100.0);  // about a third of the cells are pits
        const auto original = hts;
        const std::int64_t outlet = lowest_cell(hts);
        FlowRouter f(w, h, cell, OpenSides{false, false, false, false}, outlet);
        f.route(hts.data(), mode);
        f.accumulate();
        EXPECT_GT(f.pits(), 1000);
        expect_every_cell_drains(f);
        EXPECT_DOUBLE_EQ(f.area()[std::size_t(outlet)], double(w) * h * cell * cell);
        if (mode == Depressions::fill) {
            // Filled: no cell's receiver is higher than the cell, and nothing was lowered.
            for (std::size_t i = 0; i < hts.size(); ++i) {
                EXPECT_LE(hts[std::size_t(f.receivers()[i])], hts[i]);
                EXPECT_GE(hts[i], original[i]);
            }
        } else {
            EXPECT_EQ(hts, original);
        }
    }
}

TEST(FlowRouting, OpenSidesShareTheMapsArea) {
    const int w = 90, h = 70;
    const double cell = 10.0;
    auto hts = noise(w, h, 8, 50.0);
    FlowRouter f(w, h, cell, OpenSides{true, false, false, true});
    f.route(hts.data(), Depressions::fill);
    f.accumulate();
    expect_every_cell_drains(f);
    double out = 0.0;
    for (std::size_t i = 0; i < f.size(); ++i)
        if (f.is_outlet(std::int64_t(i))) out += f.area()[i];
    EXPECT_DOUBLE_EQ(out, double(w) * h * cell * cell);
    // Closed sides are not outlets: the east and south edges (but their corners with open sides).
    EXPECT_FALSE(f.is_outlet(std::int64_t(h / 2) * w + (w - 1)));
    EXPECT_FALSE(f.is_outlet(std::int64_t(h - 1) * w + w / 2));
    EXPECT_TRUE(f.is_outlet(std::int64_t(h / 2) * w));
}

TEST(FlowRouting, ALakeSpillsOverItsLowestPass) {
    // A bowl whose rim is lowest (10 m) at one place on its east side: the lake fills to 10 m
    // and its water leaves there.
    const int w = 21, h = 21;
    std::vector<double> hts(std::size_t(w) * h, 0.0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const int ring = std::max(std::abs(x - 10), std::abs(y - 10));
            double v = ring == 6 ? 30.0 : ring < 6 ? 5.0 - 0.1 * (6 - ring) : 30.0 - 2.0 * (ring - 6);
            v = ring > 6 ? 1.0 * (10 - ring) : v;
            hts[std::size_t(y) * w + x] = v;
        }
    hts[std::size_t(10) * w + 16] = 10.0;  // the pass
    FlowRouter f(w, h, 1.0, OpenSides{});
    f.route(hts.data(), Depressions::fill);
    f.accumulate();
    expect_every_cell_drains(f);
    EXPECT_EQ(f.pits(), 1);
    for (int y = 5; y <= 15; ++y)
        for (int x = 5; x <= 15; ++x) EXPECT_DOUBLE_EQ(hts[std::size_t(y) * w + x], 10.0) << x << "," << y;
    // The pass receives the whole lake (11 x 11 cells) and itself.
    EXPECT_DOUBLE_EQ(f.area()[std::size_t(10) * w + 16], 122.0);
}

TEST(StreamPower, SameBitsOnOneAndTwoThreads) {
    const int w = 161, h = 129;  // 129 rows: many row bands and root groups on 2 threads
    std::vector<double> results[2];
    std::vector<double> areas[2];
    for (int t = 0; t < 2; ++t) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(t + 1));
        Settings s;
        s.diffusivity = 0.02;
        s.open = {true, true, false, true};
        auto up = noise(w, h, 77, 2e-3);  // uneven uplift: lakes form and fill each step
        Model model(w, h, 30.0, noise(w, h, 5, 200.0), up, s);
        model.run(2e5, 1e4);
        results[t] = model.heights();
        areas[t] = model.flow().area();
    }
    EXPECT_EQ(0, std::memcmp(results[0].data(), results[1].data(), results[0].size() * sizeof(double)));
    EXPECT_EQ(0, std::memcmp(areas[0].data(), areas[1].data(), areas[0].size() * sizeof(double)));
}

TEST(StreamPower, NonFiniteHeightsAreFound) {
    Settings s;
    std::vector<double> hts = noise(20, 20, 3, 10.0);
    hts[57] = std::nan("");
    Model model(20, 20, 10.0, hts, {}, s);
    EXPECT_EQ(model.first_non_finite(), 57);
}

TEST(StreamPower, ChiGrowsUpstreamByTheIntegral) {
    const int w = 50;
    Settings s = river_settings(1.0);
    std::vector<double> h0(w);
    for (int x = 0; x < w; ++x) h0[std::size_t(x)] = 3.0 * x;
    Model model(w, 1, 10.0, h0, {}, s);
    model.route_only();
    const auto chi = model.chi(1.0);
    double expect = 0.0;
    for (int x = 1; x < w; ++x) {
        expect += std::pow(1.0 / (double(w - x) * 100.0), 0.4) * 10.0;
        EXPECT_NEAR(chi[std::size_t(x)], expect, 1e-12 * expect);
    }
}

// ---- Multiple flow directions (Freeman 1991) --------------------------------------------------

/// Drainage areas of a cone (a peak of slope `slope` at the centre of an n × n map, every side open)
/// by D8 (exponent 0) or multiple flow directions.
std::vector<double> cone_areas(int n, double cell, double exponent, std::vector<double>* heights = nullptr) {
    std::vector<double> hts(std::size_t(n) * n);
    const double c = 0.5 * (n - 1);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) hts[std::size_t(y) * n + x] = 1000.0 - 0.2 * cell * std::hypot(x - c, y - c);
    FlowRouter f(n, n, cell, OpenSides{});
    f.route(hts.data(), Depressions::fill);
    if (exponent > 0.0) f.accumulate_multiple(hts.data(), exponent);
    else f.accumulate();
    if (heights) *heights = hts;
    return f.area();
}

TEST(MultipleFlow, OnAConeTheAreaSpreadsAsDivergentFlowDoes) {
    // Water from a peak spreads over ever wider contours: the area upslope of a
    // contour length b at distance r is the sector b·r/2, so the specific
    // catchment area (area per unit contour width) is r/2 (the cone test of
    // Freeman 1991 and Quinn et al. 1991). With a grid cell's contour width
    // taken as one cell, A = cell·r/2 in every direction; the cell's own area
    // and its outflow edge half a cell further out add 2–5 % at 30–90 cells from
    // the peak. D8 sends each cell's water to one neighbour: the area gathers on
    // the rays of the grid's 8 directions and stays small between them.
    const int n = 201;
    const double cell = 10.0, c = 0.5 * (n - 1);
    struct Ring {
        double mean_ratio = 0, cv = 0;
    };
    auto ring = [&](const std::vector<double>& area) {
        std::vector<double> ratio;
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const double r = std::hypot(x - c, y - c);
                if (r < 30.0 || r > 90.0) continue;
                ratio.push_back(area[std::size_t(y) * n + x] / (cell * 0.5 * (r * cell)));
            }
        Ring out;
        for (double v : ratio) out.mean_ratio += v / double(ratio.size());
        for (double v : ratio) out.cv += (v - out.mean_ratio) * (v - out.mean_ratio) / double(ratio.size());
        out.cv = std::sqrt(out.cv) / out.mean_ratio;
        return out;
    };
    const Ring mfd = ring(cone_areas(n, cell, 1.1)), d8 = ring(cone_areas(n, cell, 0.0));
    EXPECT_NEAR(mfd.mean_ratio, 1.0, 0.08) << "specific catchment area / (r/2), mean over the ring";
    EXPECT_LT(mfd.cv, 0.05) << "spread of that ratio over the ring (same in every direction)";
    EXPECT_GT(d8.cv, 0.4) << "D8 on the same cone (the property that tells the two apart)";
}

TEST(MultipleFlow, EveryDropReachesAnOutletOnceWithClosedSidesAndLakes) {
    // Noise with every side closed: about a third of the cells are pits, filled
    // into lakes (flats whose water follows the D8 tree) between slopes that
    // split theirs. The one outlet gets the whole map's area (to round-off:
    // the shares are fractions), nothing is lost or counted twice.
    const int w = 123, h = 97;
    const double cell = 30.0;
    auto hts = noise(w, h, 42, 100.0);
    const std::int64_t outlet = lowest_cell(hts);
    FlowRouter f(w, h, cell, OpenSides{false, false, false, false}, outlet);
    f.route(hts.data(), Depressions::fill);
    f.accumulate_multiple(hts.data(), 1.1);
    const double total = double(w) * h * cell * cell;
    EXPECT_NEAR(f.area()[std::size_t(outlet)], total, 1e-9 * total);
    for (std::size_t i = 0; i < f.size(); ++i) ASSERT_GE(f.area()[i], cell * cell) << i;
    // Open sides: the outlets share the map's area.
    auto hts2 = noise(w, h, 8, 50.0);
    FlowRouter g(w, h, cell, OpenSides{true, false, true, true});
    g.route(hts2.data(), Depressions::fill);
    g.accumulate_multiple(hts2.data(), 1.1);
    double out = 0.0;
    for (std::size_t i = 0; i < g.size(); ++i)
        if (g.is_outlet(std::int64_t(i))) out += g.area()[i];
    EXPECT_NEAR(out, total, 1e-9 * total);
}

TEST(MultipleFlow, SameBitsOnOneAndTwoThreadsAndTheSolverStillFollowsTheSteepest) {
    const int w = 161, h = 129;
    std::vector<double> results[2], areas[2];
    for (int t = 0; t < 2; ++t) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(t + 1));
        Settings s;
        s.diffusivity = 0.02;
        s.mfd_exponent = 1.1;
        s.open = {true, true, false, true};
        Model model(w, h, 30.0, noise(w, h, 5, 200.0), noise(w, h, 77, 2e-3), s);
        model.run(2e5, 1e4);
        results[t] = model.heights();
        areas[t] = model.flow().area();
        expect_every_cell_drains(model.flow());
    }
    EXPECT_EQ(0, std::memcmp(results[0].data(), results[1].data(), results[0].size() * sizeof(double)));
    EXPECT_EQ(0, std::memcmp(areas[0].data(), areas[1].data(), areas[0].size() * sizeof(double)));
    // The areas are not D8's (some cell has a fractional share of a cell's area).
    bool fractional = false;
    for (double a : areas[0]) fractional = fractional || std::abs(a / 900.0 - std::round(a / 900.0)) > 1e-6;
    EXPECT_TRUE(fractional);
    // Unfilled lakes would send water back into themselves: refused.
    Settings bad;
    bad.mfd_exponent = 1.1;
    bad.depressions = Depressions::route;
    EXPECT_THROW(Model(8, 8, 1.0, noise(8, 8, 1, 1.0), {}, bad), std::invalid_argument);
}

TEST(BasinGraph, TheTreeDoesNotDependOnTheOrderTheLinksCameIn) {
    // A tiled run collects its links tile by tile and rank 0 joins them: the
    // tree (each pit's way out and lake level) must not follow that order.
    // Passes drawn from a few values, so that equal passes (flat lakes) are common.
    const std::int32_t nodes = 400;
    std::vector<Link> links;
    std::uint64_t k = 0;
    for (std::int32_t b = 1; b < nodes; ++b)
        for (int e = 0; e < 4; ++e) {
            const auto a = std::int32_t(random::uniform(9, k++) * b);  // to a lower node (0: the sea)
            const double pass = std::floor(random::uniform(9, k++) * 5.0),
                         low = pass - std::floor(random::uniform(9, k++) * 2.0);
            links.push_back({pass, low, a, b, std::int64_t(k), std::int64_t(k + 1)});
        }
    std::vector<Link> sorted = links;
    const BasinTree want = solve_basin_graph(sorted, nodes);
    for (std::uint64_t seed = 1; seed <= 5; ++seed) {
        std::vector<Link> shuffled = links;
        for (std::size_t e = shuffled.size(); e > 1; --e)
            std::swap(shuffled[e - 1], shuffled[std::size_t(random::below(e, 100 + seed, e))]);
        const BasinTree got = solve_basin_graph(shuffled, nodes);
        ASSERT_EQ(got.level, want.level);
        for (std::int32_t v = 1; v < nodes; ++v) {
            const Link& g = shuffled[std::size_t(got.out_link[std::size_t(v)])];
            const Link& w = sorted[std::size_t(want.out_link[std::size_t(v)])];
            EXPECT_EQ(g.i, w.i) << "node " << v;
            EXPECT_EQ(g.j, w.j) << "node " << v;
        }
    }
    // Among equal passes the link from the lower cell goes first: water crosses a flat lake from its lowest shore.
    std::vector<Link> two = {{3.0, 2.0, 0, 1, 10, 11}, {3.0, 1.0, 0, 1, 20, 21}};
    const BasinTree t = solve_basin_graph(two, 2);
    EXPECT_EQ(two[std::size_t(t.out_link[1])].i, 20);
}

TEST(BasinJoin, TilesThatSettleTheirClosedLakesGiveTheWholeGraphsTree) {
    // A lattice of basins (96 x 64; the outer ring drains to the sea, and
    // some inner ones too) cut into tiles of 32 x 32. A basin is closed on its
    // tile when all its neighbours are there (and 9 in 10 such are); its links
    // are then all in its tile's list. Links between two open basins go to
    // one tile or, as across a seam, to both with different cells. Passes
    // come from a few values, so equal passes are common. Whatever the tiles
    // settle, every basin must get the whole graph's way out and lake level.
    const int X = 96, Y = 64, tile = 32;
    auto node = [&](int x, int y) { return std::int64_t(y) * X + x + 1; };  // 0: the sea
    auto basin_id = [](std::int64_t v) { return v == 0 ? std::int64_t(-1) : 5 * v + 2; };  // in index order, as pits
    auto tile_of = [&](int x, int y) { return (y / tile) * (X / tile) + x / tile; };
    const int tiles = (X / tile) * (Y / tile);
    for (std::uint64_t seed = 1; seed <= 20; ++seed) {
        std::uint64_t k = 0;
        auto uniform = [&] { return random::uniform(seed, k++); };
        std::vector<std::uint8_t> closed(std::size_t(X * Y + 1), 0);
        for (int y = 1; y < Y - 1; ++y)
            for (int x = 1; x < X - 1; ++x) {
                bool same = true;
                for (int d = 0; d < 8; ++d) same = same && tile_of(x + kDx[d], y + kDy[d]) == tile_of(x, y);
                closed[std::size_t(node(x, y))] = same && uniform() < 0.9;
            }
        std::vector<std::vector<Link>> per_tile(static_cast<std::size_t>(tiles));
        std::vector<Link> whole;  // node numbers
        std::int64_t cell = 0;
        auto add = [&](std::int64_t u, std::int64_t v, int t) {  // u < v, nodes
            const double pass = std::floor(uniform() * 6.0), low = pass - std::floor(uniform() * 2.0);
            const std::int64_t i = cell++, j = cell++;
            whole.push_back({pass, low, u, v, i, j});
            per_tile[std::size_t(t)].push_back({pass, low, basin_id(u), basin_id(v), i, j});
        };
        for (int y = 0; y < Y; ++y)
            for (int x = 0; x < X; ++x) {
                const std::int64_t v = node(x, y);
                const int t = tile_of(x, y);
                if (x == 0 || y == 0 || x == X - 1 || y == Y - 1 || uniform() < 0.05) add(0, v, t);
                for (int d : {0, 1, 2, 3}) {  // east, south-east, south, south-west: each pair once
                    const int nx = x + kDx[d], ny = y + kDy[d];
                    if (nx < 0 || nx >= X || ny >= Y) continue;
                    const std::int64_t u = node(nx, ny);
                    const int tu = tile_of(nx, ny);
                    if (closed[std::size_t(v)]) add(v, u, t);
                    else if (closed[std::size_t(u)]) add(v, u, tu);
                    else if (t != tu && uniform() < 0.5) add(v, u, t), add(v, u, tu);  // a pair seen by both tiles
                    else add(v, u, uniform() < 0.5 ? t : tu);
                }
            }
        std::vector<Link> sorted = whole;
        const BasinTree want = solve_basin_graph(sorted, std::int32_t(X * Y + 1));

        std::vector<TileForest> forests;
        std::vector<Link> deferred;
        std::vector<ForestEdge> edges;
        std::vector<std::int64_t> anchors;
        std::int64_t settled = 0;
        for (int t = 0; t < tiles; ++t) {
            forests.push_back(contract_tile(per_tile[std::size_t(t)],
                                            [&](std::int64_t b) { return closed[std::size_t((b - 2) / 5)] != 0; }));
            const TileForest& f = forests.back();
            deferred.insert(deferred.end(), f.deferred.begin(), f.deferred.end());
            edges.insert(edges.end(), f.edges.begin(), f.edges.end());
            anchors.insert(anchors.end(), f.anchors.begin(), f.anchors.end());
        }
        std::sort(anchors.begin(), anchors.end());
        anchors.erase(std::unique(anchors.begin(), anchors.end()), anchors.end());
        std::unordered_map<std::int64_t, KeyExit> keys;
        for (const KeyExit& e : join_tiles(deferred, edges, anchors)) keys.emplace(e.basin, e);
        std::map<std::int64_t, BasinExit> got;
        for (const TileForest& f : forests)
            for (const BasinExit& e : orient_tile(f, keys)) ASSERT_TRUE(got.emplace(e.basin, e).second) << e.basin;
        for (std::int64_t v = 1; v <= X * Y; ++v) {
            const Link& w = sorted[std::size_t(want.out_link[std::size_t(v)])];
            const std::int64_t in = w.a == v ? w.i : w.j, across = w.a == v ? w.j : w.i;
            const std::int64_t b = basin_id(v);
            if (closed[std::size_t(v)]) {
                ASSERT_EQ(got.count(b), 1u) << "seed " << seed << " basin " << v;
                EXPECT_EQ(got[b].level, want.level[std::size_t(v)]) << "seed " << seed << " basin " << v;
                EXPECT_EQ(got[b].in, in) << "seed " << seed << " basin " << v;
                EXPECT_EQ(got[b].across, across) << "seed " << seed << " basin " << v;
                if (keys.count(b))
                    EXPECT_EQ(keys[b].level, want.level[std::size_t(v)]) << "seed " << seed << " key " << v;
                ++settled;
            } else {
                ASSERT_EQ(keys.count(b), 1u) << "seed " << seed << " basin " << v;
                EXPECT_EQ(keys[b].level, want.level[std::size_t(v)]) << "seed " << seed << " basin " << v;
                EXPECT_EQ(keys[b].in, in) << "seed " << seed << " basin " << v;
                EXPECT_EQ(keys[b].across, across) << "seed " << seed << " basin " << v;
            }
        }
        EXPECT_EQ(std::int64_t(got.size()), settled);
        // Rank 0 sees much less than the whole graph.
        EXPECT_LT(deferred.size() + edges.size(), whole.size() / 2) << "seed " << seed;
    }
}

TEST(MultipleFlow, ACellSplitsItsWaterBySlopeToThePowerP) {
    // One inner cell 10 m above a row of outlets (3 × 2 map, every side but the
    // north open): its lower neighbours are south (slope 10) and south-west and
    // south-east (slope 10/√2); its neighbours west and east are higher.
    for (double p : {1.0, 1.1, 2.0, 8.0}) {
        std::vector<double> hts = {20.0, 10.0, 20.0, 0.0, 0.0, 0.0};
        FlowRouter f(3, 2, 1.0, OpenSides{false, true, true, true});
        f.route(hts.data(), Depressions::fill);
        f.accumulate_multiple(hts.data(), p);
        const double ws = std::pow(10.0, p), wd = std::pow(10.0 / std::sqrt(2.0), p);
        EXPECT_NEAR(f.area()[4], 1.0 + ws / (ws + 2.0 * wd), 1e-12) << "p = " << p;
        EXPECT_NEAR(f.area()[3], 1.0 + wd / (ws + 2.0 * wd), 1e-12) << "p = " << p;
        EXPECT_NEAR(f.area()[5], f.area()[3], 1e-12) << "p = " << p;
        EXPECT_EQ(f.receivers()[1], 4);  // the solver's receiver: the steepest
    }
}

}  // namespace

// ------------------------------------------------------------ deposition (Yuan et al. 2019)

struct DepositionCase {
    double n;
    double k;
    double g;
    double mfd = 0.0;  // > 0: drainage area by multiple flow directions (the sediment follows the D8 tree)
};

class DepositionSteadyState : public ::testing::TestWithParam<DepositionCase> {};

TEST_P(DepositionSteadyState, ChannelsCarryOnePlusGTimesTheUplift) {
    // dh/dt = U − K A^m S^n + (G/A) Qs. At steady state every cell lowers at U, so the flux
    // through a cell is Qs = U·A and the deposition term is G·U: the channels must incise
    // (1 + G)·U, S = ((1 + G)·U/K)^(1/n)·A^(−m/n). A solver that deposited nothing (G = 0's
    // slopes) is 2^(1/n) − 1 off at G = 1: 41 % for n = 2, 100 % for n = 1.
    const int w = 81, h = 61;
    const double cell = 50.0, U = 1e-3;
    const auto [n, k, g, mfd] = GetParam();
    Settings s;
    s.mfd_exponent = mfd;
    s.erodibility = k;
    s.area_exponent = 0.5 * n;
    s.slope_exponent = n;
    s.diffusivity = 0.0;
    s.deposition = g;
    s.open = {true, false, true, false};
    Model model(w, h, cell, noise(w, h, 1, 10.0), std::vector<double>(std::size_t(w) * h, U), s);
    model.run(1.2e8, 2e5);
    const auto& f = model.flow();
    const auto& hh = model.heights();
    const double s0 = std::pow((1.0 + g) * U / k, 1.0 / n);
    std::vector<double> la, ls;
    double worst = 0.0;
    for (std::size_t i = 0; i < hh.size(); ++i) {
        const double a = f.area()[i];
        const std::int32_t r = f.receivers()[i];
        if (r == std::int32_t(i) || a < 10 * cell * cell) continue;
        const double slope = (hh[i] - hh[std::size_t(r)]) / f.distance(std::int64_t(i));
        worst = std::max(worst, std::abs(slope / (s0 * std::pow(a, -0.5)) - 1.0));
        la.push_back(std::log(a));
        ls.push_back(std::log(slope));
    }
    ASSERT_GT(la.size(), 200u);
    EXPECT_LT(worst, 0.02) << "largest relative deviation from S = ((1+G)U/K)^(1/n) A^(-m/n), G = " << g;
    const auto [slope, intercept] = fit(la, ls);
    std::printf("n = %g, G = %g: %zu channel cells, worst deviation %.3g %%, concavity %.4f\n", n, g, la.size(),
                100.0 * worst, -slope);
    EXPECT_NEAR(-slope, 0.5, 0.01);
    EXPECT_NEAR(std::exp(intercept), s0, 0.02 * s0);
    // At steady state the sediment that leaves is all the rock uplifted: U × the non-outlet area per year.
    double inner = 0.0;
    for (std::size_t i = 0; i < hh.size(); ++i)
        if (!f.is_outlet(std::int64_t(i))) inner += cell * cell;
    if (g > 0.0) EXPECT_NEAR(model.sediment_out(), U * 2e5 * inner, 1e-3 * U * 2e5 * inner);
}

INSTANTIATE_TEST_SUITE_P(StreamPower, DepositionSteadyState,
                         ::testing::Values(DepositionCase{1.0, 1e-5, 0.0}, DepositionCase{1.0, 1e-5, 1.0},
                                           DepositionCase{2.0, 1e-7, 1.0}, DepositionCase{0.7, 3e-5, 1.0},
                                           DepositionCase{1.0, 1e-5, 1.0, 1.1}),
                         [](const auto& info) {
                             return "n" + std::to_string(int(info.param.n * 10)) + "_G" +
                                 std::to_string(int(info.param.g)) + (info.param.mfd > 0.0 ? "_mfd" : "");
                         });

TEST(Deposition, EachCellSolvesItsEquationAndTheSedimentBalances) {
    // One step on noise (lakes left as they are, so the heights before the solve are h + U dt):
    // every cell must satisfy h* − h' = E − G·V/A with E = K dt A^m ((h' − h'_r)/L)^n and V the
    // net lowering × cell² summed over the cell and its donors (computed here, from the output);
    // and eroded − deposited volume = what the model says left through the outlets.
    for (double n : {1.0, 2.0, 0.7}) {
        for (double g : {0.5, 3.0}) {
            const int w = 97, hgt = 83;
            const double cell = 40.0, U = 2e-3, dt = 2e4;
            Settings s;
            s.erodibility = n == 1.0 ? 2e-5 : n == 2.0 ? 4e-7 : 5e-5;
            s.area_exponent = 0.45 * n;
            s.slope_exponent = n;
            s.diffusivity = 0.0;
            s.deposition = g;
            s.depressions = Depressions::route;
            s.open = {true, true, false, true};
            auto h0 = noise(w, hgt, 9, 300.0);
            for (int y = 0; y < hgt; ++y)
                for (int x = 0; x < w; ++x) h0[std::size_t(y) * w + x] += 2.0 * y;  // a tilt: long rivers north
            Model model(w, hgt, cell, h0, std::vector<double>(h0.size(), U), s);
            model.step(dt);
            const auto& f = model.flow();
            const auto& hn = model.heights();
            std::vector<double> hs(h0.size());
            for (std::size_t i = 0; i < h0.size(); ++i) hs[i] = f.is_outlet(std::int64_t(i)) ? h0[i] : h0[i] + U * dt;
            // V and the tree's area, upstream first.
            std::vector<double> V(h0.size(), 0.0), A(h0.size(), cell * cell);
            const auto& st = f.stack();
            const auto& rv = f.receivers();
            for (std::size_t k = st.size(); k-- > 0;) {
                const std::size_t i = std::size_t(st[k]), r = std::size_t(rv[i]);
                if (r == i) continue;
                V[i] += cell * cell * (hs[i] - hn[i]);
                V[r] += V[i];
                A[r] += A[i];
            }
            double eroded = 0.0, deposited = 0.0, worst = 0.0, out = 0.0;
            int deposits = 0;
            for (std::size_t i = 0; i < h0.size(); ++i) {
                const std::size_t r = std::size_t(rv[i]);
                if (r == i) {
                    out += V[i];  // what flowed into the outlet
                    continue;
                }
                const double x = hn[i] - hn[r];
                const bool incises = x > 0.0;  // a cell incises if it ends above its receiver
                const double E = incises ? s.erodibility * dt * std::pow(f.area()[i], s.area_exponent) *
                        std::pow(x / f.distance(std::int64_t(i)), n)
                                         : 0.0;
                const double Dep = g * V[i] / A[i];
                const double res = std::abs((hs[i] - hn[i]) - (E - Dep)) / (1.0 + std::abs(hs[i]));
                worst = std::max(worst, res);
                eroded += cell * cell * E;
                deposited += cell * cell * Dep;
                deposits += Dep > 1e-6;
            }
            EXPECT_LT(worst, 1e-10) << "n = " << n << ", G = " << g << ": largest residual of a cell's equation";
            std::printf(
                "n = %g, G = %g: residual %.2g, eroded %.4g m3, deposited %.4g m3, out %.4g m3, balance %.2g m3\n", n,
                g, worst, eroded, deposited, model.sediment_out(), eroded - deposited - model.sediment_out());
            EXPECT_GT(deposits, 1000);
            EXPECT_GT(deposited, 0.05 * eroded);
            EXPECT_NEAR(eroded - deposited, model.sediment_out(), 1e-9 * eroded) << "n = " << n << ", G = " << g;
            EXPECT_NEAR(out, model.sediment_out(), 1e-9 * eroded);
        }
    }
}

TEST(Deposition, AVanishingCoefficientIsTheDetachmentLimitedSolver) {
    // G → 0: the two-pass solver must give the old one's heights (to its tolerance).
    for (double n : {1.0, 2.0}) {
        const int w = 70, h = 60;
        Settings s;
        s.erodibility = n == 1.0 ? 2e-5 : 4e-7;
        s.slope_exponent = n;
        s.diffusivity = 0.01;
        Model a(w, h, 30.0, noise(w, h, 3, 100.0), noise(w, h, 4, 2e-3), s);
        s.deposition = 1e-13;
        Model b(w, h, 30.0, noise(w, h, 3, 100.0), noise(w, h, 4, 2e-3), s);
        a.run(1e5, 1e4);
        b.run(1e5, 1e4);
        for (std::size_t i = 0; i < a.heights().size(); ++i)
            ASSERT_NEAR(a.heights()[i], b.heights()[i], 1e-7) << "n = " << n << ", cell " << i;
    }
}

// ------------------------------------------------------------ uplift from a history

/// A three-frame history on the grid: frame 0 flat, then `first` m gained by the first interval
/// and `second` by the second, in a bump at the centre.
UpliftHistory bump_history(int w, int h, double years, double first, double second) {
    auto bump = [w, h](double metres) {
        std::vector<double> v(std::size_t(w) * h);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const double r2 = std::pow(x - 0.5 * w, 2) + std::pow(y - 0.5 * h, 2);
                v[std::size_t(y) * w + x] = metres * std::exp(-r2 / (0.08 * w * h));
            }
        return v;
    };
    UpliftHistory u;
    u.times = {0.0, 0.5 * years, years};
    u.rate = [=](std::size_t k) {
        auto r = bump(k == 0 ? first : second);
        for (double& v : r) v /= 0.5 * years;
        return r;
    };
    return u;
}

TEST(UpliftHistory, EachIntervalUpliftsByItsOwnFrames) {
    // K = 0: the heights are the start plus the integral of the rate; at mid-run a history that
    // uplifts only in its first half has given all its metres, one that uplifts only in its second
    // half none. dt = 3e4 does not divide the half (1e5): steps straddle the frame time.
    const int w = 60, h = 50;
    const double years = 2e5, dt = 3e4;
    Settings s;
    s.erodibility = 0.0;
    s.diffusivity = 0.0;
    s.depressions = Depressions::route;  // lakes keep their heights: only the uplift changes them
    const auto start = noise(w, h, 2, 5.0);
    const UpliftHistory early = bump_history(w, h, years, 400.0, 0.0);
    for (int which = 0; which < 2; ++which) {
        Model model(w, h, 30.0, start, {}, s);
        model.set_uplift_history(which == 0 ? bump_history(w, h, years, 400.0, 0.0)
                                            : bump_history(w, h, years, 0.0, 400.0));
        model.run(1e5, dt);  // the first half
        const auto mid = model.heights();
        model.run(1e5, dt);  // the second half
        const auto gain = early.rate(0);
        for (std::size_t i = 0; i < start.size(); ++i) {
            if (model.flow().is_outlet(std::int64_t(i))) {
                ASSERT_EQ(model.heights()[i], start[i]);
                continue;
            }
            const double total = gain[i] * 1e5;  // the bump's metres at this cell
            ASSERT_NEAR(model.heights()[i], start[i] + total, 1e-9 * (1.0 + total)) << i;
            ASSERT_NEAR(mid[i], start[i] + (which == 0 ? total : 0.0), 1e-9 * (1.0 + total)) << which << ", " << i;
        }
    }
}

TEST(UpliftHistory, WhenTheUpliftComesChangesTheLandscape) {
    // With incision the same 400 m give different ranges: uplifted early, the rivers have had the
    // second half to cut it down; uplifted late, the bump stands higher at the end.
    const int w = 60, h = 50;
    const double years = 2e6;
    Settings s;
    s.erodibility = 1e-5;
    s.deposition = 1.0;
    double mean[2];
    for (int which = 0; which < 2; ++which) {
        Model model(w, h, 30.0, noise(w, h, 2, 5.0), {}, s);
        model.set_uplift_history(which == 0 ? bump_history(w, h, years, 400.0, 0.0)
                                            : bump_history(w, h, years, 0.0, 400.0));
        model.run(years, 2e4);
        mean[which] = std::accumulate(model.heights().begin(), model.heights().end(), 0.0) / double(w * h);
    }
    std::printf("mean height after 2 Myr: uplifted early %.2f m, late %.2f m\n", mean[0], mean[1]);
    EXPECT_GT(mean[1], 1.5 * mean[0]) << "early " << mean[0] << " m, late " << mean[1] << " m";
}

TEST(StreamPower, SameBitsOnOneAndTwoThreadsWithDepositionAndAnUpliftHistory) {
    const int w = 161, h = 129;
    std::vector<double> results[2];
    double out[2];
    for (int t = 0; t < 2; ++t) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(t + 1));
        for (double n : {1.0, 2.0}) {
            Settings s;
            s.diffusivity = 0.02;
            s.deposition = 1.5;
            s.slope_exponent = n;
            s.erodibility = n == 1.0 ? 2e-5 : 4e-7;
            s.open = {true, true, false, true};
            Model model(w, h, 30.0, noise(w, h, 5, 200.0), noise(w, h, 77, 2e-3), s);
            model.set_uplift_history(bump_history(w, h, 2e5, 100.0, 50.0));
            model.run(2e5, 1e4);
            if (n == 1.0) {
                results[t] = model.heights();
                out[t] = model.sediment_out();
            } else {
                results[t].insert(results[t].end(), model.heights().begin(), model.heights().end());
            }
        }
    }
    EXPECT_EQ(0, std::memcmp(results[0].data(), results[1].data(), results[0].size() * sizeof(double)));
    EXPECT_EQ(0, std::memcmp(&out[0], &out[1], sizeof(double)));
}

namespace {

/// A ridge along the y axis, `relief` metres high in the middle column, falling linearly to both sides.
std::vector<double> ridge(int w, int h, double relief, std::uint64_t seed) {
    auto v = noise(w, h, seed, 1.0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            v[std::size_t(y) * w + x] += relief * (1.0 - std::abs(x - (w - 1) / 2.0) / ((w - 1) / 2.0));
    return v;
}

Settings westerly_rain() {
    Settings s;
    s.orographic_rain = true;
    s.rain.wind_from = 270.0;
    s.rain_resolution = 1.0;  // the model's own grid
    return s;
}

}  // namespace

TEST(OrographicRainInTheModel, EachCellAddsItsRainOverTheBackgroundToTheDrainageArea) {
    // A plane falling south, water leaving by the south side: every column is one river, and a cell's
    // drainage area is cell² times the sum of rain/background over the cells above it in its column.
    const int w = 40, h = 30;
    const double cell = 250.0;
    std::vector<double> plane(std::size_t(w) * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) plane[std::size_t(y) * w + x] = 3000.0 - 50.0 * y + 3.0 * std::sin(0.3 * x);
    Settings s = westerly_rain();
    s.rain.wind_from = 0.0;  // a northerly, down the slope: wet in the north, drier further down
    s.rain.background = 0.8;
    s.open = {false, false, true, false};
    Model model(w, h, cell, plane, {}, s);
    model.route_only();
    const auto rain = model.rain();
    const auto& area = model.flow().area();
    ASSERT_EQ(rain.size(), plane.size());
    double low = 1e9, high = 0.0;
    for (int x = 0; x < w; ++x) {
        double sum = 0.0;
        for (int y = 0; y < h; ++y) {
            const std::size_t i = std::size_t(y) * w + x;
            low = std::min(low, rain[i]);
            high = std::max(high, rain[i]);
            sum += rain[i] / 0.8;
            if (y < h - 1) ASSERT_NEAR(area[i], sum * cell * cell, 1e-9 * sum * cell * cell) << x << ", " << y;
        }
    }
    EXPECT_GT(high, 1.5 * low) << "the rain varies over the map, so the weights are tested";
}

TEST(OrographicRainInTheModel, TheWindwardSideErodesFasterAndTheDivideMovesDownwind) {
    // A ridge between two open sides, uplifted evenly. Under uniform rain it stays symmetric; under a
    // westerly the wet western flank erodes faster, so the west stands lower and the main divide
    // migrates east, into the rain shadow (as in the Southern Alps or the Olympics).
    const int w = 121, h = 41;
    const double cell = 250.0;
    auto mean_divide = [&](const std::vector<double>& z) {
        double sum = 0.0;
        for (int y = 0; y < h; ++y) {
            int best = 0;
            for (int x = 1; x < w; ++x)
                if (z[std::size_t(y) * w + x] > z[std::size_t(y) * w + best]) best = x;
            sum += best;
        }
        return sum / h;
    };
    auto half_mean = [&](const std::vector<double>& z, bool west) {
        double sum = 0.0;
        for (int y = 0; y < h; ++y)
            for (int x = west ? 0 : w / 2 + 1; x < (west ? w / 2 : w); ++x) sum += z[std::size_t(y) * w + x];
        return sum / (double(h) * (w / 2));
    };
    double divide[2], west[2], east[2];
    for (int orographic = 0; orographic < 2; ++orographic) {
        Settings s = westerly_rain();
        s.orographic_rain = orographic == 1;
        s.rain.background = 0.5;
        s.rain.wind_share = 0.5;  // the moist wind half the year: a clear rain shadow
        s.open = {false, true, false, true};
        s.diffusivity = 0.01;
        Model model(w, h, cell, ridge(w, h, 1500.0, 9), std::vector<double>(std::size_t(w) * h, 1e-3), s);
        model.run(2e6, 5e4);
        divide[orographic] = mean_divide(model.heights());
        west[orographic] = half_mean(model.heights(), true);
        east[orographic] = half_mean(model.heights(), false);
    }
    EXPECT_NEAR(divide[0], (w - 1) / 2.0, 4.0) << "uniform rain: the divide stays in the middle";
    EXPECT_NEAR(west[0], east[0], 0.1 * east[0]);
    EXPECT_GT(divide[1], divide[0] + 5.0) << "the divide moves east, downwind";
    EXPECT_LT(west[1], 0.85 * east[1]) << "the wet west stands lower than the dry east";
}

TEST(OrographicRainInTheModel, SameBitsOnOneAndTwoThreads) {
    const int w = 97, h = 81;
    std::vector<double> results[2];
    for (int t = 0; t < 2; ++t) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(t + 1));
        Settings s = westerly_rain();
        s.rain.wind_from = 230.0;
        s.rain_resolution = 120.0;  // 4 cells a block: the coarse path
        s.diffusivity = 0.02;
        Model model(w, h, 30.0, ridge(w, h, 800.0, 4), std::vector<double>(std::size_t(w) * h, 1e-3), s);
        model.run(2e5, 2e4);
        results[t] = model.heights();
        for (double r : model.rain()) results[t].push_back(r);
    }
    EXPECT_EQ(0, std::memcmp(results[0].data(), results[1].data(), results[0].size() * sizeof(double)));
}

TEST(UpliftEdgeTaper, TheUpliftFallsSmoothlyToTheOpenSidesOnly) {
    // 101 × 51 vertices 30 m apart, open west and south, a 600 m (20-cell) taper.
    const OpenSides open{false, false, true, true};  // north, east, south, west
    auto at = [&](int x, int y) { return edge_taper(x, y, 101, 51, 30.0, open, 600.0); };
    EXPECT_EQ(at(0, 20), 0.0);  // on the west side
    EXPECT_EQ(at(40, 50), 0.0);  // on the south side
    EXPECT_EQ(at(50, 20), 1.0);  // further than the taper from both
    EXPECT_EQ(at(100, 0), 1.0);  // the north-east corner: closed sides keep their uplift
    EXPECT_DOUBLE_EQ(at(10, 20), 0.5);  // halfway: smoothstep(1/2)
    EXPECT_DOUBLE_EQ(at(5, 20), 0.25 * 0.25 * 2.5);  // smoothstep(1/4) = 5/32
    EXPECT_DOUBLE_EQ(at(30, 45), at(5, 20));  // 5 cells from the south side, the nearer
    for (int x = 0; x < 20; ++x) EXPECT_LT(at(x, 20), at(x + 1, 20)) << x;  // rising...
    EXPECT_EQ(edge_taper(0, 0, 101, 51, 30.0, open, 0.0), 1.0);  // ...and no taper: everything
    EXPECT_EQ(edge_taper(0, 0, 101, 51, 30.0, OpenSides{false, false, false, false}, 600.0), 1.0);
}
