// Specification of maps turned at render time (rotated.h): a rotation turns directions in
// and out and leaves densities alone, so a rotated sampler passes the same statistical
// checks as the unrotated one, measured in the renderer's frame with a rotation computed
// independently here (Rodrigues' formula in double).
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "binned_checks.h"
#include "envmis/build/bins.h"
#include "envmis/build/env_map.h"
#include "envmis/sampling/rotated.h"
#include "errors.h"
#include "maps.h"
#include "stats.h"

namespace envmis {
namespace {

using test::Rng;

const double kLevel = test::sidak_level(0.01, 6);

// The turn by `radians` about the unit axis, in double: world = M local.
struct Turn {
    double m[3][3];
    Turn(Vec3 axis, double radians) {
        const double l = std::sqrt(double{axis.x} * axis.x + double{axis.y} * axis.y + double{axis.z} * axis.z);
        const double x = axis.x / l, y = axis.y / l, z = axis.z / l, c = std::cos(radians), s = std::sin(radians);
        const double t = 1 - c;
        const double rows[3][3] = {{t * x * x + c, t * x * y - s * z, t * x * z + s * y},
                                   {t * x * y + s * z, t * y * y + c, t * y * z - s * x},
                                   {t * x * z - s * y, t * y * z + s * x, t * z * z + c}};
        std::copy(&rows[0][0], &rows[0][0] + 9, &m[0][0]);
    }
    // M^T d: the map's own direction of a renderer's one.
    Vec3 to_local(Vec3 d) const {
        return {static_cast<float>(m[0][0] * d.x + m[1][0] * d.y + m[2][0] * d.z),
                static_cast<float>(m[0][1] * d.x + m[1][1] * d.y + m[2][1] * d.z),
                static_cast<float>(m[0][2] * d.x + m[1][2] * d.y + m[2][2] * d.z)};
    }
};

const Vec3 kAxis{0.3f, -0.5f, 0.8f};
const float kAngle = 1.1f;

EnvMap sky(bool compensate) {
    EnvMapOptions o;
    o.compensation.enabled = compensate;
    return build_env_map(test::sun_sky_map(64, 32), o);
}

TEST(Rotation, AboutAnAxisTurnsByTheRightHandRule) {
    const Rotation r = Rotation::about({0, 0, 2}, static_cast<float>(kPi / 2));
    const Vec3 y = r.to_world({1, 0, 0});
    EXPECT_NEAR(y.x, 0, 1e-7);
    EXPECT_NEAR(y.y, 1, 1e-7);
    EXPECT_NEAR(y.z, 0, 1e-7);
    const Vec3 back = r.to_local(y);
    EXPECT_NEAR(back.x, 1, 1e-7);
    const Rotation up = Rotation::about_up(Axes::parse("y-up"), static_cast<float>(kPi / 2));
    const Vec3 turned = up.to_world({0, 0, 1});  // about world +y: z goes to x
    EXPECT_NEAR(turned.x, 1, 1e-7);
    EXPECT_NEAR(turned.z, 0, 1e-7);
}

TEST(Rotation, FromRowsRefusesScalesShearsReflectionsAndNonFiniteAxes) {
    const float identity[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    EXPECT_EQ(Rotation::from_rows(identity).m[1][1], 1.0f);
    const float scaled[3][3] = {{2, 0, 0}, {0, 2, 0}, {0, 0, 2}};
    const float sheared[3][3] = {{1, 0.1f, 0}, {0, 1, 0}, {0, 0, 1}};
    const float mirrored[3][3] = {{-1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    test::expect_error<std::invalid_argument>([&] { Rotation::from_rows(scaled); }, {"row 0", "not a unit vector"});
    test::expect_error<std::invalid_argument>([&] { Rotation::from_rows(sheared); }, {"row 0", "not a unit vector"});
    test::expect_error<std::invalid_argument>([&] { Rotation::from_rows(mirrored); }, {"reflection", "--axes"});
    EXPECT_THROW(Rotation::about({0, 0, 0}, 1), std::invalid_argument);
    EXPECT_THROW(Rotation::about({NAN, 0, 1}, 1), std::invalid_argument);
    EXPECT_THROW(Rotation::about({0, 0, 1}, INFINITY), std::invalid_argument);
}

TEST(Rotated, DirectionsFollowTheDensityTurned) {
    for (bool compensate : {false, true}) {
        const EnvMap map = sky(compensate);
        const Rotated<EnvMapView> turned{map.view(), Rotation::about(kAxis, kAngle)};
        const Turn turn(kAxis, kAngle);
        // Texel masses from the unrotated pdf at texel centres (the documented density).
        const uint32_t w = map.width(), h = map.height();
        std::vector<double> expected(size_t{w} * h), observed(expected.size());
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t x = 0; x < w; ++x)
                expected[size_t{y} * w + x] =
                    map.view().pdf_uv({(x + 0.5f) / w, (y + 0.5f) / h}) * std::sin(kPi * (y + 0.5) / h);
        const double total = std::accumulate(expected.begin(), expected.end(), 0.0);
        const size_t n = 200000;
        for (double& e : expected) e *= n / total;
        // Float rounding in the turn may carry a sample over a texel border (envmap.h):
        // where that border is a compensated density's edge, the sample lands in a texel
        // of density 0. Rare; counted, then left out of the test.
        Rng rng(31 + compensate);
        size_t over_edge = 0;
        for (size_t i = 0; i < n; ++i) {
            const size_t t = test::equirect_texel_of(turn.to_local(turned.sample(rng.uniform2()).direction), w, h);
            if (expected[t] == 0)
                ++over_edge;
            else
                observed[t] += 1;
        }
        EXPECT_LE(over_edge, n / 10000);
        for (double& e : expected) e *= static_cast<double>(n - over_edge) / n;
        const auto chi = test::chi_square(expected, observed);
        EXPECT_GT(chi.p_value, kLevel) << "compensate=" << compensate << ": " << chi.describe();
    }
}

TEST(Rotated, PdfIntegratesToOneAndAgreesWithSamples) {
    // The midpoint rule meets the turned texels' edges at random: a map without a sun
    // keeps its error small.
    EnvMapOptions o;
    const EnvMap smooth = build_env_map(test::random_map(24, 12, 36), o);
    const Rotated<EnvMapView> turned_smooth{smooth.view(), Rotation::about(kAxis, kAngle)};
    const double integral = test::sphere_integral(512, 1024, [&](Vec3 d) { return turned_smooth.pdf(d); });
    EXPECT_NEAR(integral, 1.0, 2e-3);
    const EnvMap map = sky(true);
    const Rotated<EnvMapView> turned{map.view(), Rotation::about(kAxis, kAngle)};
    Rng rng(32);
    int edge_cases = 0;
    const int n = 50000;
    for (int i = 0; i < n; ++i) {
        const EnvSample s = turned.sample(rng.uniform2());
        ASSERT_NEAR(length(s.direction), 1.0f, 1e-5f);
        const EnvMapView::Lookup l = turned.lookup(s.direction);
        if (std::abs(l.pdf - s.pdf) > 1e-3f * s.pdf || l.radiance.r != s.radiance.r) ++edge_cases;
    }
    EXPECT_LT(edge_cases, n / 500);
}

// Batch forms, on every length around the block size: the bits of single calls.
TEST(Rotated, ManyCallsAreBitIdenticalToSingleCalls) {
    const EnvMap map = sky(true);
    const Rotated<EnvMapView> turned{map.view(), Rotation::about(kAxis, kAngle)};
    Rng rng(33);
    for (uint32_t n : {0u, 1u, 255u, 256u, 257u, 600u}) {
        std::vector<float> x(n), y(n), z(n), u(n), v(n), out[7];
        for (auto& o : out) o.resize(n);
        for (uint32_t i = 0; i < n; ++i) {
            const Vec3 d = normalize(Vec3{rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f});
            x[i] = d.x, y[i] = d.y, z[i] = d.z, u[i] = rng.uniform(), v[i] = rng.uniform();
        }
        lookup_many(turned, {x.data(), y.data(), z.data()},
                    {out[0].data(), out[1].data(), out[2].data(), out[3].data()}, n);
        for (uint32_t i = 0; i < n; ++i) {
            const EnvMapView::Lookup l = turned.lookup({x[i], y[i], z[i]});
            ASSERT_EQ(bit_cast<uint32_t>(out[3][i]), bit_cast<uint32_t>(l.pdf)) << i;
            ASSERT_EQ(bit_cast<uint32_t>(out[0][i]), bit_cast<uint32_t>(l.radiance.r)) << i;
        }
        sample_many(
            turned, {u.data(), v.data()},
            {out[0].data(), out[1].data(), out[2].data(), out[3].data(), out[4].data(), out[5].data(), out[6].data()},
            n);
        for (uint32_t i = 0; i < n; ++i) {
            const EnvSample s = turned.sample({u[i], v[i]});
            ASSERT_EQ(bit_cast<uint32_t>(out[0][i]), bit_cast<uint32_t>(s.direction.x)) << i;
            ASSERT_EQ(bit_cast<uint32_t>(out[1][i]), bit_cast<uint32_t>(s.direction.y)) << i;
            ASSERT_EQ(bit_cast<uint32_t>(out[2][i]), bit_cast<uint32_t>(s.direction.z)) << i;
            ASSERT_EQ(bit_cast<uint32_t>(out[3][i]), bit_cast<uint32_t>(s.pdf)) << i;
        }
    }
}

// A normal-aware map turned: the renderer's normal picks the bin its turned-back normal
// picks unrotated, and that bin's samples come out turned, with their density.
TEST(RotatedBinned, BinsFollowTheTurnedNormalAndSamplesTheirDensity) {
    const EnvMap plain = test::plain_map(test::sun_sky_map(64, 32));
    BinnedOptions options;
    options.bins_per_side = 5;
    const BinnedEnvMap binned = build_bins(plain, options);
    const BinnedEnvMapView view = binned.view();
    const Rotation rotation = Rotation::about(kAxis, kAngle);
    const RotatedBinned turned{&view, rotation};
    const Turn turn(kAxis, kAngle);
    Rng rng(34);
    for (const Vec3 normal : test::test_normals(5)) {
        const Vec3 world_normal = rotation.to_world(normal);
        const float choice = rng.uniform();
        const Rotated<BinView> bin = turned.bin({world_normal}, 0, choice);
        const BinView unrotated = view.bin({rotation.to_local(world_normal)}, 0, choice);
        ASSERT_EQ(bin.view.cells.start, unrotated.cells.start);
        // Chi-square of turned samples against the bin's texel probabilities.
        const std::vector<double> p = test::texel_probabilities(unrotated, plain);
        const size_t n = 100000;
        std::vector<double> expected(p.size()), observed(p.size());
        for (size_t i = 0; i < p.size(); ++i) expected[i] = p[i] * n;
        for (size_t i = 0; i < n; ++i) {
            const EnvSample s = bin.sample(rng.uniform2());
            observed[test::equirect_texel_of(turn.to_local(s.direction), plain.width(), plain.height())] += 1;
        }
        const auto chi = test::chi_square(expected, observed);
        EXPECT_GT(chi.p_value, test::kBinnedLevel) << chi.describe();
    }
}

TEST(RotatedBinned, ManyCallsAreBitIdenticalToSingleCalls) {
    const EnvMap plain = test::plain_map(test::sun_sky_map(64, 32));
    BinnedOptions options;
    options.bins_per_side = 5;
    const BinnedEnvMap binned = build_bins(plain, options);
    const BinnedEnvMapView view = binned.view();
    const RotatedBinned turned{&view, Rotation::about(kAxis, kAngle)};
    Rng rng(35);
    const uint32_t n = 300;
    std::vector<float> ax(n), ay(n), az(n), vc(n), x(n), y(n), z(n), choices(n), u(n), v(n), out[7];
    for (auto& o : out) o.resize(n);
    for (uint32_t i = 0; i < n; ++i) {
        const Vec3 a = normalize(Vec3{rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f});
        const Vec3 d = normalize(Vec3{rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f});
        ax[i] = a.x, ay[i] = a.y, az[i] = a.z, x[i] = d.x, y[i] = d.y, z[i] = d.z;
        choices[i] = rng.uniform(), u[i] = rng.uniform(), v[i] = rng.uniform(), vc[i] = rng.uniform();
    }
    lookup_many(turned, 1, {ax.data(), ay.data(), az.data(), vc.data()}, choices.data(), {x.data(), y.data(), z.data()},
                {out[0].data(), out[1].data(), out[2].data(), out[3].data()}, n);
    for (uint32_t i = 0; i < n; ++i) {
        const EnvMapView::Lookup l =
            turned.bin({{ax[i], ay[i], az[i]}, vc[i]}, 1, choices[i]).lookup({x[i], y[i], z[i]});
        ASSERT_EQ(bit_cast<uint32_t>(out[3][i]), bit_cast<uint32_t>(l.pdf)) << i;
    }
    sample_many(
        turned, 1, {ax.data(), ay.data(), az.data(), vc.data()}, choices.data(), {u.data(), v.data()},
        {out[0].data(), out[1].data(), out[2].data(), out[3].data(), out[4].data(), out[5].data(), out[6].data()}, n);
    for (uint32_t i = 0; i < n; ++i) {
        const EnvSample s = turned.bin({{ax[i], ay[i], az[i]}, vc[i]}, 1, choices[i]).sample({u[i], v[i]});
        ASSERT_EQ(bit_cast<uint32_t>(out[0][i]), bit_cast<uint32_t>(s.direction.x)) << i;
        ASSERT_EQ(bit_cast<uint32_t>(out[2][i]), bit_cast<uint32_t>(s.direction.z)) << i;
        ASSERT_EQ(bit_cast<uint32_t>(out[3][i]), bit_cast<uint32_t>(s.pdf)) << i;
    }
}

}  // namespace
}  // namespace envmis
