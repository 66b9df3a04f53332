// Analytic test surfaces: their defining properties.
#include "shape.hpp"

#include <orogen/error.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

using namespace orogen;
using namespace orogen::shape;

namespace {

struct Surface {
    int w, h;
    double cell;
    std::vector<float> z;
    float at(int x, int y) const { return z[std::size_t(y) * w + x]; }
};

Surface make(Kind kind, int w = 65, int h = 65, double cell = 1.0, double height = 100.0, double slope = 10.0,
             double direction = 0.0) {
    Surface s{w, h, cell, std::vector<float>(std::size_t(w) * h, -1.0f)};
    make_shape({s.z.data(), w, h, cell}, {kind, height, slope, direction});
    return s;
}

}  // namespace

TEST(Shape, PyramidHasItsApexInTheCentreAndFourPlanarFaces) {
    const Surface s = make(Kind::pyramid);
    EXPECT_FLOAT_EQ(s.at(32, 32), 100.0f);
    EXPECT_FLOAT_EQ(s.at(0, 0), 0.0f);
    EXPECT_FLOAT_EQ(s.at(64, 32), 0.0f);
    EXPECT_FLOAT_EQ(*std::max_element(s.z.begin(), s.z.end()), 100.0f);
    // Each face is a plane: equal steps along the centre line.
    for (int x = 33; x < 64; ++x) EXPECT_NEAR(s.at(x, 32) - s.at(x + 1, 32), 100.0 / 32, 1e-4);
    // Level sets are squares: (32+k, 32) and (32+k, 32+k) have the same height.
    for (int k = 0; k <= 32; ++k) EXPECT_FLOAT_EQ(s.at(32 + k, 32), s.at(32 + k, 32 + k));
}

TEST(Shape, HemisphereIsAHalfEllipsoidOnTheCentre) {
    const Surface s = make(Kind::hemisphere, 65, 41);  // radius 20 samples (half the shorter side)
    EXPECT_FLOAT_EQ(s.at(32, 20), 100.0f);
    for (int y = 0; y < 41; ++y)
        for (int x = 0; x < 65; ++x) {
            const double d = std::hypot(x - 32.0, y - 20.0) / 20.0;
            const double want = d < 1 ? 100.0 * std::sqrt(1 - d * d) : 0.0;
            ASSERT_NEAR(s.at(x, y), want, 1e-3);
        }
}

TEST(Shape, ConeFallsLinearlyToItsRim) {
    const Surface s = make(Kind::cone);
    EXPECT_FLOAT_EQ(s.at(32, 32), 100.0f);
    EXPECT_NEAR(s.at(48, 32), 50.0f, 1e-4);
    EXPECT_FLOAT_EQ(s.at(0, 0), 0.0f);
}

TEST(Shape, FlatAndPlane) {
    const Surface f = make(Kind::flat, 20, 10, 1.0, 7.5);
    for (float v : f.z) EXPECT_EQ(v, 7.5f);
    // 45° toward the south, cells 2 m: rises 2 m per row, lowest row at `height`.
    const Surface p = make(Kind::plane, 20, 10, 2.0, 3.0, 45.0, 90.0);
    for (int y = 0; y < 10; ++y)
        for (int x = 0; x < 20; ++x) ASSERT_NEAR(p.at(x, y), 3.0 + 2.0 * y, 1e-4);
    // Toward the west: the east edge is the lowest.
    const Surface q = make(Kind::plane, 20, 10, 1.0, 0.0, 30.0, 180.0);
    EXPECT_NEAR(q.at(19, 5), 0.0, 1e-4);
    EXPECT_NEAR(q.at(0, 5), 19 * std::tan(30 * 3.141592653589793 / 180), 1e-4);
}

TEST(Shape, CrookedStaysWithinItsHeightAndIsNotAPlane) {
    const Surface s = make(Kind::crooked, 129, 129, 1.0, 50.0);
    const auto [lo, hi] = std::minmax_element(s.z.begin(), s.z.end());
    EXPECT_GE(*lo, 0.0f);
    EXPECT_LE(*hi, 50.0f);
    EXPECT_GT(*hi - *lo, 35.0f);
    // Falls south on average, with ridges across: some row is not monotone.
    double north = 0, south = 0;
    for (int x = 0; x < 129; ++x) {
        north += s.at(x, 0);
        south += s.at(x, 128);
    }
    EXPECT_GT(north, south);
    int turns = 0;
    for (int x = 1; x < 128; ++x) turns += (s.at(x, 64) - s.at(x - 1, 64)) * (s.at(x + 1, 64) - s.at(x, 64)) < 0;
    EXPECT_GE(turns, 2);
}

TEST(Shape, UnknownKindNamesTheChoices) {
    try {
        kind_from_name("sphere");
        FAIL();
    } catch (const BadInput& e) {
        EXPECT_STREQ(e.what(),
                     "shape: unknown kind 'sphere'; use one of crooked, pyramid, hemisphere, flat, plane, cone");
    }
}
