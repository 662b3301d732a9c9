// Specification of the equirectangular mapping and axes (mapping.h).
#include <gtest/gtest.h>

#include "envmis/mapping.h"
#include "stats.h"

namespace envmis {
namespace {

TEST(Mapping, FollowsTheDocumentedConvention) {
    EXPECT_NEAR(equirect_direction({0.3f, 0.0f}).z, 1.0f, 1e-6f);  // v = 0: top row, +z
    EXPECT_NEAR(equirect_direction({0.3f, 0.99999f}).z, -1.0f, 1e-4f);
    const Vec3 d = equirect_direction({0.25f, 0.5f});  // theta = pi/2, phi = pi/2
    EXPECT_NEAR(d.x, 0.0f, 1e-6f);
    EXPECT_NEAR(d.y, 1.0f, 1e-6f);
    EXPECT_NEAR(d.z, 0.0f, 1e-6f);
}

TEST(Mapping, UvOfDirectionInvertsDirectionOfUv) {
    test::Rng rng(1);
    for (int i = 0; i < 10000; ++i) {
        const Vec2 uv{rng.uniform(), 0.001f + 0.998f * rng.uniform()};
        const Vec2 back = equirect_uv(equirect_direction(uv));
        EXPECT_NEAR(back.y, uv.y, 1e-5f);
        const float du = std::abs(back.x - uv.x);
        EXPECT_LT(std::min(du, 1 - du), 1e-5f);  // u wraps around
    }
}

TEST(Axes, ParseAndPrint) {
    EXPECT_EQ(Axes::parse("z-up"), Axes{});
    EXPECT_EQ(Axes::parse("x,y,z"), Axes{});
    EXPECT_EQ(Axes::parse("y-up"), Axes::parse("x,z,-y"));
    EXPECT_EQ(Axes::parse("-y,+x,z").to_string(), "-y,x,z");
    for (const char* bad : {"", "x,y", "x,x,z", "x,y,w", "x,y,z,x", "xy,z", "up"})
        EXPECT_THROW(Axes::parse(bad), std::invalid_argument) << bad;
}

TEST(Axes, ToCanonicalInvertsToWorld) {
    const Vec3 v{0.1f, -0.7f, 0.3f};
    for (const char* a : {"x,y,z", "x,z,-y", "-z,y,x", "y,-x,-z"}) {
        const Axes axes = Axes::parse(a);
        const Vec3 back = to_canonical(axes, to_world(axes, v));
        EXPECT_EQ(back.x, v.x) << a;
        EXPECT_EQ(back.y, v.y) << a;
        EXPECT_EQ(back.z, v.z) << a;
    }
}

}  // namespace
}  // namespace envmis
