// Specification of the pbrt-v4-style reference sampler (apps/common/pbrt_style.h) that
// the benchmarks measure envmis against: it samples pbrt-v4's density (channel average,
// compensated as asked) exactly, its pdf integrates to one and agrees with its samples,
// and its mappings are envmis's equal-area convention.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "envmis/image/mapping.h"
#include "maps.h"
#include "pbrt_style.h"
#include "stats.h"

namespace envmis::reference {
namespace {

EnvMapOptions equal_area(bool compensate, float alpha = 1) {
    EnvMapOptions o;
    o.mapping = Mapping::equal_area;
    o.compensation = {compensate, alpha};
    return o;
}

// pbrt-v4's texel masses, computed here from the image.
std::vector<double> expected_mass(const RgbImage& image, bool compensate, double alpha) {
    std::vector<double> mass;
    for (const Rgb& p : image.pixels) mass.push_back((double{p.r} + p.g + p.b) / 3);
    const double mean = std::accumulate(mass.begin(), mass.end(), 0.0) / static_cast<double>(mass.size());
    if (compensate)
        for (double& m : mass) m = std::max(m - alpha * mean, 0.0);
    return mass;
}

size_t texel_of(Vec2 uv, uint32_t n) {
    const auto x = std::min(static_cast<uint32_t>(uv.x * n), n - 1),
               y = std::min(static_cast<uint32_t>(uv.y * n), n - 1);
    return size_t{y} * n + x;
}

TEST(PbrtStyle, SamplesFollowPbrtsDensity) {
    const double level = test::sidak_level(0.01, 3);
    for (const auto& [compensate, alpha] : {std::pair{false, 1.0f}, {true, 1.0f}, {true, 0.5f}}) {
        const RgbImage image = test::random_map(24, 24, 5);
        const PbrtStyleEnvMap map(image, equal_area(compensate, alpha));
        const std::vector<double> mass = expected_mass(image, compensate, alpha);
        const double total = std::accumulate(mass.begin(), mass.end(), 0.0);
        const size_t n = 200000;
        std::vector<double> expected, observed(mass.size());
        for (double m : mass) expected.push_back(n * m / total);
        test::Rng rng(17);
        for (size_t i = 0; i < n; ++i) observed[texel_of(map.sample(rng.uniform2()).uv, 24)] += 1;
        const auto chi = test::chi_square(expected, observed);
        EXPECT_GT(chi.p_value, level) << "compensate " << compensate << " alpha " << alpha << ": " << chi.describe();
        for (size_t i = 0; i < mass.size(); ++i)
            if (mass[i] == 0) {
                EXPECT_EQ(observed[i], 0) << "texel " << i << " has no density";
            }
    }
}

// Every equal-area texel covers 4 pi / n^2: the pdf at texel centres sums to one.
TEST(PbrtStyle, PdfIntegratesToOne) {
    for (bool compensate : {false, true}) {
        const RgbImage image = test::sun_sky_map(32, 32);
        const PbrtStyleEnvMap map(image, equal_area(compensate));
        double total = 0;
        for (uint32_t y = 0; y < 32; ++y)
            for (uint32_t x = 0; x < 32; ++x)
                total += map.pdf(pbrt_square_to_sphere({(x + 0.5f) / 32, (y + 0.5f) / 32})) * 4 * kPi / (32 * 32);
        EXPECT_NEAR(total, 1.0, 1e-4) << "compensate " << compensate;
    }
}

TEST(PbrtStyle, SamplesCarryThePdfOfTheirDirectionInAnyFrame) {
    const RgbImage image = test::random_map(64, 64, 6);
    for (const char* axes : {"z-up", "y-up", "x,-z,y"}) {
        EnvMapOptions o = equal_area(true);
        o.axes = Axes::parse(axes);
        const PbrtStyleEnvMap map(image, o);
        test::Rng rng(18);
        int edges = 0;
        for (int i = 0; i < 20000; ++i) {
            const EnvSample s = map.sample(rng.uniform2());
            ASSERT_GT(s.pdf, 0.0f);
            ASSERT_NEAR(length(s.direction), 1.0f, 1e-5f);
            ASSERT_EQ(s.radiance.g, image.pixels[texel_of(s.uv, 64)].g);
            edges += std::abs(map.pdf(s.direction) - s.pdf) > 1e-4f * s.pdf;  // a texel's edge, rounded across
        }
        EXPECT_LT(edges, 20) << axes;
    }
}

TEST(PbrtStyle, MappingsAreEnvmisEqualAreaConventionAndInverses) {
    test::Rng rng(19);
    for (int i = 0; i < 100000; ++i) {
        const Vec2 p = rng.uniform2();
        const Vec3 d = pbrt_square_to_sphere(p), e = equal_area_direction(p);
        ASSERT_NEAR(d.x, e.x, 2e-6f) << p.x << " " << p.y;
        ASSERT_NEAR(d.y, e.y, 2e-6f);
        ASSERT_NEAR(d.z, e.z, 2e-6f);
        const Vec2 back = pbrt_sphere_to_square(d);
        ASSERT_NEAR(back.x, p.x, 2e-6f) << p.x << " " << p.y;
        ASSERT_NEAR(back.y, p.y, 2e-6f);
    }
}

TEST(PbrtStyle, AConstantMapCompensatedWholeFallsBackToUniform) {
    const RgbImage image = test::constant_map(8, 8, {2, 2, 2});
    const PbrtStyleEnvMap map(image, equal_area(true));
    test::Rng rng(20);
    for (int i = 0; i < 1000; ++i) EXPECT_NEAR(map.sample(rng.uniform2()).pdf, 1 / (4 * kPi), 1e-6);
}

TEST(PbrtStyle, OnlySquareEqualAreaMapsAreAccepted) {
    EXPECT_THROW(PbrtStyleEnvMap(test::constant_map(16, 8, {1, 1, 1}), equal_area(true)), std::invalid_argument);
    EXPECT_THROW(PbrtStyleEnvMap(test::constant_map(8, 8, {1, 1, 1}), EnvMapOptions{}), std::invalid_argument);
}

}  // namespace
}  // namespace envmis::reference
