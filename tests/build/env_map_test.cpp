// Specification of the build of an environment map from an image (build/env_map.h): its
// statistics (mean, threshold, zeroed texels, repaired pixels) against computations
// written here, and its refusals. How the built map samples is envmap_test's.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "envmis/build/env_map.h"
#include "errors.h"
#include "maps.h"

namespace envmis {
namespace {

EnvMapOptions options(bool compensate, float alpha = 1.0f) {
    EnvMapOptions o;
    o.compensation = {compensate, alpha};
    return o;
}

// The table writer streams the density a row at a time: the rows are density()'s.
// Finite pixels whose power 4 pi Lbar overflows float would give Inf and NaN estimates:
// the map is refused, saying how to scale it.
TEST(BuildEnvMap, AMapWhosePowerOverflowsFloatIsRefusedWithTheFactorToScaleItBy) {
    test::expect_error<std::invalid_argument>(
        [] {
            build_env_map(test::constant_map(64, 32, {3e38f, 3e38f, 3e38f}));
        },
        {"luminance overflows", "scale the map down", "1e-3"});
}

// A sun of texels near float's maximum overflows the float lanes of a row's sum, but not
// the map's power: its statistics stay exact and finite.
TEST(BuildEnvMap, ASunNearFloatsMaximumKeepsFiniteStatistics) {
    RgbImage image = test::constant_map(256, 128, {1, 1, 1});
    for (uint32_t x = 100; x < 164; ++x) image.pixels[64 * 256 + x] = {3e38f, 3e38f, 3e38f};
    const EnvMap map = build_env_map(image, EnvMapOptions{});
    const EnvMapStats& s = map.stats();
    EXPECT_TRUE(std::isfinite(s.mean_luminance) && s.mean_luminance > 1e35) << s.mean_luminance;
    EXPECT_EQ(s.fallback, DensityFallback::none);
    EXPECT_GT(s.threshold, 0.0f);
}

TEST(BuildEnvMap, CompensationZeroesExactlyTheTexelsAtOrBelowAlphaLbar) {
    const RgbImage image = test::random_map(50, 25, 7);
    for (float alpha : {0.5f, 1.0f, 3.0f}) {
        const EnvMap map = build_env_map(image, options(true, alpha));
        const auto density = map.density();
        uint64_t zeroed = 0;
        for (size_t i = 0; i < density.size(); ++i) {
            const float l = luminance(image.pixels[i], {});
            EXPECT_EQ(density[i] == 0, l <= map.stats().threshold) << i;
            zeroed += l > 0 && l <= map.stats().threshold;
        }
        EXPECT_EQ(map.stats().zeroed_texels, zeroed);
        EXPECT_NEAR(map.stats().threshold, alpha * map.stats().mean_luminance, 1e-6 * map.stats().threshold);
        EXPECT_TRUE(map.compensated());
        EXPECT_FALSE(map.complete());
    }
}

TEST(BuildEnvMap, MeanLuminanceIsSolidAngleWeighted) {
    // Bright poles, dark equator: a per-texel mean would be far higher.
    RgbImage image = test::constant_map(16, 64, {0, 0, 0});
    for (uint32_t x = 0; x < 16; ++x) image.pixels[x] = image.pixels[63 * 16 + x] = {1, 1, 1};
    const EnvMap map = build_env_map(image, options(true));
    const double s0 = std::sin(kPi * 0.5 / 64);
    double weights = 0;
    for (int y = 0; y < 64; ++y) weights += std::sin(kPi * (y + 0.5) / 64);
    EXPECT_NEAR(map.stats().mean_luminance, 2 * s0 / weights, 1e-7);
}

TEST(BuildEnvMap, BadPixelsAreRepairedAndCounted) {
    RgbImage image = test::constant_map(4, 3, {1, 1, 1});
    image.pixels[0] = {NAN, 1, 1};
    image.pixels[1] = {INFINITY, -INFINITY, 1};
    image.pixels[2] = {-0.004f, 1, -2};
    const EnvMap map = build_env_map(image, options(false));
    EXPECT_EQ(map.stats().bad_pixels.nan, 1u);
    EXPECT_EQ(map.stats().bad_pixels.infinite, 2u);
    EXPECT_EQ(map.stats().bad_pixels.negative, 2u);
    for (const Rgb& p : map.radiance().pixels)
        EXPECT_TRUE(p.r >= 0 && p.g >= 0 && p.b >= 0 && std::isfinite(p.r + p.g + p.b));
}

TEST(BuildEnvMap, RejectsInvalidConstruction) {
    EXPECT_THROW(build_env_map(RgbImage{}), std::invalid_argument);
    EXPECT_THROW(build_env_map(RgbImage{4, 4, RgbPixels(15)}), std::invalid_argument);
    EXPECT_THROW(build_env_map(test::constant_map(4, 2, {1, 1, 1}), options(true, -1.0f)), std::invalid_argument);
    EXPECT_THROW(build_env_map(test::constant_map(4, 2, {1, 1, 1}), options(true, NAN)), std::invalid_argument);
}

}  // namespace
}  // namespace envmis
