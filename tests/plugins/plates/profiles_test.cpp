// The boundary relief functions alone: rift valley with its ridge, the
// asymmetric trench and arc, and that both stay near their segment.
#include "profiles.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

using namespace orogen;
using namespace orogen::plates;

TEST(PlatesProfiles, RiftIsAValleyWithARidgeOnItsAxis) {
    const RiftShape shape{8.0, 30.0, 15.0};
    double floor = 0.0, floor_at = 0.0;
    for (double s = 0.0; s <= 24.0; s += 0.05) {
        const double h = rift_profile(s, shape);
        EXPECT_LT(h, 0.0) << s;  // lower everywhere across the rift
        EXPECT_DOUBLE_EQ(h, rift_profile(-s, shape));  // symmetric
        if (h < floor) floor = h, floor_at = s;
    }
    EXPECT_GT(floor_at, 1.0);  // the valley floor is off the axis...
    EXPECT_GT(rift_profile(0.0, shape), floor + 5.0);  // ...and the ridge stands above it
}

TEST(PlatesProfiles, SubductionPutsTheTrenchOnTheDenseSideAndTheArcOnTheLight) {
    const SubductionShape shape{8.0, 60.0, 40.0};
    double lo = 0.0, lo_at = 0.0, hi = 0.0, hi_at = 0.0;
    for (double s = -20.0; s <= 20.0; s += 0.05) {
        const double h = subduction_profile(s, shape);
        if (h < lo) lo = h, lo_at = s;
        if (h > hi) hi = h, hi_at = s;
    }
    EXPECT_LT(lo_at, 0.0);
    EXPECT_GT(hi_at, 0.0);
    EXPECT_LT(lo, -50.0);
    EXPECT_GT(hi, 35.0);
    // Asymmetric: mirror images differ.
    EXPECT_GT(std::abs(subduction_profile(-4.0, shape) - subduction_profile(4.0, shape)), 20.0);
}

TEST(PlatesProfiles, ShapesChangeOnlyCellsNearTheSegmentAndReportTheChange) {
    const int n = 97;
    std::vector<float> terrain(n * n, 100.0f), uplift(n * n, 0.0f);
    GridView t{terrain.data(), n, n, 10.0}, u{uplift.data(), n, n, 10.0};
    const Point2 a{30, 48}, b{66, 48};
    const double w = 6.0;
    shape_subduction(t, a, b, {0, 1}, {w, 60.0, 40.0}, &u);
    carve_rift(t, {48, 10}, {48, 20}, {w, 30.0, 15.0}, &u);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const float dh = t.at(x, y) - 100.0f;
            EXPECT_NEAR(u.at(x, y), dh, 1e-4) << x << "," << y;
            const bool near_subduction = x >= 30 - 2.5 * w - 1 && x <= 66 + 2.5 * w + 1 && std::abs(y - 48) <= 2.5 * w + 1;
            const bool near_rift = std::abs(x - 48) <= 3 * w + 1 && y >= 10 - 3 * w - 1 && y <= 20 + 3 * w + 1;
            if (!near_subduction && !near_rift) EXPECT_EQ(dh, 0.0f) << x << "," << y;
        }
    // y grows south: the light plate lies south (toward +y), so the arc is south of y = 48, the trench north.
    EXPECT_GT(t.at(48, 54), 120.0f);
    EXPECT_LT(t.at(48, 46), 60.0f);
}
