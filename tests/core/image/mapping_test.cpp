// Specification of the equirectangular and equal-area mappings and axes (mapping.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "envmis/image/mapping.h"
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

// pbrt-v4's EqualAreaSquareToSphere: centre +z, corners -z, edge midpoints on the
// equator, u along +x and v along +y.
TEST(EqualArea, FollowsPbrtsConvention) {
    const auto near = [](Vec3 a, Vec3 b) { return length(a - b) < 1e-5f; };
    EXPECT_TRUE(near(equal_area_direction({0.5f, 0.5f}), {0, 0, 1}));
    for (Vec2 corner : {Vec2{0, 0}, Vec2{1, 0}, Vec2{0, 1}, Vec2{1, 1}})
        EXPECT_TRUE(near(equal_area_direction(corner), {0, 0, -1}));
    EXPECT_TRUE(near(equal_area_direction({1, 0.5f}), {1, 0, 0}));
    EXPECT_TRUE(near(equal_area_direction({0, 0.5f}), {-1, 0, 0}));
    EXPECT_TRUE(near(equal_area_direction({0.5f, 1}), {0, 1, 0}));
    EXPECT_TRUE(near(equal_area_direction({0.5f, 0}), {0, -1, 0}));
    const float c = std::sqrt(0.5f);  // the diagonal's midpoint: the equator at 45 degrees
    EXPECT_TRUE(near(equal_area_direction({0.75f, 0.75f}), {c, c, 0}));
}

TEST(EqualArea, UvOfDirectionInvertsDirectionOfUv) {
    test::Rng rng(2);
    for (int i = 0; i < 100000; ++i) {
        const Vec2 uv = rng.uniform2();
        const Vec3 d = equal_area_direction(uv);
        ASSERT_NEAR(length(d), 1.0f, 2e-6f);
        const Vec2 back = equal_area_uv(d);
        // Float precision: the -z corners lose a few bits to 1 - |z|.
        ASSERT_NEAR(back.x, uv.x, 1e-5f) << uv.x << "," << uv.y;
        ASSERT_NEAR(back.y, uv.y, 1e-5f) << uv.x << "," << uv.y;
    }
}

// The contract's accuracy (mapping.h), against the same mapping in double with the
// library's sine and cosine; over a million random points and the square's edges and
// diagonals, where r or t reach their ends.
TEST(EqualArea, DirectionIsWithinTwoPointFourTenMillionthsOfTheExactOne) {
    const auto exact = [](Vec2 uv) {
        const double u = 2.0 * uv.x - 1, v = 2.0 * uv.y - 1, au = std::abs(u), av = std::abs(v);
        const double signed_distance = 1 - (au + av), r = 1 - std::abs(signed_distance);
        const double phi = (r == 0 ? 1.0 : (av - au) / r + 1) * kPi / 4, s = r * std::sqrt(2 - r * r);
        return std::array<double, 3>{std::copysign(std::cos(phi) * s, u), std::copysign(std::sin(phi) * s, v),
                                     std::copysign(1 - r * r, signed_distance)};
    };
    std::vector<Vec2> points;
    test::Rng rng(4);
    for (int i = 0; i < 1000000; ++i) points.push_back(rng.uniform2());
    for (int i = 0; i <= 4096; ++i) {
        const float t = static_cast<float>(i) / 4096;
        for (Vec2 p : {Vec2{t, 0}, Vec2{0, t}, Vec2{t, 0.5f}, Vec2{0.5f, t}, Vec2{t, t}, Vec2{t, 1 - t}})
            points.push_back(p);
    }
    double worst = 0;
    for (const Vec2 uv : points) {
        const Vec3 d = equal_area_direction(uv);
        const auto e = exact(uv);
        worst = std::max({worst, std::abs(d.x - e[0]), std::abs(d.y - e[1]), std::abs(d.z - e[2])});
    }
    EXPECT_LT(worst, 2.4e-7);  // 2.1e-7 here; the Horner form of the polynomials gave 2.5e-7
}

// Equal area: uniform points of the square give uniform directions, so z is uniform on
// [-1, 1] and the azimuth on [0, 2 pi) (chi-square, 64 bins each, and jointly 16 x 16).
TEST(EqualArea, UniformSquareGivesUniformDirections) {
    const int bins = 16, n = 400000;
    std::vector<double> observed(bins * bins), expected(bins * bins, static_cast<double>(n) / (bins * bins));
    test::Rng rng(3);
    for (int i = 0; i < n; ++i) {
        const Vec3 d = equal_area_direction(rng.uniform2());
        double phi = std::atan2(double{d.y}, double{d.x});
        if (phi < 0) phi += 2 * kPi;
        const int zb = std::min(bins - 1, static_cast<int>((d.z + 1) / 2 * bins));
        const int pb = std::min(bins - 1, static_cast<int>(phi / (2 * kPi) * bins));
        observed[static_cast<size_t>(zb * bins + pb)] += 1;
    }
    const auto chi = test::chi_square(expected, observed);
    EXPECT_GT(chi.p_value, 1e-3) << chi.describe();
}

TEST(Mapping, NamesReadBack) {
    for (Mapping m : {Mapping::equirect, Mapping::equal_area}) EXPECT_EQ(parse_mapping(to_string(m)), m);
    EXPECT_THROW(parse_mapping("cube"), std::invalid_argument);
}

TEST(Axes, ParseAndPrint) {
    EXPECT_EQ(Axes::parse("z-up"), Axes{});
    EXPECT_EQ(Axes::parse("x,y,z"), Axes{});
    EXPECT_EQ(Axes::parse("y-up"), Axes::parse("x,z,-y"));
    EXPECT_EQ(Axes::parse("-y,+x,z").to_string(), "-y,x,z");
    for (const char* bad : {"", "x,y", "x,x,z", "x,y,w", "x,y,z,x", "xy,z", "up"})
        EXPECT_THROW(Axes::parse(bad), std::invalid_argument) << bad;
}

// Each renderer's own formula for the image point of a direction in its world frame
// (with an identity light transform), written here from its sources; v from the top row.
struct Convention {
    const char* preset;
    Vec2 (*uv)(double x, double y, double z);
};
double wrap(double u) { return u - std::floor(u); }
const Convention kConventions[] = {
    // pbrt-v4 (imgtool makeequiarea, EqualAreaSquareToSphere's frame): phi = atan2(y, x), z up.
    {"pbrt-v4",
     [](double x, double y, double z) {
         return Vec2{static_cast<float>(wrap(std::atan2(y, x) / (2 * kPi))), static_cast<float>(std::acos(z) / kPi)};
     }},
    // Mitsuba 3 (envmap emitter): u = atan2(x, -z) / 2 pi, v = acos(y) / pi, y up.
    {"mitsuba3",
     [](double x, double y, double z) {
         return Vec2{static_cast<float>(wrap(std::atan2(x, -z) / (2 * kPi))), static_cast<float>(std::acos(y) / kPi)};
     }},
    // Blender Cycles (environment texture): u = 1/2 - atan2(y, x) / 2 pi, v = 1 - acos(z) / pi
    // counted from the bottom row, so acos(z) / pi from the top.
    {"blender",
     [](double x, double y, double z) {
         return Vec2{static_cast<float>(wrap(0.5 - std::atan2(y, x) / (2 * kPi))),
                     static_cast<float>(std::acos(z) / kPi)};
     }},
};

TEST(Axes, RendererPresetsPutEachDirectionOnTheTexelTheRendererReads) {
    const uint32_t w = 64, h = 32;
    test::Rng rng(41);
    for (const Convention& c : kConventions) {
        const Axes axes = Axes::parse(c.preset);
        int agree = 0;
        const int n = 2000;
        for (int i = 0; i < n; ++i) {
            const Vec3 d = normalize(Vec3{rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f});
            const Vec2 ours = equirect_uv(to_canonical(axes, d)), theirs = c.uv(d.x, d.y, d.z);
            const auto texel = [&](Vec2 uv) {
                return std::pair{std::min(w - 1, static_cast<uint32_t>(uv.x * w)),
                                 std::min(h - 1, static_cast<uint32_t>(uv.y * h))};
            };
            agree += texel(ours) == texel(theirs);
        }
        EXPECT_GT(agree, n * 99 / 100) << c.preset;  // float rounding at texel borders only
    }
    EXPECT_EQ(Axes::parse("mitsuba3").to_string(), "y,z,-x");
    EXPECT_EQ(Axes::parse("blender").to_string(), "-x,y,z");
    EXPECT_EQ(Axes::parse("pbrt-v4"), Axes{});
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
