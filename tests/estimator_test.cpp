// Specification of the direct-lighting estimators (estimator.h): every valid technique
// is unbiased against the quadrature reference on a synthetic sun map and real maps,
// compensation pays off where it should, and the biased combination is refused.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "envmis/estimator.h"
#include "envmis/io/image_io.h"
#include "envmis/quadrature.h"
#include "envmis/statistics.h"
#include "maps.h"

namespace envmis {
namespace {

struct Maps {
    std::string name;
    EnvMap plain, compensated;
};

Maps make_maps(std::string name, const RgbImage& image, LumaCoefficients luma = {}) {
    EnvMapOptions o;
    o.luma = luma;
    o.compensation.enabled = false;
    EnvMap plain(image, o);
    o.compensation.enabled = true;
    return {std::move(name), std::move(plain), EnvMap(image, o)};
}

Maps load_maps(const std::string& file) {
    const io::LoadedImage image = io::load_image(std::string(ENVMIS_DATA_DIR) + "/envmaps/" + file);
    return make_maps(file, image.image, image.luma);
}

const std::vector<const char*> kTechniques = {"env", "bsdf", "mis-balance", "mis-power", "mis-balance-comp",
                                              "mis-power-comp"};

std::vector<ShadingPoint> points() {
    return {{{0, 0, 1}, normalize(Vec3{0.3f, 0.2f, 1})}, {normalize(Vec3{0.7f, -0.2f, 0.3f}), normalize(Vec3{0.4f, 0.5f, 0.6f})}};
}

void expect_unbiased(const Maps& maps, uint64_t seed) {
    for (const Bsdf& bsdf : {Bsdf::lambert(), Bsdf::phong(50), Bsdf::ggx(0.1f)})
        for (const ShadingPoint& p : points()) {
            const double reference = reflected_radiance(maps.plain, bsdf, p, {1e-5, 32}).luminance;
            for (const char* name : kTechniques) {
                const Technique t = Technique::parse(name);
                const EnvMap& env = t.compensated ? maps.compensated : maps.plain;
                const DirectLightingEstimator estimator(env, t);
                Pcg32 rng(seed++);
                RunningStats stats;
                const int n = 50000;
                for (int i = 0; i < n; ++i) stats.add(luminance(estimator.estimate(p, bsdf, rng), env.options().luma));
                // The exact variance gives a trustworthy standard error even where rare,
                // bright samples (a small sun hit by BSDF sampling) make the sample variance
                // unreliable.
                const double se = std::sqrt(exact_variance(env, t, {}, bsdf, p, 4) / n);
                EXPECT_NEAR(stats.mean(), reference, 4 * se + 1e-6 * reference)
                    << maps.name << " " << bsdf.name() << " " << name << " normal.z=" << p.normal.z;
            }
        }
}

TEST(Estimator, UnbiasedOnASyntheticSunMap) { expect_unbiased(make_maps("sun", test::sun_sky_map(256, 128)), 1); }
TEST(Estimator, UnbiasedOnASunnyPhotographedMap) { expect_unbiased(load_maps("rooitou_park_1k.hdr"), 1000); }
TEST(Estimator, UnbiasedOnALossyExrWithNegativePixels) { expect_unbiased(load_maps("city.exr"), 2000); }

TEST(Estimator, CompensationLowersLambertVarianceUnderASunnyMap) {
    // Over normals spread evenly over the sphere (geometric mean of the per-normal
    // variance ratios), as `envmis compare` reports it. Single normals can go either way:
    // one facing the sun gains little from compensation.
    const Maps maps = load_maps("rooitou_park_1k.hdr");
    const Bsdf lambert = Bsdf::lambert();
    double log_ratio = 0;
    const int k = 12;
    for (int i = 0; i < k; ++i) {
        const double z = 1 - (2 * i + 1.0) / k, r = std::sqrt(1 - z * z), phi = 2.399963 * i;
        const Vec3 n{static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)), static_cast<float>(z)};
        const ShadingPoint p{n, n};
        const double plain = exact_variance(maps.plain, Technique::parse("mis-balance"), {}, lambert, p, 2);
        const double compensated = exact_variance(maps.compensated, Technique::parse("mis-balance-comp"), {}, lambert, p, 2);
        log_ratio += std::log(compensated / plain) / k;
    }
    EXPECT_LT(std::exp(log_ratio), 0.9);
}

TEST(Estimator, RefusesEnvironmentSamplingAloneOverACompensatedDensity) {
    const Maps maps = make_maps("sun", test::sun_sky_map(64, 32));
    try {
        DirectLightingEstimator(maps.compensated, Technique::parse("env-comp"));
        FAIL() << "accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("biased"), std::string::npos) << e.what();
    }
    EXPECT_NO_THROW(DirectLightingEstimator(maps.compensated, Technique::parse("mis-balance-comp")));
    EXPECT_THROW(DirectLightingEstimator(maps.plain, Technique::parse("mis-balance"), {0, 2}), std::invalid_argument);
}

TEST(Technique, NamesRoundTrip) {
    for (const char* name : {"env", "env-comp", "bsdf", "mis-balance", "mis-power", "mis-balance-comp", "mis-power-comp"})
        EXPECT_EQ(Technique::parse(name).name(), name);
    EXPECT_THROW(Technique::parse("mis"), std::invalid_argument);
}

TEST(MisWeight, BalanceAndPowerSumToOne) {
    for (Heuristic h : {Heuristic::balance, Heuristic::power})
        for (auto [a, b] : {std::pair{1.0f, 3.0f}, std::pair{0.2f, 0.0f}, std::pair{5.0f, 5.0f}})
            EXPECT_NEAR(mis_weight(h, a, b) + mis_weight(h, b, a), 1.0f, 1e-6f);
    EXPECT_FLOAT_EQ(mis_weight(Heuristic::balance, 1, 3), 0.25f);
    EXPECT_FLOAT_EQ(mis_weight(Heuristic::power, 1, 3), 0.1f);
}

}  // namespace
}  // namespace envmis
