// Specification of the study's shading points (comparison.h): normals spread evenly over
// the sphere, seen head-on or at a fixed angle towards turning azimuths.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "envmis/build/env_map.h"
#include "envmis/study/comparison/comparison.h"
#include "maps.h"

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

// Each technique's random stream depends on the seed, the point and the technique only:
// its numbers are bit-identical whichever others run beside it.
TEST(Compare, ATechniquesNumbersAreTheSameWhicheverOthersRun) {
    EnvMapOptions uncompensated;
    uncompensated.compensation.enabled = false;
    const EnvMap plain = build_env_map(test::sun_sky_map(64, 32), uncompensated);
    const std::vector<Bsdf> bsdfs = {Bsdf::lambert(), Bsdf::phong(50)};
    const CompensatedMaps compensated = compensated_maps(plain, std::vector<float>{1.0f, 1.0f});
    const std::vector<ShadingPoint> points = sphere_points(3);
    const auto run = [&](std::initializer_list<const char*> names) {
        ComparisonOptions options;
        options.bsdfs = bsdfs;
        options.techniques.clear();
        for (const char* name : names) options.techniques.push_back(Technique::parse(name));
        options.spp = 256;
        return compare({plain, compensated, points, options});
    };
    const Comparison alone = run({"mis-balance"});
    for (const Comparison& with : {run({"env", "mis-balance"}), run({"bsdf", "mis-balance-comp", "mis-balance"})})
        for (size_t b = 0; b < bsdfs.size(); ++b) {
            const TechniqueStats& a = *alone.bsdfs[b].find("mis-balance");
            const TechniqueStats& w = *with.bsdfs[b].find("mis-balance");
            EXPECT_EQ(a.mean, w.mean) << bsdfs[b].name();
            EXPECT_EQ(a.variance, w.variance) << bsdfs[b].name();
            EXPECT_EQ(a.point_variances, w.point_variances) << bsdfs[b].name();
        }
}

}  // namespace
}  // namespace envmis
