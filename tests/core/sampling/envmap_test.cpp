// Specification of the environment-map sampler (envmap.h), checked against
// computations written independently here from the documented conventions.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "envmis/build/env_map.h"
#include "envmis/sampling/envmap.h"
#include "errors.h"
#include "forced_path.h"
#include "maps.h"
#include "stats.h"

namespace envmis {
namespace {

using test::Rng;

const double kLevel = test::sidak_level(0.01, 20);

// The documented density, computed from scratch: q(x, y) sin(theta_y), q = L or max(L - alpha Lbar, 0).
std::vector<double> reference_mass(const RgbImage& m, bool compensate, double alpha) {
    const uint32_t w = m.width, h = m.height;
    std::vector<double> lum(size_t{w} * h), mass(lum.size());
    double weighted = 0, weights = 0;
    for (uint32_t y = 0; y < h; ++y) {
        const double s = std::sin(kPi * (y + 0.5) / h);
        for (uint32_t x = 0; x < w; ++x) {
            const Rgb p = m.at(x, y);
            const double l = 0.2126 * std::max(p.r, 0.0f) + 0.7152 * std::max(p.g, 0.0f) + 0.0722 * std::max(p.b, 0.0f);
            lum[size_t{y} * w + x] = l;
            weighted += s * l, weights += s;
        }
    }
    const double threshold = compensate ? alpha * weighted / weights : 0.0;
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const double l = lum[size_t{y} * w + x];
            mass[size_t{y} * w + x] = std::max(l - threshold, 0.0) * std::sin(kPi * (y + 0.5) / h);
        }
    return mass;
}

void expect_directions_follow(const EnvMap& map, const std::vector<double>& mass, uint64_t seed) {
    const size_t n = std::max<size_t>(100000, 30 * mass.size());
    const double total = std::accumulate(mass.begin(), mass.end(), 0.0);
    std::vector<double> observed(mass.size()), expected(mass.size());
    for (size_t i = 0; i < mass.size(); ++i) expected[i] = n * mass[i] / total;
    Rng rng(seed);
    for (size_t i = 0; i < n; ++i)
        observed[test::equirect_texel_of(map.sample(rng.uniform2()).direction, map.width(), map.height())] += 1;
    const auto chi = test::chi_square(expected, observed);
    EXPECT_GT(chi.p_value, kLevel) << map.width() << "x" << map.height() << ": " << chi.describe();
}

// For a density proportional to sin(theta) of the row centre (constant and black maps):
// the exact solid-angle pdf at a sample, close to 1 / (4 pi) away from the poles.
void expect_sine_density(const EnvMap& map, uint64_t seed) {
    const uint32_t h = map.height();
    double mean_sin = 0;
    for (uint32_t y = 0; y < h; ++y) mean_sin += std::sin(kPi * (y + 0.5) / h) / h;
    Rng rng(seed);
    for (int i = 0; i < 1000; ++i) {
        const EnvSample s = map.sample(rng.uniform2());
        const double row_sin = std::sin(kPi * (std::floor(s.uv.y * h) + 0.5) / h);
        const double expected = row_sin / mean_sin / (2 * kPi * kPi * std::sin(kPi * s.uv.y));
        EXPECT_NEAR(s.pdf, expected, 1e-4 * expected);
    }
}

EnvMapOptions options(bool compensate, float alpha = 1.0f) {
    EnvMapOptions o;
    o.compensation = {compensate, alpha};
    return o;
}

TEST(EnvMap, DirectionsFollowTheDocumentedDensity) {
    uint64_t seed = 100;
    for (const RgbImage& image : {test::sun_sky_map(64, 32), test::random_map(40, 20, 1), test::random_map(7, 5, 2)})
        for (bool compensate : {false, true}) {
            const EnvMap map = build_env_map(image, options(compensate));
            expect_directions_follow(map, reference_mass(image, compensate, 1.0), seed++);
        }
}

// An equal-area map: texel (x, y) has mass q(x, y) (every texel covers 4 pi / (w h)),
// Lbar is the plain mean, and the solid-angle pdf is the image density / (4 pi).
TEST(EnvMap, EqualAreaMapsFollowTheirDensity) {
    uint64_t seed = 300;
    for (const RgbImage& image : {test::sun_sky_map(32, 32), test::random_map(24, 24, 5), test::random_map(5, 5, 6)})
        for (bool compensate : {false, true}) {
            EnvMapOptions o = options(compensate);
            o.mapping = Mapping::equal_area;
            const EnvMap map = build_env_map(image, o);
            const uint32_t w = image.width, h = image.height;
            std::vector<double> lum(size_t{w} * h), mass(lum.size());
            double mean = 0;
            for (size_t i = 0; i < lum.size(); ++i) {
                const Rgb p = image.pixels[i];
                lum[i] = 0.2126 * p.r + 0.7152 * p.g + 0.0722 * p.b;
                mean += lum[i] / static_cast<double>(lum.size());
            }
            EXPECT_NEAR(map.stats().mean_luminance, mean, 1e-6 * mean);
            for (size_t i = 0; i < lum.size(); ++i) mass[i] = std::max(lum[i] - (compensate ? mean : 0.0), 0.0);
            const double total = std::accumulate(mass.begin(), mass.end(), 0.0);

            const size_t n = std::max<size_t>(100000, 30 * mass.size());
            std::vector<double> observed(mass.size()), expected(mass.size());
            for (size_t i = 0; i < mass.size(); ++i) expected[i] = n * mass[i] / total;
            Rng rng(seed++);
            for (size_t i = 0; i < n; ++i) {
                const EnvSample s = map.sample(rng.uniform2());
                ASSERT_EQ(s.pdf, map.pdf_uv(s.uv));
                // Bins from the direction alone, through the inverse mapping.
                const Vec2 uv = equal_area_uv(s.direction);
                observed[size_t{detail::cell_of(uv.y, h)} * w + detail::cell_of(uv.x, w)] += 1;
                // The solid-angle pdf, from the mass of the sample's texel alone.
                const size_t own = size_t{detail::cell_of(s.uv.y, h)} * w + detail::cell_of(s.uv.x, w);
                const double expected_pdf = mass[own] / total * (w * h) / (4 * kPi);
                ASSERT_NEAR(s.pdf, expected_pdf, 1e-3 * expected_pdf + 1e-7 * w * h);
            }
            const auto chi = test::chi_square(expected, observed);
            EXPECT_GT(chi.p_value, kLevel) << w << "x" << h << " compensate=" << compensate << ": " << chi.describe();

            // Midpoint rule over the square, 4x finer than the texels, each point's pdf
            // taken from its direction: the integral of the pdf over the sphere is 1.
            double integral = 0;
            const uint32_t n4 = 4 * w;
            for (uint32_t j = 0; j < n4; ++j)
                for (uint32_t i = 0; i < n4; ++i)
                    integral += map.pdf(equal_area_direction({(i + 0.5f) / n4, (j + 0.5f) / n4}));
            EXPECT_NEAR(integral * 4 * kPi / (static_cast<double>(n4) * n4), 1.0, 1e-3)
                << w << "x" << h << " compensate=" << compensate;
        }
    EnvMapOptions o;
    o.mapping = Mapping::equal_area;
    EXPECT_THROW(build_env_map(test::random_map(8, 4, 1), o), std::invalid_argument);  // not square
}

TEST(EnvMap, DensityRowsAreTheDensity) {
    const EnvMap map = build_env_map(test::random_map(13, 7, 8), options(true));
    const std::vector<float> all = map.density();
    std::vector<float> row(13);
    for (uint32_t y = 0; y < 7; ++y) {
        map.density_row(y, row);
        for (uint32_t x = 0; x < 13; ++x) ASSERT_EQ(row[x], all[size_t{y} * 13 + x]);
    }
    EXPECT_THROW(map.density_row(7, row), std::invalid_argument);
    std::vector<float> short_row(12);
    EXPECT_THROW(map.density_row(0, short_row), std::invalid_argument);
}

TEST(EnvMap, CompensationStrengthAlphaIsHonoured) {
    const RgbImage image = test::random_map(32, 16, 3);
    for (float alpha : {0.0f, 0.5f, 2.0f}) {
        const EnvMap map = build_env_map(image, options(true, alpha));
        expect_directions_follow(map, reference_mass(image, true, alpha), 200 + static_cast<uint64_t>(alpha * 10));
    }
}

TEST(EnvMap, SolidAnglePdfIntegratesToOne) {
    for (const RgbImage& image :
         {test::sun_sky_map(64, 32), test::random_map(9, 5, 4), test::constant_map(1, 1, {1, 1, 1})})
        for (bool compensate : {false, true}) {
            const EnvMap map = build_env_map(image, options(compensate));
            // Midpoint rule in (theta, phi) on a grid aligned with, and 4x finer than, the texels.
            const double integral =
                test::sphere_integral(4 * map.height(), 4 * map.width(), [&](Vec3 d) { return map.pdf(d); });
            EXPECT_NEAR(integral, 1.0, 1e-3) << image.width << "x" << image.height << " compensate=" << compensate;
        }
}

TEST(EnvMap, SampleAgreesWithPdfAndEval) {
    const RgbImage image = test::sun_sky_map(128, 64);
    const EnvMap map = build_env_map(image, options(true));
    Rng rng(5);
    int edge_cases = 0;
    const int n = 50000;
    for (int i = 0; i < n; ++i) {
        const EnvSample s = map.sample(rng.uniform2());
        ASSERT_EQ(s.pdf, map.pdf_uv(s.uv));
        ASSERT_NEAR(length(s.direction), 1.0f, 1e-5f);
        // From the direction alone, float round trips may land in the neighbouring texel.
        const float p = map.pdf(s.direction);
        if (std::abs(p - s.pdf) > 1e-3f * s.pdf) ++edge_cases;
        const Rgb e = map.eval(s.direction);
        if (e.r != s.radiance.r || e.g != s.radiance.g || e.b != s.radiance.b) ++edge_cases;
    }
    EXPECT_LT(edge_cases, n / 500);
}

TEST(EnvMap, PdfIsZeroExactlyWhereTheDensityIs) {
    const RgbImage image = test::random_map(24, 12, 6);
    const EnvMap map = build_env_map(image, options(true));
    const auto mass = reference_mass(image, true, 1.0);
    for (uint32_t y = 0; y < 12; ++y)
        for (uint32_t x = 0; x < 24; ++x) {
            const float p = map.pdf_uv({(x + 0.5f) / 24, (y + 0.5f) / 12});
            EXPECT_EQ(p > 0, mass[size_t{y} * 24 + x] > 0) << x << "," << y;
        }
}

TEST(EnvMap, UncompensatedMapIsComplete) {
    const EnvMap map = build_env_map(test::random_map(20, 10, 8), options(false));
    EXPECT_FALSE(map.compensated());
    EXPECT_TRUE(map.complete());
    EXPECT_EQ(map.stats().threshold, 0.0f);
}

TEST(EnvMap, ConstantMapFallsBackToUncompensated) {
    const EnvMap map = build_env_map(test::constant_map(32, 16, {0.5f, 0.5f, 0.5f}), options(true));
    EXPECT_EQ(map.stats().fallback, DensityFallback::uncompensated);
    EXPECT_FALSE(map.compensated());
    EXPECT_TRUE(map.complete());
    expect_sine_density(map, 9);
}

TEST(EnvMap, BlackMapSamplesTheSphereUniformly) {
    const EnvMap map = build_env_map(test::constant_map(32, 16, {0, 0, 0}), options(true));
    EXPECT_EQ(map.stats().fallback, DensityFallback::uniform);
    EXPECT_TRUE(map.complete());
    expect_sine_density(map, 10);
}

TEST(EnvMap, SingleTexelMapWorks) {
    const EnvMap map = build_env_map(test::constant_map(1, 1, {2, 2, 2}), options(true));
    Rng rng(11);
    for (int i = 0; i < 1000; ++i) {
        const EnvSample s = map.sample(rng.uniform2());
        EXPECT_FLOAT_EQ(s.radiance.r, 2.0f);
        if (s.pdf > 0) {
            EXPECT_NEAR(s.pdf * kTwoPiSquared * std::sin(kPi * double{s.uv.y}), 1.0, 1e-5);
        }
    }
}

TEST(EnvMap, AbsurdDynamicRangeStillSamplesCorrectly) {
    RgbImage image = test::constant_map(32, 16, {});
    Rng rng(12);
    for (Rgb& p : image.pixels) {
        const float l = std::pow(10.0f, 16 * rng.uniform() - 8);  // 1e-8 .. 1e8
        p = {l, l, l};
    }
    const EnvMap map = build_env_map(image, options(false));
    EXPECT_TRUE(map.complete());
    EXPECT_GT(map.stats().max_luminance / map.stats().min_positive_luminance, 1e14f);
    for (uint32_t y = 0; y < 16; ++y)
        for (uint32_t x = 0; x < 32; ++x) EXPECT_GT(map.pdf_uv({(x + 0.5f) / 32, (y + 0.5f) / 16}), 0.0f);
    expect_directions_follow(map, reference_mass(image, false, 1.0), 13);
}

TEST(EnvMap, AxesRotateDirectionsWithoutChangingPdfs) {
    const RgbImage image = test::sun_sky_map(64, 32);
    EnvMapOptions y_up = options(true);
    y_up.axes = Axes::parse("y-up");
    const EnvMap z_map = build_env_map(image, options(true)), y_map = build_env_map(image, y_up);
    Rng rng(14);
    for (int i = 0; i < 1000; ++i) {
        const Vec2 u = rng.uniform2();
        const EnvSample a = z_map.sample(u), b = y_map.sample(u);
        EXPECT_EQ(a.pdf, b.pdf);
        EXPECT_FLOAT_EQ(b.direction.y, a.direction.z);  // canonical up is world +y
        EXPECT_FLOAT_EQ(b.direction.x, a.direction.x);
        EXPECT_FLOAT_EQ(b.direction.z, -a.direction.y);
        EXPECT_NEAR(y_map.pdf(b.direction), b.pdf, 1e-3f * b.pdf + 1e-6f);
    }
}

// Maps for the batch functions' paths: power-of-two and odd sizes, compensated or not,
// in both mappings, 2x1 and 1x1 (whose full-width cell, 2^31 units, breaks a signed
// conversion), y up and a permutation with two axes negated.
std::vector<EnvMap> batch_maps() {
    EnvMapOptions y_up = options(true), equal_area = options(true), equal_area_plain = options(false);
    y_up.axes = Axes::parse("y-up");
    equal_area.mapping = equal_area_plain.mapping = Mapping::equal_area;
    std::vector<EnvMap> maps;
    maps.push_back(build_env_map(test::sun_sky_map(1024, 512), options(true)));
    maps.push_back(build_env_map(test::sun_sky_map(1024, 512), options(false)));
    maps.push_back(build_env_map(test::random_map(37, 19, 3), options(false)));
    maps.push_back(build_env_map(test::random_map(37, 19, 3), options(true)));
    maps.push_back(build_env_map(test::random_map(2, 1, 4), options(true)));
    maps.push_back(build_env_map(test::random_map(2, 2, 6), options(false)));
    maps.push_back(build_env_map(test::constant_map(1, 1, {1, 2, 3}), options(false)));
    maps.push_back(build_env_map(test::sun_sky_map(64, 32), y_up));
    maps.push_back(build_env_map(test::random_map(32, 32, 5), equal_area));
    maps.push_back(build_env_map(test::random_map(37, 37, 7), equal_area_plain));
    maps.push_back(build_env_map(test::sun_sky_map(98, 98), equal_area));
    maps.push_back(build_env_map(test::random_map(2, 2, 8), equal_area));
    EnvMapOptions equal_area_y_up = equal_area;
    equal_area_y_up.axes = y_up.axes;
    maps.push_back(build_env_map(test::random_map(16, 16, 9), equal_area_y_up));
    EnvMapOptions mirrored = options(false);
    mirrored.axes = Axes::parse("-z,x,-y");
    maps.push_back(build_env_map(test::random_map(37, 19, 10), mirrored));
    return maps;
}

uint32_t bits(float f) { return bit_cast<uint32_t>(f); }

// lookup_many's SIMD path repeats lookup's arithmetic: every lane must give lookup's
// exact bits, on every path.
TEST(EnvMap, LookupManyIsBitIdenticalToLookup) {
    ENVMIS_SKIP_IF_FORCED_PATH_UNAVAILABLE();
    std::vector<Vec3> directions = {{0, 0, 1},      {0, 0, -1},       {1, 0, 0},        {-1, 0, 0},
                                    {0, 1, 0},      {0, -1, 0},       {1, -0.0f, 0},    {-1, -0.0f, 0},
                                    {1e-20f, 0, 1}, {0, -1e-20f, -1}, {0.6f, -0.8f, 0}, {0, 0, 0}};
    const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
    for (const Vec3 off_sphere : {Vec3{nan, 0, 1}, Vec3{inf, 0, 0}, Vec3{-inf, inf, 0}, Vec3{0, nan, nan}})
        directions.push_back(off_sphere);  // NaN image points: cell 0 on every path
    Rng rng(17);
    while (directions.size() < 1003) {  // not a multiple of the SIMD width
        const Vec2 u = rng.uniform2();
        const float z = 1 - 2 * u.x, r = std::sqrt(std::max(0.0f, 1 - z * z)), phi = 2 * kPiF * u.y;
        directions.push_back({r * std::cos(phi), r * std::sin(phi), z});
    }
    for (const EnvMap& map : batch_maps()) {
        // Add directions that the map itself samples: the sun, the seam, the last column.
        std::vector<Vec3> d = directions;
        for (int i = 0; i < 500; ++i) d.push_back(map.sample(rng.uniform2()).direction);
        std::vector<float> x, y, z, r(d.size()), g(d.size()), b(d.size()), pdf(d.size());
        for (const Vec3 v : d) x.push_back(v.x), y.push_back(v.y), z.push_back(v.z);
        const EnvMapView view = map.view();
        lookup_many(view, {x.data(), y.data(), z.data()}, {r.data(), g.data(), b.data(), pdf.data()},
                    static_cast<uint32_t>(d.size()));
        for (size_t i = 0; i < d.size(); ++i) {
            const EnvMapView::Lookup e = view.lookup(d[i]);
            ASSERT_EQ(bits(pdf[i]), bits(e.pdf)) << map.width() << "x" << map.height() << " direction " << i;
            ASSERT_EQ(bits(r[i]), bits(e.radiance.r)) << map.width() << "x" << map.height() << " direction " << i;
            ASSERT_EQ(bits(g[i]), bits(e.radiance.g));
            ASSERT_EQ(bits(b[i]), bits(e.radiance.b));
        }
    }
}

// sample_many's SIMD path repeats sample's search and arithmetic likewise, for points
// at the ends of [0,1), on the random generator's grid and off it; the image points too.
TEST(EnvMap, SampleManyIsBitIdenticalToSample) {
    ENVMIS_SKIP_IF_FORCED_PATH_UNAVAILABLE();
    // And outside [0,1), which both paths clamp (unit_point).
    const float edges[] = {0.0f,         0x1p-24f,
                           0.5f,         0.25f,
                           1 - 0x1p-24f, kOneMinusEpsilon,
                           1.0f,         -0.5f,
                           2.0f,         std::numeric_limits<float>::quiet_NaN()};
    std::vector<Vec2> points;
    for (const float a : edges)
        for (const float b : edges) points.push_back({a, b});
    Rng rng(19);
    while (points.size() < 1500) points.push_back(rng.uniform2());
    while (points.size() < 2005) {  // finer than 2^-31 (the CDF's unit) near 0; not a multiple of 8
        const Vec2 u = rng.uniform2();
        points.push_back({u.x * 0x1p-9f, u.y * 0x1p-9f});
    }
    std::vector<float> ux, uy;
    for (const Vec2 p : points) ux.push_back(p.x), uy.push_back(p.y);
    for (const EnvMap& map : batch_maps()) {
        const size_t n = points.size();
        std::vector<float> x(n), y(n), z(n), pdf(n), r(n), g(n), b(n), u(n), v(n);
        const EnvMapView view = map.view();
        sample_many(view, {ux.data(), uy.data()},
                    {x.data(), y.data(), z.data(), pdf.data(), r.data(), g.data(), b.data(), u.data(), v.data()},
                    static_cast<uint32_t>(n));
        for (size_t i = 0; i < n; ++i) {
            const EnvSample e = view.sample(points[i]);
            const float expected[] = {e.direction.x, e.direction.y, e.direction.z, e.pdf, e.radiance.r,
                                      e.radiance.g,  e.radiance.b,  e.uv.x,        e.uv.y};
            const float got[] = {x[i], y[i], z[i], pdf[i], r[i], g[i], b[i], u[i], v[i]};
            for (int k = 0; k < 9; ++k)
                ASSERT_EQ(bits(got[k]), bits(expected[k]))
                    << map.width() << "x" << map.height() << " point " << i << " (" << points[i].x << ", "
                    << points[i].y << ") output " << k;
        }
    }
}

// The pipelines' start and end: batches shorter than, as long as and just longer than
// the prefetch distance and the SIMD width, each call on its own output arrays.
TEST(EnvMap, ManyCallsOfEveryLengthAreBitIdenticalToSingleCalls) {
    ENVMIS_SKIP_IF_FORCED_PATH_UNAVAILABLE();
    const EnvMap map = build_env_map(test::sun_sky_map(64, 32), options(false));
    const EnvMapView view = map.view();
    Rng rng(23);
    constexpr uint32_t kMax = 70;
    float ux[kMax], uy[kMax], dx[kMax], dy[kMax], dz[kMax];
    for (uint32_t i = 0; i < kMax; ++i) {
        ux[i] = rng.uniform(), uy[i] = rng.uniform();
        const Vec3 d = map.sample(rng.uniform2()).direction;
        dx[i] = d.x, dy[i] = d.y, dz[i] = d.z;
    }
    for (uint32_t n = 0; n <= kMax; ++n) {
        std::vector<float> o(7 * kMax, -1.0f);  // a write past lane n - 1 shows
        float* p = o.data();
        sample_many(view, {ux, uy}, {p, p + kMax, p + 2 * kMax, p + 3 * kMax, p + 4 * kMax, p + 5 * kMax, p + 6 * kMax},
                    n);
        for (uint32_t i = 0; i < n; ++i) {
            const EnvSample e = view.sample({ux[i], uy[i]});
            ASSERT_EQ(bits(p[i]), bits(e.direction.x)) << n << " " << i;
            ASSERT_EQ(bits(p[kMax + i]), bits(e.direction.y)) << n << " " << i;
            ASSERT_EQ(bits(p[3 * kMax + i]), bits(e.pdf)) << n << " " << i;
            ASSERT_EQ(bits(p[5 * kMax + i]), bits(e.radiance.g)) << n << " " << i;
        }
        for (uint32_t i = n; i < kMax; ++i) ASSERT_EQ(p[i], -1.0f) << n << " " << i;
        lookup_many(view, {dx, dy, dz}, {p, p + kMax, p + 2 * kMax, p + 3 * kMax}, n);
        for (uint32_t i = 0; i < n; ++i) {
            const EnvMapView::Lookup e = view.lookup({dx[i], dy[i], dz[i]});
            ASSERT_EQ(bits(p[3 * kMax + i]), bits(e.pdf)) << n << " " << i;
            ASSERT_EQ(bits(p[2 * kMax + i]), bits(e.radiance.b)) << n << " " << i;
        }
        for (uint32_t i = n; i < kMax; ++i) ASSERT_EQ(p[3 * kMax + i], -1.0f) << n << " " << i;
    }
}

// Lookups read the radiance at random texels: on 4 KiB pages most of those reads of a
// large map miss the TLB, so its pixels are allocated for huge pages (large_vector.h).
TEST(EnvMap, TheRadianceOfALargeMapStartsOnAHugePageBoundary) {
    const EnvMap map = build_env_map(test::constant_map(1024, 512, {1, 1, 1}));  // 6 MiB of pixels
    EXPECT_EQ(reinterpret_cast<uintptr_t>(map.radiance().pixels.data()) % (size_t{2} << 20), 0u);
}

// A build's parts make the map the build made; a distribution of another size is refused.
TEST(EnvMap, ABuildsPartsMakeItsMapAndPartsOfOtherSizesAreRefused) {
    const RgbImage image = test::random_map(8, 4, 2);
    const EnvMap built = build_env_map(image, options(false));
    const EnvMap again(image, Distribution2D(built.distribution()), built.options(), built.stats());
    Rng rng(3);
    for (int i = 0; i < 100; ++i) {
        const Vec2 u = rng.uniform2();
        EXPECT_EQ(again.sample(u).pdf, built.sample(u).pdf);
        EXPECT_EQ(again.sample(u).radiance.g, built.sample(u).radiance.g);
    }
    EXPECT_THROW(
        EnvMap(test::random_map(16, 4, 2), Distribution2D(built.distribution()), built.options(), built.stats()),
        std::invalid_argument);
}

}  // namespace
}  // namespace envmis
