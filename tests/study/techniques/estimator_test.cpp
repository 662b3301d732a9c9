// Specification of the direct-lighting estimators (estimator.h): every valid technique
// is unbiased against the quadrature reference on a synthetic sun map and real maps,
// compensation pays off where it should, and the biased combination is refused.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>

#include "envmis/build/env_map.h"
#include "envmis/io/image_io.h"
#include "envmis/study/comparison/comparison.h"
#include "envmis/study/reference/quadrature.h"
#include "envmis/study/shading/frame.h"
#include "envmis/study/statistics/statistics.h"
#include "envmis/study/techniques/estimator.h"
#include "estimates.h"
#include "forced_path.h"
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
    EnvMap plain = build_env_map(image, o);
    o.compensation.enabled = true;
    return {std::move(name), std::move(plain), build_env_map(image, o)};
}

Maps load_maps(const std::string& file) {
    const io::LoadedImage image = io::load_image(std::string(ENVMIS_DATA_DIR) + "/envmaps/" + file);
    return make_maps(file, image.image, image.luma);
}

// Every technique but env-comp, which is refused (see below), and the -bins ones, which
// sample a binned map (binned_estimator_test.cpp).
std::vector<Technique> valid_techniques() {
    std::vector<Technique> t;
    for (const Technique& technique : Technique::all())
        if (technique.name() != "env-comp" && !technique.bins) t.push_back(technique);
    return t;
}

std::vector<ShadingPoint> points() {
    return {{{0, 0, 1}, normalize(Vec3{0.3f, 0.2f, 1})},
            {normalize(Vec3{0.7f, -0.2f, 0.3f}), normalize(Vec3{0.4f, 0.5f, 0.6f})}};
}

// The standard error of the mean of n estimates. The exact variance gives a trustworthy
// one even where rare, bright samples (a small sun hit by BSDF sampling) make the sample
// variance unreliable. Adaptive and mixture techniques have no exact variance: the
// larger of their sample variance and balance MIS's exact variance over the same
// (compensated, for the mixture) density stands in.
double standard_error(const Maps& maps, Technique t, const Bsdf& bsdf, const ShadingPoint& p,
                      const RunningStats& stats) {
    const double n = static_cast<double>(stats.count());
    if (!t.adaptive() && !t.mixture)
        return std::sqrt(exact_variance(t.compensated ? maps.compensated : maps.plain, t, {}, bsdf, p, 4) / n);
    const Technique balance{Strategy::mis, Heuristic::balance, t.compensated};
    const double balance_variance =
        exact_variance(t.compensated ? maps.compensated : maps.plain, balance, {}, bsdf, p, 4);
    return std::sqrt(std::max(stats.variance(), balance_variance) / n);
}

void expect_unbiased(const Maps& maps, uint64_t seed) {
    for (const Bsdf& bsdf : {Bsdf::lambert(), Bsdf::phong(50), Bsdf::ggx(0.1f)})
        for (const ShadingPoint& p : points()) {
            const double reference = reflected_radiance(maps.plain, bsdf, p, {1e-5, 32}).luminance;
            for (const Technique& t : valid_techniques()) {
                const DirectLightingEstimator estimator(maps.plain, maps.compensated, t);
                Pcg32 rng(seed++);
                PointState state;
                RunningStats stats;
                for (int i = 0; i < 50000; ++i)
                    stats.add(luminance(estimator.estimate(p, bsdf, rng, state), maps.plain.options().luma));
                EXPECT_NEAR(stats.mean(), reference, 4 * standard_error(maps, t, bsdf, p, stats) + 1e-6 * reference)
                    << maps.name << " " << bsdf.name() << " " << t.name() << " normal.z=" << p.normal.z;
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
    const auto normals = sphere_points(12);
    const double k = static_cast<double>(normals.size());
    for (const ShadingPoint& p : normals) {
        const double plain = exact_variance(maps.plain, Technique::parse("mis-balance"), {}, lambert, p, 2);
        const double compensated =
            exact_variance(maps.compensated, Technique::parse("mis-balance-comp"), {}, lambert, p, 2);
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
    // A sample count that wraps around 32 bits.
    EXPECT_THROW(DirectLightingEstimator(maps.plain, Technique::parse("mis-balance"), {0xFFFFFF00u, 0x105u}),
                 std::invalid_argument);
}

TEST(Estimator, OptimalMisLowersLambertVarianceUnderASunnyMap) {
    // Geometric mean over normals of measured variance ratios against balance MIS over
    // the same density: optimal weights may lose a little where balance is already near
    // optimal, but not on average.
    const Maps maps = load_maps("rooitou_park_1k.hdr");
    const Bsdf lambert = Bsdf::lambert();
    for (const char* pair : {"mis-optimal", "mis-optimal-comp"}) {
        const Technique optimal = Technique::parse(pair);
        const Technique balance{Strategy::mis, Heuristic::balance, optimal.compensated};
        double log_ratio = 0;
        const auto normals = sphere_points(8);
        const double k = static_cast<double>(normals.size());
        for (uint64_t i = 0; i < normals.size(); ++i) {
            const ShadingPoint& p = normals[i];
            RunningStats stats[2];
            for (int j = 0; j < 2; ++j) {
                const DirectLightingEstimator estimator(maps.plain, maps.compensated, j ? optimal : balance);
                Pcg32 rng(77, i);
                PointState state;
                for (int e = 0; e < 4096; ++e) stats[j].add(luminance(estimator.estimate(p, lambert, rng, state), {}));
            }
            log_ratio += std::log(stats[1].variance() / stats[0].variance()) / k;
        }
        EXPECT_LT(std::exp(log_ratio), 0.95) << pair;
    }
}

TEST(Estimator, OptimalMisFallsBackToBalanceOnASingularSystemAndSaysSo) {
    // Viewed from below the surface, the BSDF has no density anywhere: its row of the
    // system is zero, and no alpha is learnt.
    const Maps maps = make_maps("constant", test::constant_map(64, 32, {1, 1, 1}));
    const DirectLightingEstimator optimal(maps.plain, maps.compensated, Technique::parse("mis-optimal"));
    const ShadingPoint below{{0, 0, 1}, normalize(Vec3{0.3f, 0, -1})};
    Pcg32 rng(5);
    PointState state;
    for (int i = 0; i < 64; ++i) EXPECT_EQ(optimal.estimate(below, Bsdf::lambert(), rng, state).g, 0.0f);
    EXPECT_FALSE(state.optimal.solved);
    EXPECT_EQ(state.ill_conditioned, 4u);  // at 8, 16, 32 and 64 estimates
    for (const auto& row : state.optimal.alpha)
        for (float a : row) EXPECT_EQ(a, 0.0f);
}

TEST(Estimator, OptimalMisSplitsCollinearControlVariatesEvenly) {
    // A constant map: compensation falls back to the plain density, so the mixture's
    // control variates hold the same density twice. The ridge keeps the system solvable
    // and shares the coefficient between the two copies.
    const Maps maps = make_maps("constant", test::constant_map(64, 32, {1, 1, 1}));
    ASSERT_EQ(maps.compensated.stats().fallback, DensityFallback::uncompensated);
    const DirectLightingEstimator all(maps.plain, maps.compensated, Technique::parse("mis-optimal-all"));
    Pcg32 rng(5);
    PointState state;
    for (int i = 0; i < 64; ++i) all.estimate({}, Bsdf::lambert(), rng, state);
    EXPECT_TRUE(state.optimal.solved);
    EXPECT_EQ(state.ill_conditioned, 0u);
    for (int c = 0; c < 3; ++c) {
        EXPECT_NE(state.optimal.alpha[0][c], 0.0f);
        EXPECT_NEAR(state.optimal.alpha[0][c], state.optimal.alpha[1][c], 1e-5f * std::abs(state.optimal.alpha[0][c]));
    }
}

TEST(Estimator, MultiSampleBalanceMisBeatsOneSampleMis) {
    // Stratification over the techniques: drawing exactly one sample of each never has
    // higher variance than picking techniques at random (exact variances).
    const Maps maps = load_maps("rooitou_park_1k.hdr");
    for (const Bsdf& bsdf : {Bsdf::lambert(), Bsdf::phong(50)})
        for (const ShadingPoint& p : points()) {
            const double multi = exact_variance(maps.plain, Technique::parse("mis-balance"), {}, bsdf, p, 2);
            const double one = exact_variance(maps.plain, Technique::parse("one-sample"), {}, bsdf, p, 2);
            EXPECT_LE(multi, one * (1 + 1e-9)) << bsdf.name();
        }
}

TEST(Estimator, MixtureNeedsBothMaps) {
    const Maps maps = make_maps("sun", test::sun_sky_map(64, 32));
    EXPECT_THROW(DirectLightingEstimator(maps.compensated, Technique::parse("mis-optimal-all")), std::invalid_argument);
    EXPECT_THROW(exact_variance(maps.plain, Technique::parse("mis-optimal"), {}, Bsdf::lambert(), {}, 1),
                 std::invalid_argument);
}

// The random numbers' order is part of the estimator's contract (results are
// reproducible from a seed): the environment samples take theirs first (the mixture one
// more each, for its choice of density), then the BSDF samples, two each. An estimate
// equals the sum computed here by hand from those numbers, with the weights of its
// technique (balance: f / sum q; power: f q_k / sum q^2; a single technique: f / (n p),
// n its whole sample count), and leaves the generator exactly past them.
TEST(Estimator, FixedWeightEstimatesUseTheRandomNumbersInTheirDocumentedOrder) {
    const Maps maps = make_maps("sun", test::sun_sky_map(128, 64));
    const ShadingPoint point{normalize(Vec3{0.3f, -0.2f, 1}), normalize(Vec3{-0.5f, 0.4f, 1})};
    const Frame frame = Frame::from_normal(point.normal);
    const Vec3 wo = frame.to_local(point.wo);
    for (const Bsdf& bsdf : {Bsdf::lambert(), Bsdf::ggx(0.2f)})
        for (const Allocation a : {Allocation{1, 1}, Allocation{2, 3}})
            for (const char* name :
                 {"mis-balance", "mis-balance-comp", "mis-balance-all", "mis-power", "mis-power-comp", "env", "bsdf"}) {
                const Technique t = Technique::parse(name);
                const DirectLightingEstimator estimator(maps.plain, maps.compensated, t, a);
                const EnvMap& sampled = t.compensated && !t.mixture ? maps.compensated : maps.plain;
                const bool power = t.strategy == Strategy::mis && t.heuristic == Heuristic::power;
                const uint32_t n_env =
                    t.strategy == Strategy::env ? a.total() : (t.strategy == Strategy::bsdf ? 0 : a.env);
                const uint32_t n_bsdf =
                    t.strategy == Strategy::bsdf ? a.total() : (t.strategy == Strategy::env ? 0 : a.bsdf);
                // Density of the environment technique at a direction: the mixture's is
                // the mean of both maps'.
                const auto env_pdf = [&](Vec3 w) {
                    return t.mixture ? 0.5f * (maps.compensated.pdf(w) + maps.plain.pdf(w)) : sampled.pdf(w);
                };
                for (uint64_t seed = 1; seed <= 50; ++seed) {
                    Pcg32 rng(seed), mine(seed);
                    const Rgb got = estimator.estimate(point, bsdf, rng);
                    double sum[3] = {};
                    // A sample of technique k (0: environment, 1: BSDF) with value f.
                    const auto add = [&](int k, Rgb f, float p_env, float p_bsdf) {
                        const double q[2] = {n_env * double(p_env), n_bsdf * double(p_bsdf)};
                        const double s = power ? q[k] / (q[0] * q[0] + q[1] * q[1]) : 1 / (q[0] + q[1]);
                        sum[0] += f.r * s, sum[1] += f.g * s, sum[2] += f.b * s;
                    };
                    for (uint32_t i = 0; i < n_env; ++i) {
                        const bool from_plain = t.mixture && mine.uniform() < 0.5f;
                        const EnvMap& map = t.mixture ? (from_plain ? maps.plain : maps.compensated) : sampled;
                        const EnvSample e = map.sample(mine.uniform2());
                        if (!(e.pdf > 0)) continue;
                        const Vec3 wi = frame.to_local(e.direction);
                        const Rgb f = bsdf.eval(wo, wi);
                        // The sampled density's pdf is the one the sample returned.
                        const float p_env =
                            !t.mixture ? e.pdf
                                       : 0.5f * (e.pdf + (from_plain ? maps.compensated : maps.plain).pdf(e.direction));
                        add(0, {e.radiance.r * f.r, e.radiance.g * f.g, e.radiance.b * f.b}, p_env, bsdf.pdf(wo, wi));
                    }
                    for (uint32_t i = 0; i < n_bsdf; ++i) {
                        const BsdfSample b = bsdf.sample(wo, mine.uniform2());
                        if (!(b.pdf > 0)) continue;
                        const Vec3 wi = frame.to_world(b.wi);
                        const Rgb l = sampled.eval(wi);
                        add(1, {l.r * b.value.r, l.g * b.value.g, l.b * b.value.b}, env_pdf(wi), b.pdf);
                    }
                    const float expected[3] = {static_cast<float>(sum[0]), static_cast<float>(sum[1]),
                                               static_cast<float>(sum[2])};
                    const float actual[3] = {got.r, got.g, got.b};
                    for (int c = 0; c < 3; ++c)
                        ASSERT_NEAR(actual[c], expected[c], 1e-4f * std::abs(expected[c]) + 1e-30f)
                            << name << " " << a.env << "+" << a.bsdf << " seed " << seed << " channel " << c;
                    ASSERT_EQ(rng.uniform(), mine.uniform())
                        << name << ": the generator is not exactly past the numbers used";
                }
            }
}

// Many estimates asked at once are the estimates one at a time would give, bit for
// bit, from the same random numbers: for every technique (those that run side by side
// and those that do not), for allocations within and beyond what runs side by side, and
// across the groups of 32 a request is split into. Adaptive techniques learn the same.
TEST(Estimator, ManyEstimatesAtOnceEqualTheSameEstimatesOneAtATime) {
    ENVMIS_SKIP_IF_FORCED_PATH_UNAVAILABLE();
    const Maps maps = make_maps("sun", test::sun_sky_map(128, 64));
    const ShadingPoint point{normalize(Vec3{0.3f, -0.2f, 1}), normalize(Vec3{-0.5f, 0.4f, 1})};
    for (const Bsdf& bsdf : {Bsdf::lambert(), Bsdf::phong(20), Bsdf::ggx(0.2f)})
        for (const Allocation a : {Allocation{1, 1}, Allocation{2, 3}, Allocation{5, 4}})
            for (const Technique& t : valid_techniques()) {
                const DirectLightingEstimator estimator(maps.plain, maps.compensated, t, a);
                test::expect_batch_equals_single(
                    estimator, point, bsdf,
                    t.name() + " " + bsdf.name() + " " + std::to_string(a.env) + "+" + std::to_string(a.bsdf));
            }
}

// The same for the glossy lobes, whose lanes run eight at a time where the CPU has AVX2:
// Phong from flat (n = 0) to nearly a mirror, GGX from rough to nearly a mirror, grey
// and coloured, seen head on (where GGX's visible-normal frame takes its fallback
// tangent), obliquely, at a grazing angle and from below the surface (which stays
// scalar), under a tilted normal too. The single techniques' sums see the BSDF's
// values and densities alone (bsdf) or its values at the environment's samples (env), so
// that a lane one bit off changes an estimate; the 100 estimates are three full groups
// of 32 and one of 4, padded to 8.
TEST(Estimator, GlossyEstimatesAtOnceEqualTheSameEstimatesOneAtATimeForEveryLobeAndView) {
    ENVMIS_SKIP_IF_FORCED_PATH_UNAVAILABLE();
    const Maps maps = make_maps("sun", test::sun_sky_map(128, 64));
    const Vec3 up{0, 0, 1}, tilted = normalize(Vec3{0.3f, -0.2f, 1});
    const std::vector<ShadingPoint> views = {{up, up},
                                             {up, normalize(Vec3{0.3f, 0.2f, 1})},
                                             {up, normalize(Vec3{0.9f, -0.4f, 0.02f})},
                                             {tilted, normalize(Vec3{-0.5f, 0.4f, 1})},
                                             {tilted, normalize(Vec3{0.2f, 0.3f, -1})}};
    const Rgb coloured{0.9f, 0.5f, 0.2f};
    for (const Bsdf& bsdf : {Bsdf::phong(0), Bsdf::phong(1.5f), Bsdf::phong(20, coloured), Bsdf::phong(1000),
                             Bsdf::ggx(0.001f), Bsdf::ggx(0.1f), Bsdf::ggx(0.5f, {0.5f, 0.5f, 0.5f}), Bsdf::ggx(1)})
        for (size_t v = 0; v < views.size(); ++v)
            for (const Allocation a : {Allocation{1, 1}, Allocation{2, 3}})
                for (const char* name : {"env", "bsdf", "mis-balance", "mis-power", "mis-balance-comp"}) {
                    const DirectLightingEstimator estimator(maps.plain, maps.compensated, Technique::parse(name), a);
                    test::expect_batch_equals_single(estimator, views[v], bsdf,
                                                     std::string(name) + " " + bsdf.name() + " " +
                                                         std::to_string(a.env) + "+" + std::to_string(a.bsdf) +
                                                         " view " + std::to_string(v));
                }
}

TEST(Technique, NamesRoundTrip) {
    std::vector<std::string> names;
    for (const Technique& t : Technique::all()) {
        EXPECT_EQ(Technique::parse(t.name()), t);
        names.push_back(t.name());
    }
    EXPECT_EQ(names.size(), 18u);
    for (const char* name :
         {"env", "env-comp", "bsdf", "mis-balance", "mis-power", "mis-balance-comp", "mis-power-comp", "mis-optimal",
          "mis-optimal-comp", "mis-balance-all", "mis-optimal-all", "mis-var", "mis-var-comp", "one-sample",
          "one-sample-comp", "mis-balance-bins", "mis-power-bins", "mis-optimal-bins"})
        EXPECT_EQ(Technique::parse(name).name(), name);
    EXPECT_THROW(Technique::parse("mis"), std::invalid_argument);
    EXPECT_THROW(Technique::parse("mis-power-all"), std::invalid_argument);
}

}  // namespace
}  // namespace envmis
