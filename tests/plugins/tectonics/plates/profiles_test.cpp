// The boundary relief alone (profiles.hpp): rugged ranges, a narrow trench
// with separate arc volcanoes, rifts with stepped flanks and an axial ridge,
// saturation where contacts repeat, and that every shape stays near its
// segment.
#include "profiles.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>
#include <vector>

using namespace orogen;
using namespace orogen::plates;

namespace {

struct Field {
    int n;
    std::vector<float> z;
    float at(int x, int y) const { return z[std::size_t(y) * n + x]; }
};

Field compose(int n, const ReliefShape& shape, const std::function<void(BoundaryRelief&)>& add) {
    BoundaryRelief relief(n, n, shape, 1234);
    add(relief);
    return {n, relief.relief()};
}

ReliefShape shape_with_cell(double c) {
    ReliefShape s;
    s.cell = c;
    return s;
}

// Summits of a 1-D profile: samples highest within ±3 (the first of a flat
// top) with a drop of at least `prominence` within `reach` samples on both sides.
int prominent_maxima(const std::vector<double>& p, double prominence, int reach = 24) {
    const int n = int(p.size());
    int count = 0;
    for (int i = 0; i < n; ++i) {
        bool top = true;
        for (int k = std::max(0, i - 3); k <= std::min(n - 1, i + 3) && top; ++k)
            top = k < i ? p[std::size_t(k)] < p[std::size_t(i)] : p[std::size_t(k)] <= p[std::size_t(i)];
        if (!top) continue;
        double left = p[std::size_t(i)], right = p[std::size_t(i)];
        for (int k = std::max(0, i - reach); k < i; ++k) left = std::min(left, p[std::size_t(k)]);
        for (int k = i + 1; k <= std::min(n - 1, i + reach); ++k) right = std::min(right, p[std::size_t(k)]);
        if (p[std::size_t(i)] - left >= prominence && p[std::size_t(i)] - right >= prominence) ++count;
    }
    return count;
}

}  // namespace

TEST(PlatesProfiles, SaturateAndTerraceBehave) {
    // saturate: ≈ a for small a, never above cap, increasing.
    EXPECT_NEAR(saturate(1.0, 100.0), 1.0, 0.01);
    EXPECT_LT(saturate(1e6, 100.0), 100.0 + 1e-9);
    EXPECT_GT(saturate(500.0, 100.0), 99.0);
    for (double a = 0; a < 400; a += 7) EXPECT_LT(saturate(a, 100.0), saturate(a + 7, 100.0));
    EXPECT_EQ(saturate(50.0, 0.0), 0.0);
    // terrace: continuous, non-decreasing, exact at whole steps, flat-ish treads and steep scarps.
    double prev = 0.0;
    for (double d = 0.0; d <= 3.0; d += 0.001) {
        const double t = terrace(d, 1.0);
        EXPECT_GE(t, prev - 1e-12) << d;
        EXPECT_LT(t - prev, 0.02) << "a jump at " << d;
        prev = t;
    }
    EXPECT_NEAR(terrace(2.0, 1.0), 2.0, 1e-12);
    EXPECT_NEAR(terrace(1.3, 1.0) - terrace(1.1, 1.0), 0.2 * 0.2 / 0.75, 1e-9);  // a tread: 20 % per step
    EXPECT_GT(terrace(1.95, 1.0) - terrace(1.8, 1.0), 0.5);  // the scarp
}

// A range is rough along its crest: the crest line (the highest sample
// across the range at each position along it) has high-frequency relief
// well above a smooth profile's (a Gaussian band has none).
TEST(PlatesProfiles, RangeIsRoughAlongItsCrestAndHighestNearTheContact) {
    const double c = 40.0;
    const Field f = compose(257, shape_with_cell(c), [](BoundaryRelief& r) { r.add_range({20, 128}, {236, 128}); });
    for (float v : f.z) ASSERT_GE(v, 0.0f);  // a range only raises
    std::vector<double> crest;
    double off_line = 0.0;
    for (int x = 40; x <= 216; ++x) {
        double best = 0.0;
        int best_y = 128;
        for (int y = 128 - 32; y <= 128 + 32; ++y)
            if (f.at(x, y) > best) best = f.at(x, y), best_y = y;
        crest.push_back(best);
        off_line += std::abs(best_y - 128);
    }
    off_line /= double(crest.size());
    const double mean = std::accumulate(crest.begin(), crest.end(), 0.0) / double(crest.size());
    EXPECT_GT(mean, 20.0);
    // High-pass: the crest minus its running mean over half a cell.
    const int half = int(c / 4);
    double energy = 0.0;
    int count = 0;
    for (int i = half; i + half < int(crest.size()); ++i) {
        double m = 0.0;
        for (int k = -half; k <= half; ++k) m += crest[std::size_t(i + k)];
        m /= 2 * half + 1;
        energy += (crest[std::size_t(i)] - m) * (crest[std::size_t(i)] - m);
        ++count;
    }
    const double rough = std::sqrt(energy / count) / mean;
    EXPECT_GT(rough, 0.05) << "the crest is smooth: " << rough;
    EXPECT_GE(prominent_maxima(crest, 0.05 * mean), 4) << "a range should have several summits";
    // The summits crowd the contact line: the crest lies on average within 0.3 cells of it.
    EXPECT_LT(off_line, 0.3 * c);
    // And the range is higher on the line than half a cell off it, on average.
    double on = 0.0, off = 0.0;
    for (int x = 40; x <= 216; ++x) on += f.at(x, 128), off += 0.5 * (f.at(x, 128 - 20) + f.at(x, 128 + 20));
    EXPECT_GT(on, 1.5 * off);
}

// Subduction: a narrow, deep trench on the dense side; inland on the light
// side an arc of separate volcanoes, not one smooth band.
TEST(PlatesProfiles, SubductionHasANarrowTrenchAndAnArcOfSeparateVolcanoes) {
    const double c = 40.0;
    ReliefShape shape = shape_with_cell(c);
    const Field f = compose(257, shape, [](BoundaryRelief& r) { r.add_subduction({20, 128}, {236, 128}, {0, 5}); });
    // y grows south; the light plate lies south (toward +y).
    std::vector<double> arc;
    for (int x = 48; x <= 208; ++x) {
        int lo = 0, hi = 0;
        for (int y = 1; y < 256; ++y) {
            if (f.at(x, y) < f.at(x, lo)) lo = y;
            if (f.at(x, y) > f.at(x, hi)) hi = y;
        }
        ASSERT_LT(lo, 128) << "trench on the dense (north) side at x = " << x;
        EXPECT_LT(f.at(x, lo), -0.8 * shape.trench_depth);
        // Narrow: deeper than half its depth over at most 0.3 cells.
        int wide = 0;
        for (int y = 0; y < 257; ++y) wide += f.at(x, y) < 0.5f * f.at(x, lo);
        EXPECT_LE(wide, int(0.3 * c)) << x;
        double best = 0.0;
        for (int y = 129; y < 128 + int(c); ++y) best = std::max(best, double(f.at(x, y)));
        arc.push_back(best);
        for (int y = 0; y < 128; ++y) ASSERT_LE(f.at(x, y), 0.0f) << "no arc on the dense side";
        if (f.at(x, hi) > 5.0f) EXPECT_GT(hi - 128, 128 - lo) << "the arc stands farther inland than the trench";
    }
    const double top = *std::max_element(arc.begin(), arc.end());
    EXPECT_GT(top, 0.6 * shape.arc_height);
    // Several separate summits along the arc, each dropping by at least a third of the tallest on both sides.
    EXPECT_GE(prominent_maxima(arc, top / 3.0), 4);
}

// A rift: lower everywhere across it, an axial ridge above its floor, and
// stepped flanks: gentle treads between steep fault scarps, not a smooth slope.
TEST(PlatesProfiles, RiftIsLowerWithARidgeAndSteppedFlanks) {
    const double c = 80.0;
    const ReliefShape shape = shape_with_cell(c);
    const Field f = compose(129, shape, [](BoundaryRelief& r) { r.add_rift({64, 4}, {64, 124}); });
    for (float v : f.z) ASSERT_LE(v, 0.0f);
    const ReliefWidths w = relief_widths(c);
    for (int y : {40, 64, 90}) {
        const double floor_w = f.at(64 - int(w.ridge_half) - 2, y), floor_e = f.at(64 + int(w.ridge_half) + 2, y);
        EXPECT_LT(floor_w, -0.8 * shape.rift_depth);
        EXPECT_GT(f.at(64, y), floor_w + 4.0) << "a ridge on the axis, row " << y;
        EXPECT_GT(f.at(64, y), floor_e + 4.0) << "a ridge on the axis, row " << y;
        // Walk the east flank from the floor's edge to the rim: slopes per sample.
        std::vector<double> slope;
        for (int x = 64 + int(w.rift_floor); x < 64 + int(w.rift_half); ++x)
            slope.push_back(f.at(x + 1, y) - f.at(x, y));
        const double mean = std::accumulate(slope.begin(), slope.end(), 0.0) / double(slope.size());
        int treads = 0, scarps = 0;
        for (std::size_t i = 0; i < slope.size(); ++i) {
            treads += slope[i] < 0.4 * mean;
            scarps += slope[i] > 2.0 * mean && (i == 0 || slope[i - 1] <= 2.0 * mean);  // start of a scarp
        }
        EXPECT_GE(scarps, 2) << "row " << y;
        EXPECT_GE(treads, int(slope.size() / 3)) << "row " << y;
    }
}

// Repeated contacts at one place saturate: 200 identical contacts give less
// than 20× one contact's relief (and more than one's: they do add up).
TEST(PlatesProfiles, RepeatedContactsSaturate) {
    const ReliefShape shape = shape_with_cell(30.0);
    using Add = void (*)(BoundaryRelief&);
    const Add adds[] = {
        [](BoundaryRelief& r) {
            r.add_range({30, 64}, {100, 64});
        },
        [](BoundaryRelief& r) {
            r.add_subduction({30, 64}, {100, 64}, {0, 1});
        },
        [](BoundaryRelief& r) {
            r.add_rift({30, 64}, {100, 64});
        },
    };
    for (int kind = 0; kind < 3; ++kind) {
        auto total = [&](int contacts) {
            const Field f = compose(129, shape, [&](BoundaryRelief& r) {
                for (int i = 0; i < contacts; ++i) adds[kind](r);
            });
            double hi = 0.0, lo = 0.0;
            for (float v : f.z) hi = std::max(hi, double(v)), lo = std::min(lo, double(v));
            return std::make_pair(hi, lo);
        };
        const auto [hi1, lo1] = total(1);
        const auto [hi200, lo200] = total(200);
        if (kind != 2) {
            EXPECT_LT(hi200, 20.0 * hi1) << kind;
            EXPECT_GT(hi200, 2.0 * hi1) << kind;
        }
        if (kind != 0) {
            EXPECT_GT(lo200, 20.0 * lo1) << kind;
            EXPECT_LT(lo200, 2.0 * lo1) << kind;
        }
        EXPECT_LE(hi200,
                  (1.0 + shape.jitter) * 1.25 * shape.saturation *
                      std::max({shape.range_height, shape.arc_height, shape.ridge_height}))
            << kind;
    }
}

TEST(PlatesProfiles, ShapesChangeOnlySamplesNearTheSegmentAndReportTheChange) {
    const int n = 129;
    const double c = 24.0;
    std::vector<float> terrain(std::size_t(n) * n, 100.0f), uplift(terrain.size(), 0.0f);
    GridView t{terrain.data(), n, n, 10.0}, u{uplift.data(), n, n, 10.0};
    BoundaryRelief relief(n, n, shape_with_cell(c), 9);
    relief.add_subduction({30, 64}, {98, 64}, {0, 1});
    relief.add_rift({64, 6}, {64, 30});
    relief.add_range({100, 90}, {100, 120});
    relief.apply(t, &u);
    const ReliefWidths w = relief.widths();
    auto dist = [](double x, double y, double ax, double ay, double bx, double by) {
        const double dx = bx - ax, dy = by - ay;
        const double k = std::clamp(((x - ax) * dx + (y - ay) * dy) / (dx * dx + dy * dy), 0.0, 1.0);
        return std::hypot(x - ax - k * dx, y - ay - k * dy);
    };
    int changed = 0;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const float dh = t.at(x, y) - 100.0f;
            EXPECT_NEAR(u.at(x, y), dh, 1e-4) << x << "," << y;
            const double reach_sub = w.arc_offset + w.arc_band + w.vent_radius * 1.2 + 1;
            const bool near = dist(x, y, 30, 64, 98, 64) <= reach_sub ||
                dist(x, y, 64, 6, 64, 30) <= w.rift_half + 0.1 * c + w.end_reach + 1 ||
                dist(x, y, 100, 90, 100, 120) <= w.range_half + w.end_reach + 1;
            if (!near) EXPECT_EQ(dh, 0.0f) << x << "," << y;
            changed += dh != 0.0f;
        }
    EXPECT_GT(changed, 1000);
}
