// Tests of bank erosion (banks.hpp): the pushes a river gives its banks on
// hand-made windows with known answers (straight on, at 45° and 90° bends,
// the main donor, a diagonal river), the floor a bank stops at, outlets; and in the model, that
// rivers grow valley floors and give the same bits on one and two threads.
#include <orogen/landscape/banks.hpp>
#include <orogen/landscape/floodplain.hpp>
#include <orogen/landscape/flow.hpp>
#include "noise_terrain.hpp"
#include <orogen/landscape/stream_power.hpp>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstring>
#include <numbers>
#include <vector>

namespace {

using namespace orogen;
using namespace orogen::landscape;

constexpr int kW = 5, kH = 5;
std::size_t at(int x, int y) { return std::size_t(y) * kW + std::size_t(x); }

struct Window {
    std::vector<std::int8_t> dir = std::vector<std::int8_t>(kW * kH, -1);
    std::vector<double> area = std::vector<double>(kW * kH, 900.0);
    std::vector<double> incised = std::vector<double>(kW * kH, 0.0);
    std::vector<double> heights = std::vector<double>(kW * kH, 100.0);
    std::vector<double> right, left, scratch;
    BankWindow w{kW, kH, 0, 0, kW, kH};
};

/// A river along row 2 flowing east, lowered by 2 m, draining far more than A_b; its last cell a root.
Window straight_river() {
    Window v;
    for (int x = 0; x < kW; ++x) {
        v.dir[at(x, 2)] = x + 1 < kW ? 0 : -1;
        v.area[at(x, 2)] = 1e9;
        v.incised[at(x, 2)] = 2.0;
        v.heights[at(x, 2)] = 0.0;
    }
    return v;
}

TEST(Onset, OneMinusExpWithinItsBoundEverywhereAndOneBeyondReach) {
    // onset(x) = 1 − e^(−x) to within (2^−12)²/8 = 7.5e-9 (linear between exact values); the worst error
    // lies between nodes where the curvature is largest (near 0); 1 exactly from 38 on; never decreasing.
    double worst = 0.0, last = 0.0;
    for (double x = 0.0; x < 45.0; x += 0.000137) {
        const double v = onset(x), exact = -std::expm1(-x);
        worst = std::max(worst, std::abs(v - exact));
        ASSERT_GE(v, last) << "x " << x;
        last = v;
    }
    EXPECT_LT(worst, 7.5e-9);
    EXPECT_GT(worst, 1e-9) << "interpolated, not exact: the bound is what the test checks";
    EXPECT_EQ(onset(38.0), 1.0);
    EXPECT_EQ(onset(1e300), 1.0);
    EXPECT_EQ(onset(0.0), 0.0);
    EXPECT_EQ(onset(0.5), -std::expm1(-0.5)) << "a node is the exact value";
    EXPECT_TRUE(std::isnan(onset(std::nan(""))));
    // The banks' factor: whole cells from its own table (exact), other areas through onset.
    Banks banks;
    banks.erosion = 4.0;
    banks.area = 3e4;
    const BankAreaFactor factor(banks, 30.0);
    EXPECT_EQ(factor(900.0 * 7), -std::expm1(-7.0 * 900.0 * (1.0 / 3e4)));
    EXPECT_NEAR(factor(900.0 * 7.3), -std::expm1(-900.0 * 7.3 / 3e4), 7.5e-9);
}

TEST(Banks, AStraightRiverLowersEachBankByHalfItsShare) {
    Window v = straight_river();
    Banks b;
    b.erosion = 3.0;
    b.area = 1e4;
    bank_pushes(b, BankAreaFactor(b, 30.0), v.w, v.dir.data(), v.area.data(), v.incised.data(), v.right, v.left);
    // Flowing east (code 0) the right bank is south (code 2), the left north (code 6): κ·e/2 each.
    EXPECT_DOUBLE_EQ(v.right[at(1, 2)], 3.0);
    EXPECT_DOUBLE_EQ(v.left[at(1, 2)], 3.0);
    EXPECT_EQ(v.right[at(4, 2)], 0.0);  // the root drains nowhere: no push
    const double removed = lower_banks(b, v.w, {v.dir.data(), v.area.data(), nullptr}, {v.right.data(), v.left.data()},
                                       30.0, v.heights.data(), v.scratch);
    for (int x = 0; x < kW; ++x) {
        const double bank = x + 1 < kW ? 97.0 : 100.0;  // beside the root nothing pushes
        EXPECT_DOUBLE_EQ(v.heights[at(x, 1)], bank) << x;
        EXPECT_DOUBLE_EQ(v.heights[at(x, 3)], bank) << x;
        EXPECT_DOUBLE_EQ(v.heights[at(x, 0)], 100.0) << x;  // only the banks themselves
        EXPECT_DOUBLE_EQ(v.heights[at(x, 2)], 0.0) << x;  // the river is the incision's
    }
    EXPECT_DOUBLE_EQ(removed, 8 * 3.0 * 900.0);
}

TEST(Banks, ASmallStreamBarelyPushes) {
    Window v = straight_river();
    for (int x = 0; x < kW; ++x) v.area[at(x, 2)] = 1e3;
    Banks b;
    b.erosion = 3.0;
    b.area = 1e5;
    bank_pushes(b, BankAreaFactor(b, 30.0), v.w, v.dir.data(), v.area.data(), v.incised.data(), v.right, v.left);
    // 1e3 m² is not a whole number of 30 m cells: the factor comes from onset(), within 7.5e-9.
    EXPECT_NEAR(v.right[at(1, 2)], 3.0 * -std::expm1(-1e3 / 1e5), 3.0 * 7.5e-9);
}

TEST(Banks, ABankStopsAboveItsRiverAtTheFloorSlopeAndOutletsStay) {
    Window v = straight_river();
    v.heights[at(1, 1)] = 4.0;  // 4 m above the river, pushed 3 m: would end 1 m above it
    v.heights[at(2, 1)] = 2.0;  // below the floor already: stays
    v.heights[at(3, 1)] = 50.0;
    Banks b;
    b.erosion = 100.0;  // 100 m per bank: every bank reaches its floor
    b.area = 1e4;
    b.floor_slope = 0.1;  // 3 m above the river over one 30 m cell
    bank_pushes(b, BankAreaFactor(b, 30.0), v.w, v.dir.data(), v.area.data(), v.incised.data(), v.right, v.left);
    std::vector<std::uint8_t> outlet(kW * kH, 0);
    outlet[at(0, 3)] = 1;
    lower_banks(b, v.w, {v.dir.data(), v.area.data(), outlet.data()}, {v.right.data(), v.left.data()}, 30.0,
                v.heights.data(), v.scratch);
    EXPECT_DOUBLE_EQ(v.heights[at(1, 1)], 3.0);
    EXPECT_DOUBLE_EQ(v.heights[at(2, 1)], 2.0);
    EXPECT_DOUBLE_EQ(v.heights[at(3, 1)], 3.0);
    EXPECT_DOUBLE_EQ(v.heights[at(0, 3)], 100.0);  // an outlet
    EXPECT_DOUBLE_EQ(v.heights[at(1, 3)], 3.0);
}

/// A river coming into the centre from its donor at direction code `from` (the donor's own flow
/// direction is `from`) and leaving east; a second, smaller donor from the west.
Window bend(int from) {
    Window v;
    const int cx = 2, cy = 2;
    v.dir[at(cx, cy)] = 0;
    v.area[at(cx, cy)] = 1e9;
    v.incised[at(cx, cy)] = 1.0;
    const int dx = cx - kDx[from], dy = cy - kDy[from];
    v.dir[at(dx, dy)] = std::int8_t(from);
    v.area[at(dx, dy)] = 5e8;
    if (from != 0) {  // a smaller tributary from the west, running straight on: it must not decide the bend
        v.dir[at(cx - 1, cy)] = 0;
        v.area[at(cx - 1, cy)] = 1e8;
    }
    return v;
}

TEST(Banks, AtABendTheOuterBankTakesMore) {
    Banks b;
    b.erosion = 1.0;
    b.area = 1e4;
    {  // from the north (flowing south, code 2), turning east: 90°, the south bank (right) takes it all
        Window v = bend(2);
        bank_pushes(b, BankAreaFactor(b, 30.0), v.w, v.dir.data(), v.area.data(), v.incised.data(), v.right, v.left);
        EXPECT_DOUBLE_EQ(v.right[at(2, 2)], 1.0);
        EXPECT_DOUBLE_EQ(v.left[at(2, 2)], 0.0);
    }
    {  // from the north-east... flowing south-west (code 3), turning east: 135°, still all on the south bank
        Window v = bend(3);
        bank_pushes(b, BankAreaFactor(b, 30.0), v.w, v.dir.data(), v.area.data(), v.incised.data(), v.right, v.left);
        EXPECT_DOUBLE_EQ(v.right[at(2, 2)], 1.0);
        EXPECT_DOUBLE_EQ(v.left[at(2, 2)], 0.0);
    }
    {  // from the north-west, flowing south-east (code 1): 45°, three quarters on the south bank
        Window v = bend(1);
        bank_pushes(b, BankAreaFactor(b, 30.0), v.w, v.dir.data(), v.area.data(), v.incised.data(), v.right, v.left);
        EXPECT_DOUBLE_EQ(v.right[at(2, 2)], 0.75);
        EXPECT_DOUBLE_EQ(v.left[at(2, 2)], 0.25);
    }
    {  // from the south-west, flowing north-east (code 7): 45° the other way, three quarters on the north bank
        Window v = bend(7);
        bank_pushes(b, BankAreaFactor(b, 30.0), v.w, v.dir.data(), v.area.data(), v.incised.data(), v.right, v.left);
        EXPECT_DOUBLE_EQ(v.right[at(2, 2)], 0.25);
        EXPECT_DOUBLE_EQ(v.left[at(2, 2)], 0.75);
    }
    {  // straight on from the west: half each
        Window v = bend(0);
        bank_pushes(b, BankAreaFactor(b, 30.0), v.w, v.dir.data(), v.area.data(), v.incised.data(), v.right, v.left);
        EXPECT_DOUBLE_EQ(v.right[at(2, 2)], 0.5);
        EXPECT_DOUBLE_EQ(v.left[at(2, 2)], 0.5);
    }
}

TEST(Banks, ADiagonalRiverPushesHalfOnEachEdgeNeighbourFlankingIt) {
    Window v;
    v.dir[at(2, 2)] = 1;  // flowing south-east: right south and west, left north and east
    v.area[at(2, 2)] = 1e9;
    v.incised[at(2, 2)] = 2.0;
    v.heights[at(2, 2)] = 0.0;
    Banks b;
    b.erosion = 4.0;  // 4 m a side, 2 m on each flanking cell
    b.area = 1e4;
    bank_pushes(b, BankAreaFactor(b, 30.0), v.w, v.dir.data(), v.area.data(), v.incised.data(), v.right, v.left);
    lower_banks(b, v.w, {v.dir.data(), v.area.data(), nullptr}, {v.right.data(), v.left.data()}, 30.0, v.heights.data(),
                v.scratch);
    for (int k = 0; k < 8; k += 2) EXPECT_DOUBLE_EQ(v.heights[at(2 + kDx[k], 2 + kDy[k])], 98.0) << k;
    // The diagonal neighbours lie √2 cells off the river's line (the receiver and the donor on it): untouched.
    for (int k = 1; k < 8; k += 2) EXPECT_DOUBLE_EQ(v.heights[at(2 + kDx[k], 2 + kDy[k])], 100.0) << k;
    // Far enough, every flanking cell stops one cell's floor slope above the river.
    b.erosion = 400.0;
    b.floor_slope = 0.1;
    bank_pushes(b, BankAreaFactor(b, 30.0), v.w, v.dir.data(), v.area.data(), v.incised.data(), v.right, v.left);
    lower_banks(b, v.w, {v.dir.data(), v.area.data(), nullptr}, {v.right.data(), v.left.data()}, 30.0, v.heights.data(),
                v.scratch);
    for (int k = 0; k < 8; k += 2) EXPECT_DOUBLE_EQ(v.heights[at(2 + kDx[k], 2 + kDy[k])], 3.0) << k;
}

/// The straight river with each bank already at its floor (3 m above the river: floor slope 0.1 over
/// 30 m), the rows beyond 50 m up; then the three passes with a relay for rivers over `wide_area`.
Window wide_river(double erosion, double wide_area, double bank = 3.0) {
    Window v = straight_river();
    for (int x = 0; x < kW; ++x) {
        v.heights[at(x, 1)] = v.heights[at(x, 3)] = bank;
        v.heights[at(x, 0)] = v.heights[at(x, 4)] = 50.0;
    }
    Banks b;
    b.erosion = erosion;
    b.area = 1e4;
    b.floor_slope = 0.1;
    b.wide_area = wide_area;
    bank_pushes(b, BankAreaFactor(b, 30.0), v.w, v.dir.data(), v.area.data(), v.incised.data(), v.right, v.left);
    BankRelay relay;
    lower_banks(b, v.w, {v.dir.data(), v.area.data(), nullptr}, {v.right.data(), v.left.data()}, 30.0, v.heights.data(),
                v.scratch, &relay);
    if (b.wide()) lower_relayed(b, v.w, relay, nullptr, 30.0, v.heights.data());
    return v;
}

TEST(Banks, ALargeRiverPushesOnPastABankAtItsFloor) {
    // κ = 1, lowered 2 m: 1 m on each side. The banks cannot go lower; the cells beyond take the push.
    Window v = wide_river(1.0, 1e6);
    for (int x = 0; x + 1 < kW; ++x) {
        EXPECT_DOUBLE_EQ(v.heights[at(x, 1)], 3.0) << x;
        EXPECT_DOUBLE_EQ(v.heights[at(x, 3)], 3.0) << x;
        EXPECT_DOUBLE_EQ(v.heights[at(x, 0)], 49.0) << x;
        EXPECT_DOUBLE_EQ(v.heights[at(x, 4)], 49.0) << x;
    }
    EXPECT_DOUBLE_EQ(v.heights[at(4, 0)], 50.0);  // beside the root nothing pushes
    // A strong push stops at the river plus the floor slope over two cells.
    v = wide_river(100.0, 1e6);
    EXPECT_DOUBLE_EQ(v.heights[at(1, 0)], 6.0);
    EXPECT_DOUBLE_EQ(v.heights[at(1, 4)], 6.0);
}

TEST(Banks, OnlyLargeRiversAndBanksDownToTheirFloorPushOn) {
    Window v = wide_river(1.0, 2e9);  // the river drains 1e9 m²: too small to widen
    EXPECT_DOUBLE_EQ(v.heights[at(1, 0)], 50.0);
    v = wide_river(1.0, 0.0);  // no relay at all
    EXPECT_DOUBLE_EQ(v.heights[at(1, 0)], 50.0);
    v = wide_river(1.0, 1e6, 3.4);  // a bank 0.4 m above its floor (within half a metre) counts as down
    EXPECT_DOUBLE_EQ(v.heights[at(1, 1)], 3.0);
    EXPECT_DOUBLE_EQ(v.heights[at(1, 0)], 49.0);
    v = wide_river(1.0, 1e6, 10.0);  // a bank well above it still shields the cell beyond
    EXPECT_DOUBLE_EQ(v.heights[at(1, 1)], 9.0);
    EXPECT_DOUBLE_EQ(v.heights[at(1, 0)], 50.0);
}

TEST(Banks, ADiagonalRiverPushesOnAcrossItsFlowAndOutletsStay) {
    // A river down the diagonal, flowing south-east (code 1), its cells 0 m; all else 100 m but the cells
    // straight across it from its centre, (1, 3) and (3, 1), down to their floor (0.1·30·√2 m).
    Window v;
    for (int k = 0; k < kW; ++k) {
        v.dir[at(k, k)] = k + 1 < kW ? 1 : -1;
        v.area[at(k, k)] = 1e9;
        v.incised[at(k, k)] = 2.0;
        v.heights[at(k, k)] = 0.0;
    }
    const double rise = 0.1 * 30.0 * std::sqrt(2.0);
    v.heights[at(1, 3)] = v.heights[at(3, 1)] = rise;
    Banks b;
    b.erosion = 1.0;
    b.area = 1e4;
    b.floor_slope = 0.1;
    b.wide_area = 1e6;
    bank_pushes(b, BankAreaFactor(b, 30.0), v.w, v.dir.data(), v.area.data(), v.incised.data(), v.right, v.left);
    BankRelay relay;
    std::vector<std::uint8_t> outlet(kW * kH, 0);
    outlet[at(4, 0)] = 1;
    lower_banks(b, v.w, {v.dir.data(), v.area.data(), outlet.data()}, {v.right.data(), v.left.data()}, 30.0,
                v.heights.data(), v.scratch, &relay);
    EXPECT_EQ(relay.out[at(1, 3)], 3);  // on the river's right, onward to the south-west
    EXPECT_EQ(relay.out[at(3, 1)], 7);  // on its left, onward to the north-east
    EXPECT_DOUBLE_EQ(relay.push[at(1, 3)], 1.0);  // the river's whole push on that side
    EXPECT_DOUBLE_EQ(relay.floor[at(1, 3)], 2.0 * rise);
    lower_relayed(b, v.w, relay, outlet.data(), 30.0, v.heights.data());
    EXPECT_DOUBLE_EQ(v.heights[at(0, 4)], 99.0);
    EXPECT_DOUBLE_EQ(v.heights[at(4, 0)], 100.0);  // an outlet
}

using test::noise;

/// Mean height of the two cells `reach` cells across each river (A ≥ 40 cells, flowing along an axis)
/// above the river.
double mean_bank_rise(const Model& model, int w, int h, int reach = 1) {
    double sum = 0.0;
    int count = 0;
    for (int y = reach; y + reach < h; ++y)
        for (int x = reach; x + reach < w; ++x) {
            const std::int64_t i = std::int64_t(y) * w + x;
            if (model.flow().area()[std::size_t(i)] < 40 * 900.0) continue;
            const int d = model.flow().direction(i);
            if (d != 0 && d != 2 && d != 4 && d != 6) continue;
            const std::int64_t a = i + reach * (kDy[(d + 2) % 8] * w + kDx[(d + 2) % 8]);
            const std::int64_t c = i + reach * (kDy[(d + 6) % 8] * w + kDx[(d + 6) % 8]);
            sum += 0.5 * (model.heights()[std::size_t(a)] + model.heights()[std::size_t(c)]) -
                model.heights()[std::size_t(i)];
            ++count;
        }
    return count ? sum / count : 0.0;
}

constexpr int kValleyW = 129, kValleyH = 97;

/// Rivers cutting a noisy surface whose walls landslides hold at 35° (without banks: V notches), with
/// banks at κ = 4 from 1e4 m², 1° floors, when `banks`.
Settings valley_settings(bool banks) {
    Settings s;
    s.erodibility = 2e-5;
    s.area_exponent = 0.5;
    s.diffusivity = 0.0;
    s.open = {true, true, false, false};
    s.rock.angle = 35.0 * M_PI / 180.0;
    s.banks.erosion = banks ? 4.0 : 0.0;
    s.banks.area = 1e4;
    s.banks.floor_slope = std::tan(1.0 * M_PI / 180.0);
    return s;
}

/// After 1.2 Myr, the mean rise `reach` cells across the rivers (mean_bank_rise).
double rise_after_run(const Settings& s, int reach) {
    Model model(kValleyW, kValleyH, 30.0, noise(kValleyW, kValleyH, 11, 50.0),
                std::vector<double>(std::size_t(kValleyW) * kValleyH, 1e-3), s);
    model.run(1.2e6, 2e4);
    model.route_only();
    return mean_bank_rise(model, kValleyW, kValleyH, reach);
}

/// 0.3 Myr on one thread and on two give the same bits.
void expect_the_same_bits_on_two_threads(const Settings& s) {
    std::vector<double> threads[2];
    for (int t = 0; t < 2; ++t) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(t + 1));
        Model model(kValleyW, kValleyH, 30.0, noise(kValleyW, kValleyH, 11, 50.0),
                    std::vector<double>(std::size_t(kValleyW) * kValleyH, 1e-3), s);
        model.run(3e5, 2e4);
        threads[t] = model.heights();
    }
    EXPECT_EQ(0, std::memcmp(threads[0].data(), threads[1].data(), threads[0].size() * sizeof(double)));
}

TEST(Banks, RiversGrowValleyFloorsAndTheBitsHoldOnTwoThreads) {
    const double without = rise_after_run(valley_settings(false), 1), with = rise_after_run(valley_settings(true), 1);
    // Without banks the cells across a river stand near the landslide angle above it (tan 35° × 30 m = 21 m);
    // with them the rivers keep a floor beside them.
    EXPECT_GT(without, 10.0) << with;
    EXPECT_LT(with, 0.3 * without);
    expect_the_same_bits_on_two_threads(valley_settings(true));
}

TEST(Banks, LargeRiversWidenTheirFloorsAndTheBitsHoldOnTwoThreads) {
    // The mean rise two cells across the rivers draining more than 40 cells.
    Settings s = valley_settings(true);
    const double three = rise_after_run(s, 2);
    s.banks.wide_area = 2e4;
    const double five = rise_after_run(s, 2);
    EXPECT_GT(three, 10.0) << five;  // three-cell floors: two cells out is the valley's side
    EXPECT_LT(five, 0.6 * three);  // 0.46 of it; 0.77 when the push goes astray
    expect_the_same_bits_on_two_threads(s);
}

TEST(Banks, TheLargestRiversWidenTheirFloorsOnceMore) {
    // The mean rise three cells across the rivers draining more than 40 cells, with floors five cells
    // wide, then seven where more than 3e4 m² drains.
    Settings s = valley_settings(true);
    s.banks.wide_area = 2e4;
    const double five = rise_after_run(s, 3);
    s.banks.wider_area = 3e4;
    const double seven = rise_after_run(s, 3);
    EXPECT_GT(five, 10.0) << seven;
    EXPECT_LT(seven, 0.75 * five);
    expect_the_same_bits_on_two_threads(s);
}

TEST(Banks, FloorsKeepWideningDownstreamToTheWidestAsked) {
    // The mean rise four cells across the rivers draining more than 40 cells: floors seven cells wide
    // (from 3e4 m²), then nine from 4.5e4 m² and eleven from 6.75e4 m² (the area growing by 3e4 / 2e4 a
    // step) with bank_widest_floor = 11.
    Settings s = valley_settings(true);
    s.banks.wide_area = 2e4;
    s.banks.wider_area = 3e4;
    const double seven = rise_after_run(s, 4);
    s.banks.widest_floor = 11;
    EXPECT_EQ(s.banks.onward_passes(), 3);
    EXPECT_DOUBLE_EQ(s.banks.onward_area(2), 4.5e4);
    const double eleven = rise_after_run(s, 4);
    EXPECT_GT(seven, 10.0) << eleven;
    EXPECT_LT(eleven, 0.75 * seven);
    expect_the_same_bits_on_two_threads(s);
}

// ------------------------------------------------------------- floodplains

/// A flat 21 × 11 grid 100 m high with a river along row 5 flowing east (code 0), falling 1 m a cell
/// from 50 m, each of its cells draining `area` m² (other cells: no receiver).
struct RiverRow {
    int w = 21, h = 11;
    std::vector<double> heights, area;
    std::vector<std::int8_t> dir;
    explicit RiverRow(double a)
        : heights(std::size_t(w) * h, 100.0), area(heights.size(), 900.0), dir(heights.size(), -1) {
        for (int x = 0; x < w; ++x) {
            const std::size_t i = std::size_t(5) * w + x;
            heights[i] = 50.0 - x;
            area[i] = a;
            dir[i] = x + 1 < w ? 0 : -1;
        }
    }
    double at(int x, int y) const { return heights[std::size_t(y) * w + x]; }
};

TEST(Floodplain, EveryWindowAndThreadCountStampsTheNearestRiverTiesToTheLowerIndex) {
    // 300 rivers with reaches up to 12 cells over a 70 × 90 grid, several at the same distance from
    // some cells: against a brute force over every river for every cell, on the whole grid (bands of
    // rows on two threads and on one) and on three windows that cut it as tiles would.
    const int w = 70, h = 90;
    std::vector<FloodplainSource> sources;
    std::uint64_t state = 12345;
    auto next = [&] { return (state = state * 6364136223846793005ULL + 1442695040888963407ULL) >> 33; };
    std::vector<std::int64_t> cells;
    for (int k = 0; k < 300; ++k) cells.push_back(std::int64_t(next() % std::uint64_t(w * h)));
    std::sort(cells.begin(), cells.end());
    cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
    for (const std::int64_t c : cells) sources.push_back({c, double(next() % 1000), double(next() % 1300) / 100.0});
    std::vector<double> want_near(std::size_t(w) * h, std::numeric_limits<double>::infinity()),
        want_floor(want_near.size());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (const FloodplainSource& s : sources) {
                const double d = std::hypot(double(x - s.index % w), double(y - s.index / w));
                const std::size_t j = std::size_t(y) * w + x;
                if (d <= s.reach && d < want_near[j]) {
                    want_near[j] = d;
                    want_floor[j] = s.height;
                }
            }
    for (const int threads : {2, 1}) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
        std::vector<double> nearest, floor;
        stamp_floodplains(sources, w, {0, 0, w, h}, nearest, floor);
        for (std::size_t j = 0; j < want_near.size(); ++j) {
            ASSERT_EQ(nearest[j], want_near[j]) << "cell " << j << " on " << threads << " threads";
            if (std::isfinite(want_near[j])) ASSERT_EQ(floor[j], want_floor[j]) << "cell " << j;
        }
        for (const FloodplainWindow win :
             {FloodplainWindow{0, 0, 35, 45}, FloodplainWindow{35, 0, 35, 90}, FloodplainWindow{0, 45, 35, 45}}) {
            stamp_floodplains(sources, w, win, nearest, floor);
            for (int y = 0; y < win.height; ++y)
                for (int x = 0; x < win.width; ++x) {
                    const std::size_t j = std::size_t(win.y0 + y) * w + std::size_t(win.x0 + x);
                    const std::size_t l = std::size_t(y) * std::size_t(win.width) + std::size_t(x);
                    ASSERT_EQ(nearest[l], want_near[j]) << "window cell " << x << "," << y;
                    if (std::isfinite(want_near[j])) ASSERT_EQ(floor[l], want_floor[j]);
                }
        }
    }
}

TEST(Floodplain, CellsWithinTheHalfWidthFallToTheirNearestRiverPlusTheSlope) {
    // Half-width 30 m · (4e6 / 1e6)^0.5 = 60 m: two cells of 30 m each side, rising 0.5 m a cell.
    RiverRow r(4e6);
    const Floodplain fp{1e6, 30.0, 0.5, 0.5 / 30.0};
    std::vector<double> nearest, floor;
    const double removed =
        carve_floodplains(fp, r.w, r.h, 30.0, {r.dir.data(), r.area.data(), nullptr}, r.heights.data(), nearest, floor);
    for (int x = 0; x + 1 < r.w; ++x) {  // the last cell is a root: its floodplain is none
        EXPECT_DOUBLE_EQ(r.at(x, 5), 50.0 - x) << "the river stays";
        for (int d : {1, 2}) {
            EXPECT_DOUBLE_EQ(r.at(x, 5 - d), 50.0 - x + 0.5 * d) << x << " " << d;
            EXPECT_DOUBLE_EQ(r.at(x, 5 + d), 50.0 - x + 0.5 * d) << x << " " << d;
        }
        EXPECT_DOUBLE_EQ(r.at(x, 2), 100.0) << "beyond the half-width";
    }
    EXPECT_GT(removed, 0.0);
    // A river draining less than floodplain_area has none.
    RiverRow small(0.9e6);
    carve_floodplains(fp, small.w, small.h, 30.0, {small.dir.data(), small.area.data(), nullptr}, small.heights.data(),
                      nearest, floor);
    EXPECT_DOUBLE_EQ(small.at(3, 4), 100.0);
}

TEST(Floodplain, OnlyReachesGentlerThanTheMaxSlopePlaneAFloor) {
    // The river falls 4 m a cell (13 %, a gorge) to x = 10, then 1 m a cell (3.3 %). With a max slope of
    // 3° (5.2 %) only the gentle reach planes a floor: two cells each side from x = 10 on, none along the
    // gorge beyond that reach (x ≤ 7). The cell at x = 10 drops 1 m to its receiver: gentle, its floor kept.
    RiverRow r(4e6);
    for (int x = 0; x < r.w; ++x) r.heights[std::size_t(5) * r.w + x] = x < 10 ? 70.0 - 4.0 * x : 40.0 - (x - 10);
    Floodplain fp{1e6, 30.0, 0.5, 0.5 / 30.0};
    fp.max_slope = std::tan(3.0 * std::numbers::pi / 180.0);
    std::vector<double> nearest, floor;
    carve_floodplains(fp, r.w, r.h, 30.0, {r.dir.data(), r.area.data(), nullptr}, r.heights.data(), nearest, floor);
    for (int x = 0; x <= 7; ++x)
        for (int y : {3, 4, 6, 7}) EXPECT_DOUBLE_EQ(r.at(x, y), 100.0) << "gorge: " << x << " " << y;
    for (int x = 10; x + 1 < r.w; ++x) {
        const double river = 40.0 - (x - 10);
        EXPECT_DOUBLE_EQ(r.at(x, 4), river + 0.5) << x;
        EXPECT_DOUBLE_EQ(r.at(x, 7), river + 1.0) << x;
    }
    // Without a max slope the gorge planes its floor too.
    RiverRow every(4e6);
    for (int x = 0; x < every.w; ++x)
        every.heights[std::size_t(5) * every.w + x] = x < 10 ? 70.0 - 4.0 * x : 40.0 - (x - 10);
    fp.max_slope = 0.0;
    carve_floodplains(fp, every.w, every.h, 30.0, {every.dir.data(), every.area.data(), nullptr}, every.heights.data(),
                      nearest, floor);
    EXPECT_DOUBLE_EQ(every.at(3, 4), 70.0 - 12.0 + 0.5);
}

TEST(Floodplain, TheNearestRiverSetsACellNotTheLowestAndOutletsStay) {
    // The river runs east along row 5, then back west along row 8 much lower (a meander's two arms, 3
    // cells apart). Row 6 is nearer the upper arm: it must stand above it (no cutoff), although the lower
    // arm's floodplain reaches it too.
    RiverRow r(9e6);  // half-width 90 m: three cells
    for (int x = 0; x < r.w; ++x) {
        const std::size_t i = std::size_t(8) * r.w + x;
        r.heights[i] = 10.0 + x;
        r.area[i] = 9e6;
        r.dir[i] = x > 0 ? 4 : -1;  // west
    }
    std::vector<std::uint8_t> outlet(r.heights.size(), 0);
    outlet[std::size_t(6) * r.w + 10] = 1;
    const Floodplain fp{1e6, 30.0, 0.5, 0.5 / 30.0};
    std::vector<double> nearest, floor;
    carve_floodplains(fp, r.w, r.h, 30.0, {r.dir.data(), r.area.data(), outlet.data()}, r.heights.data(), nearest,
                      floor);
    for (int x = 1; x + 1 < r.w; ++x) {
        if (x == 10) continue;
        EXPECT_DOUBLE_EQ(r.at(x, 6), 50.0 - x + 0.5) << x << ": the upper arm's floor, not the lower arm's";
        EXPECT_DOUBLE_EQ(r.at(x, 7), 10.0 + x + 0.5) << x << ": the lower arm's";
    }
    EXPECT_DOUBLE_EQ(r.at(10, 6), 100.0) << "an outlet stays";
}

TEST(Floodplain, LargeRiversKeepWideFloorsAndTheBitsHoldOnTwoThreads) {
    // The mean rise three cells across the rivers draining more than 40 cells, with floodplains from
    // 3.6e4 m² (40 cells) 30 m wide there, against the banks alone.
    Settings s = valley_settings(true);
    const double banks = rise_after_run(s, 3);
    s.floodplain = {3.6e4, 30.0, 0.5, std::tan(1.0 * M_PI / 180.0)};
    const double plains = rise_after_run(s, 3);
    EXPECT_GT(banks, 10.0) << plains;
    EXPECT_LT(plains, 0.5 * banks);
    expect_the_same_bits_on_two_threads(s);
}

}  // namespace
