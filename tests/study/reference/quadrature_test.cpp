// Specification of the quadrature references (quadrature.h): they converge, they agree
// with closed forms, and the exact variance agrees with measured variances.
#include <gtest/gtest.h>

#include <cmath>

#include "envmis/build/bins.h"
#include "envmis/build/env_map.h"
#include "envmis/study/reference/quadrature.h"
#include "envmis/study/statistics/statistics.h"
#include "envmis/study/techniques/estimator.h"
#include "maps.h"

namespace envmis {
namespace {

EnvMapOptions plain() {
    EnvMapOptions o;
    o.compensation.enabled = false;
    return o;
}

TEST(Quadrature, ConstantWhiteSkyOnLambertGivesTheAlbedo) {
    const EnvMap map = build_env_map(test::constant_map(64, 32, {1, 1, 1}), plain());
    for (Vec3 n : {Vec3{0, 0, 1}, normalize(Vec3{0.3f, -0.5f, 0.2f})}) {
        const QuadratureResult r = reflected_radiance(map, Bsdf::lambert({0.5f, 0.6f, 0.7f}), {n, n}, {1e-5, 64});
        EXPECT_NEAR(r.value.r, 0.5, 2e-4);
        EXPECT_NEAR(r.value.b, 0.7, 2e-4);
        EXPECT_LE(r.error, 1e-5 * r.luminance);
    }
}

TEST(Quadrature, SubdivisionConverges) {
    const EnvMap map = build_env_map(test::sun_sky_map(128, 64), plain());
    const ShadingPoint p{normalize(Vec3{0.2f, 0.1f, 1}), normalize(Vec3{-0.3f, 0.4f, 1})};
    for (const Bsdf& bsdf : {Bsdf::lambert(), Bsdf::phong(50), Bsdf::ggx(0.1f)}) {
        double previous_change = INFINITY;
        QuadratureResult last = reflected_radiance(map, bsdf, p, {1, 1});
        for (int s = 2; s <= 16; s *= 2) {
            const QuadratureResult r = reflected_radiance(map, bsdf, p, {0, s});
            const double change = std::abs(r.luminance - last.luminance);
            // Monotone until float rounding of the result (1e-6 relative) is reached.
            EXPECT_LT(change, previous_change + 1e-6 * r.luminance) << bsdf.name() << " s=" << s;
            previous_change = change;
            last = r;
        }
        EXPECT_LT(previous_change, 1e-3 * last.luminance) << bsdf.name();
        const QuadratureResult adaptive = reflected_radiance(map, bsdf, p, {1e-4, 32});
        EXPECT_LE(adaptive.error, 1e-4 * adaptive.luminance) << bsdf.name();
    }
}

TEST(Quadrature, SingleBrightTexelMatchesItsClosedForm) {
    // One texel of radiance 1 elsewhere black: L_o = f cos at the texel times its solid angle.
    RgbImage image = test::constant_map(256, 128, {});
    image.pixels[40 * 256 + 100] = {1, 1, 1};
    const EnvMap map = build_env_map(image, plain());
    const ShadingPoint p{{0, 0, 1}, {0, 0, 1}};
    const double theta_top = kPi * 40 / 128, theta_bottom = kPi * 41 / 128;
    const double solid_angle = 2 * kPi / 256 * (std::cos(theta_top) - std::cos(theta_bottom));
    const double cos_centre = std::cos(kPi * 40.5 / 128);
    const QuadratureResult r = reflected_radiance(map, Bsdf::lambert({1, 1, 1}), p, {1e-7, 64});
    EXPECT_NEAR(r.luminance, cos_centre / kPi * solid_angle, 1e-4 * r.luminance);
}

TEST(Quadrature, ExactVarianceMatchesMeasuredVariance) {
    const RgbImage image = test::random_map(64, 32, 3, 1.5f);
    const EnvMap plain_map = build_env_map(image, plain()), compensated = build_env_map(image);
    const ShadingPoint p{normalize(Vec3{0.1f, 0.2f, 1}), normalize(Vec3{0.5f, 0, 1})};
    for (const Bsdf& bsdf : {Bsdf::lambert(), Bsdf::phong(20)})
        for (const char* name : {"env", "bsdf", "mis-balance", "mis-power", "mis-balance-comp"}) {
            const Technique t = Technique::parse(name);
            const EnvMap& env = t.compensated ? compensated : plain_map;
            const DirectLightingEstimator estimator(env, t);
            Pcg32 rng(11);
            RunningStats stats;
            for (int i = 0; i < 400000; ++i) stats.add(luminance(estimator.estimate(p, bsdf, rng), {}));
            const double exact = exact_variance(env, t, {}, bsdf, p, 8);
            EXPECT_NEAR(stats.variance(), exact, 0.03 * exact) << bsdf.name() << " " << name;
        }
}

// The same where the two techniques take different sample counts: a weight or a
// normalisation with the counts swapped gives another variance (one-sample MIS's too).
TEST(Quadrature, ExactVarianceMatchesMeasuredVarianceAtUnequalCounts) {
    const RgbImage image = test::random_map(64, 32, 3, 1.5f);
    const EnvMap plain_map = build_env_map(image, plain()), compensated = build_env_map(image);
    const ShadingPoint p{normalize(Vec3{0.1f, 0.2f, 1}), normalize(Vec3{0.5f, 0, 1})};
    for (const Allocation a : {Allocation{3, 1}, Allocation{1, 4}})
        for (const Bsdf& bsdf : {Bsdf::lambert(), Bsdf::phong(20)})
            for (const char* name : {"mis-balance", "mis-power", "one-sample", "mis-balance-comp"}) {
                const Technique t = Technique::parse(name);
                const EnvMap& env = t.compensated ? compensated : plain_map;
                const DirectLightingEstimator estimator(env, t, a);
                Pcg32 rng(11);
                RunningStats stats;
                for (int i = 0; i < 200000; ++i) stats.add(luminance(estimator.estimate(p, bsdf, rng), {}));
                const double exact = exact_variance(env, t, a, bsdf, p, 8);
                EXPECT_NEAR(stats.variance(), exact, 0.04 * exact)
                    << bsdf.name() << " " << name << " " << a.env << ":" << a.bsdf;
            }
}

// The exact variance of a -bins technique is that of the bin the point picks: a normal
// facing up and one facing down (another bin, another compensation) on the same map.
TEST(Quadrature, ExactVarianceOfBinnedMisMatchesMeasuredVariance) {
    const RgbImage image = test::random_map(64, 32, 3, 1.5f);
    const BinnedEnvMap binned = build_bins(build_env_map(image, plain()));
    const Technique t = Technique::parse("mis-balance-bins");
    const DirectLightingEstimator estimator(binned, t);
    for (const ShadingPoint& p : {ShadingPoint{normalize(Vec3{0.1f, 0.2f, 1}), normalize(Vec3{0.5f, 0, 1})},
                                  ShadingPoint{normalize(Vec3{0.3f, -0.2f, -1}), normalize(Vec3{0, 0.4f, -1})}})
        for (const Bsdf& bsdf : {Bsdf::lambert(), Bsdf::phong(20)}) {
            Pcg32 rng(11);
            RunningStats stats;
            for (int i = 0; i < 400000; ++i) stats.add(luminance(estimator.estimate(p, bsdf, rng), {}));
            const double exact = exact_variance(binned, t, {}, bsdf, p, 8);
            EXPECT_NEAR(stats.variance(), exact, 0.03 * exact) << bsdf.name() << " normal.z=" << p.normal.z;
        }
    // The plain map's overload refuses a -bins technique rather than use the wrong density.
    EXPECT_THROW(exact_variance(binned.radiance_map(), t, {}, Bsdf::lambert(), {}, 1), std::invalid_argument);
}

}  // namespace
}  // namespace envmis
