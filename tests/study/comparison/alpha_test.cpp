// Specification of the automatic choice of the compensation strength (alpha.h): the
// downsampled copy it works on, and the choices it makes where the answer is known.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "envmis/build/env_map.h"
#include "envmis/compensation/compensation.h"
#include "envmis/study/comparison/alpha.h"
#include "envmis/study/reference/quadrature.h"
#include "maps.h"

namespace envmis {
namespace {

double mean_luminance(const RgbImage& image) {
    std::vector<float> l;
    for (const Rgb& p : image.pixels) l.push_back(luminance(p, {}));
    return solid_angle_mean(l, image.width, image.height);
}

// Few points and one BSDF keep each choice to milliseconds.
AlphaOptions quick(std::vector<Bsdf> bsdfs) {
    AlphaOptions o;
    o.bsdfs = std::move(bsdfs);
    o.points = sphere_points(8);
    return o;
}

TEST(Downsample, HalvesUntilTheWidthFitsAndKeepsTheSolidAngleMean) {
    const RgbImage image = test::random_map(256, 128, 7);
    const RgbImage small = downsample(image, 40);
    EXPECT_EQ(small.width, 32u);
    EXPECT_EQ(small.height, 16u);
    EXPECT_NEAR(mean_luminance(small), mean_luminance(image), 1e-5 * mean_luminance(image));
    // The sun's power is kept too, though spread over fewer, dimmer texels.
    const RgbImage sun = test::sun_sky_map(512, 256);
    EXPECT_NEAR(mean_luminance(downsample(sun, 64)), mean_luminance(sun), 1e-5 * mean_luminance(sun));
}

TEST(Downsample, LeavesSmallMapsAndHandlesOddSizesAndBadPixels) {
    const RgbImage image = test::random_map(64, 32, 3);
    const RgbImage same = downsample(image, 128);
    EXPECT_EQ(same.width, 64u);
    EXPECT_EQ(same.pixels.size(), image.pixels.size());

    RgbImage odd = test::constant_map(7, 3, {1, 1, 1});
    odd.pixels[4] = {std::numeric_limits<float>::quiet_NaN(), -1, std::numeric_limits<float>::infinity()};
    const RgbImage small = downsample(odd, 2);
    EXPECT_EQ(small.width, 3u);  // 7 x 3 -> 3 x 1, the odd texels joining their neighbours; one high, it stops
    EXPECT_EQ(small.height, 1u);
    for (const Rgb& p : small.pixels) {
        EXPECT_TRUE(std::isfinite(p.r) && std::isfinite(p.g) && std::isfinite(p.b));
        EXPECT_LE(p.r, 1.0f);
        EXPECT_GE(p.b, 0.0f);
    }
}

TEST(ChooseAlpha, AlwaysTriesAlphaZeroWhoseCriterionIsExactlyOne) {
    AlphaOptions o = quick({Bsdf::lambert(), Bsdf::ggx(0.3f)});
    o.candidates = {2, 1};
    const AlphaChoice c = choose_alpha(test::sun_sky_map(128, 64), {}, o);
    ASSERT_EQ(c.candidates.size(), 3u);
    EXPECT_EQ(c.candidates[0].alpha, 0.0f);  // added, and candidates ascend
    EXPECT_EQ(c.candidates[1].alpha, 1.0f);
    EXPECT_EQ(c.candidates[2].alpha, 2.0f);
    EXPECT_EQ(c.candidates[0].criterion, 1.0);
    for (double r : c.candidates[0].per_bsdf) EXPECT_EQ(r, 1.0);
    EXPECT_EQ(c.bsdf_alphas.size(), 2u);
    EXPECT_THROW(choose_alpha(test::sun_sky_map(16, 8), {},
                              [] {
                                  AlphaOptions bad;
                                  bad.candidates = {-0.5f};
                                  return bad;
                              }()),
                 std::invalid_argument);
}

TEST(ChooseAlpha, PicksNoCompensationWhereItCannotHelp) {
    // A constant map: compensation either keeps the density (alpha < 1) or zeroes it and
    // falls back to the plain one; every candidate ties at 1 and the tie goes to 0.
    const AlphaChoice flat = choose_alpha(test::constant_map(64, 32, {0.5f, 0.5f, 0.5f}), {}, quick({Bsdf::lambert()}));
    EXPECT_EQ(flat.alpha, 0.0f);
    EXPECT_EQ(flat.bsdf_alphas[0], 0.0f);
    for (const AlphaCandidate& c : flat.candidates) EXPECT_NEAR(c.criterion, 1.0, 1e-6) << c.alpha;
}

TEST(ChooseAlpha, CompensatesANearlyConstantMapForGlossyLobes) {
    // Within 5% of constant, mild compensation changes nothing (the density stays nearly
    // uniform), but alpha = 1 leaves the environment technique only the brighter texels
    // and hands the rest to BSDF sampling, which is nearly noise-free under a constant
    // sky: the exact variance drops by about 20% for Phong and GGX (measured variances
    // at 20000 estimates per point agree: 0.79 and 0.76).
    RgbImage ripples = test::random_map(64, 32, 5, 0);
    for (Rgb& p : ripples.pixels) p = {0.5f + 0.05f * p.r, 0.5f + 0.05f * p.g, 0.5f + 0.05f * p.b};
    const AlphaChoice c = choose_alpha(ripples, {}, quick({Bsdf::phong(50), Bsdf::ggx(0.1f)}));
    for (size_t b = 0; b < 2; ++b) {
        EXPECT_EQ(c.bsdf_alphas[b], 1.0f) << b;
        for (const AlphaCandidate& a : c.candidates) {
            if (a.alpha < 1) {
                EXPECT_GT(a.per_bsdf[b], 0.99) << a.alpha;
            } else if (a.alpha == 1) {
                EXPECT_LT(a.per_bsdf[b], 0.85);
            }
        }
    }
}

TEST(ChooseAlpha, CompensatesForLambertUnderASun) {
    const AlphaChoice c = choose_alpha(test::sun_sky_map(256, 128), {}, quick({Bsdf::lambert()}));
    EXPECT_GT(c.bsdf_alphas[0], 0.0f);
    EXPECT_GT(c.alpha, 0.0f);
    const auto chosen = std::find_if(c.candidates.begin(), c.candidates.end(),
                                     [&](const AlphaCandidate& a) { return a.alpha == c.alpha; });
    ASSERT_NE(chosen, c.candidates.end());
    EXPECT_LT(chosen->criterion, 0.9);  // a clear gain, not a tie broken by rounding
    for (const AlphaCandidate& a : c.candidates) EXPECT_GE(a.criterion, chosen->criterion);
    EXPECT_EQ(c.width, 128u);  // downsampled to the default 128 texels
}

TEST(ChooseAlpha, CriterionIsTheExactVarianceRatioOnTheDownsampledMap) {
    const RgbImage image = test::sun_sky_map(64, 32);
    AlphaOptions o = quick({Bsdf::phong(20)});
    o.candidates = {0.5f};
    const AlphaChoice c = choose_alpha(image, {}, o);
    EnvMapOptions plain_options, comp_options;
    plain_options.compensation.enabled = false;
    comp_options.compensation.alpha = 0.5f;
    const EnvMap plain = build_env_map(image, plain_options), comp = build_env_map(image, comp_options);
    const auto ratios =
        geometric_mean_ratios(exact_variances(comp, Technique::parse("mis-balance-comp"), {}, o.bsdfs, o.points, 1),
                              exact_variances(plain, Technique::parse("mis-balance"), {}, o.bsdfs, o.points, 1), 1);
    ASSERT_EQ(c.candidates.size(), 2u);
    EXPECT_DOUBLE_EQ(c.candidates[1].per_bsdf[0], ratios[0]);
    EXPECT_DOUBLE_EQ(c.candidates[1].criterion, ratios[0]);  // one BSDF: the same mean
}

TEST(GeometricMeanRatios, SkipsPairsWithoutVariance) {
    const std::vector<double> v = {2, 8, 0, 5}, base = {1, 2, 1, 5};  // 2 BSDFs x 2 points
    const auto r = geometric_mean_ratios(v, base, 2);
    EXPECT_DOUBLE_EQ(r[0], std::sqrt(2.0 * 4.0));
    EXPECT_DOUBLE_EQ(r[1], 1.0);  // the dark point left out
    EXPECT_THROW(geometric_mean_ratios(v, std::vector<double>(3), 2), std::invalid_argument);
}

}  // namespace
}  // namespace envmis
