// Specification of the study's shading points (comparison.h): normals spread evenly over
// the sphere, seen head-on or at a fixed angle towards turning azimuths.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "envmis/study/comparison/comparison.h"

namespace envmis {
namespace {

TEST(SpherePoints, NormalsAreUnitAndSeenHeadOnByDefault) {
    for (const ShadingPoint& p : sphere_points(50)) {
        EXPECT_NEAR(length(p.normal), 1.0f, 1e-5f);
        EXPECT_EQ(p.wo.x, p.normal.x);
        EXPECT_EQ(p.wo.z, p.normal.z);
    }
}

TEST(SpherePoints, AViewAngleTiltsEveryViewByItTowardsAzimuthsThatTurn) {
    const auto head_on = sphere_points(40);
    for (double degrees : {45.0, 75.0, 85.0}) {
        const auto points = sphere_points(40, degrees);
        double sum_x = 0, sum_y = 0;  // the tilts' directions in each point's tangent plane spread
        for (size_t i = 0; i < points.size(); ++i) {
            EXPECT_EQ(points[i].normal.x, head_on[i].normal.x);
            EXPECT_NEAR(length(points[i].wo), 1.0f, 1e-5f);
            EXPECT_NEAR(std::acos(dot(points[i].wo, points[i].normal)) * 180 / kPi, degrees, 1e-3);
            const Vec3 tilt = normalize(points[i].wo - points[i].normal * dot(points[i].wo, points[i].normal));
            sum_x += std::atan2(tilt.y, tilt.x) > 0 ? 1 : -1;
            sum_y += tilt.z > 0 ? 1 : -1;
        }
        EXPECT_LT(std::abs(sum_x), 20);
        EXPECT_LT(std::abs(sum_y), 20);
    }
    EXPECT_THROW(sphere_points(4, 90), std::invalid_argument);
    EXPECT_THROW(sphere_points(4, -1), std::invalid_argument);
}

}  // namespace
}  // namespace envmis
