// Specification of the conversion between mappings (remap.h): power is kept, a sun
// stays a compact blob, smooth maps survive a round trip, and the converted map
// describes the same lighting as the original.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "envmis/build/env_map.h"
#include "envmis/build/remap.h"
#include "envmis/sampling/distribution.h"
#include "envmis/study/reference/quadrature.h"
#include "maps.h"

namespace envmis {
namespace {

void expect_power_kept(const RgbImage& in, Mapping from, const RgbImage& out, Mapping to, double tolerance) {
    const auto a = total_power(in, from), b = total_power(out, to);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(b[c], a[c], tolerance * a[c]) << "channel " << c;
}

TEST(Remap, TexelSolidAnglesCoverTheSphere) {
    for (Mapping m : {Mapping::equirect, Mapping::equal_area}) {
        double sum = 0;
        for (uint32_t y = 0; y < 24; ++y) sum += 24 * texel_solid_angle(m, y, 24, 24);
        EXPECT_NEAR(sum, 4 * kPi, 1e-12);
    }
}

TEST(Remap, KeepsTotalPowerBothWays) {
    const RgbImage sky = test::sun_sky_map(256, 128, 1e5f);
    const RemapResult square = remap(sky, Mapping::equirect, Mapping::equal_area, 128, 128);
    expect_power_kept(sky, Mapping::equirect, square.image, Mapping::equal_area, 0.005);
    const RemapResult back = remap(square.image, Mapping::equal_area, Mapping::equirect, 256, 128);
    expect_power_kept(sky, Mapping::equirect, back.image, Mapping::equirect, 0.005);
    // Also far from the input's resolution, both coarser and finer.
    for (uint32_t n : {16u, 512u})
        expect_power_kept(sky, Mapping::equirect, remap(sky, Mapping::equirect, Mapping::equal_area, n, n).image,
                          Mapping::equal_area, 0.005);
}

// A one-texel sun lands in a few neighbouring texels holding all its power.
TEST(Remap, OneTexelSunStaysOneCompactBlob) {
    for (const Vec2 sun : {Vec2{0.3f, 0.3f}, Vec2{0.9f, 0.02f}, Vec2{0.5f, 0.97f}, Vec2{0.0f, 0.5f}}) {
        RgbImage map = test::constant_map(512, 256, {});
        const uint32_t sx = detail::cell_of(sun.x, 512), sy = detail::cell_of(sun.y, 256);
        map.pixels[size_t{sy} * 512 + sx] = {1e6f, 1e6f, 1e6f};
        const RgbImage out = remap(map, Mapping::equirect, Mapping::equal_area, 256, 256).image;
        const Vec2 centre = equal_area_uv(equirect_direction({(sx + 0.5f) / 512, (sy + 0.5f) / 256}));
        const auto cx = static_cast<int>(centre.x * 256), cy = static_cast<int>(centre.y * 256);
        double near = 0, total = 0;
        for (uint32_t y = 0; y < 256; ++y)
            for (uint32_t x = 0; x < 256; ++x) {
                const double p = out.at(x, y).r * texel_solid_angle(Mapping::equal_area, y, 256, 256);
                total += p;
                // Within two texels, across the octahedral seams too: compare directions.
                const Vec3 d = equal_area_direction({(x + 0.5f) / 256, (y + 0.5f) / 256});
                const Vec3 c = equal_area_direction({(cx + 0.5f) / 256, (cy + 0.5f) / 256});
                if (p > 0 && std::acos(std::clamp(dot(d, c), -1.0f, 1.0f)) < 3 * std::sqrt(4 * kPi / (256.0 * 256)))
                    near += p;
            }
        const double power = 1e6 * texel_solid_angle(Mapping::equirect, sy, 512, 256);
        EXPECT_NEAR(total, power, 1e-6 * power);
        EXPECT_NEAR(near, power, 1e-6 * power) << "sun at " << sun.x << "," << sun.y;
    }
}

TEST(Remap, ConstantMapStaysConstant) {
    const RgbImage flat = test::constant_map(128, 64, {0.5f, 1.0f, 2.0f});
    for (const auto& [from, to, w, h] : {std::tuple{Mapping::equirect, Mapping::equal_area, 64u, 64u},
                                         std::tuple{Mapping::equirect, Mapping::equal_area, 200u, 200u},
                                         std::tuple{Mapping::equirect, Mapping::equirect, 64u, 32u}}) {
        const RgbImage out = remap(flat, from, to, w, h).image;
        for (const Rgb& p : out.pixels) {
            ASSERT_NEAR(p.r, 0.5f, 0.01f);
            ASSERT_NEAR(p.g, 1.0f, 0.02f);
            ASSERT_NEAR(p.b, 2.0f, 0.04f);
        }
    }
}

// equirect -> equal-area -> equirect at the same texel count: a smooth sky comes back
// within a few percent away from the seams' filtering.
TEST(Remap, SmoothMapSurvivesARoundTrip) {
    RgbImage sky = test::constant_map(256, 128, {});
    for (uint32_t y = 0; y < 128; ++y)
        for (uint32_t x = 0; x < 256; ++x) {
            const Vec3 d = equirect_direction({(x + 0.5f) / 256, (y + 0.5f) / 128});
            const float l = 1.5f + d.z + 0.5f * d.x * d.y;
            sky.pixels[size_t{y} * 256 + x] = {l, 0.5f * l, 0.25f * l};
        }
    const RgbImage square = remap(sky, Mapping::equirect, Mapping::equal_area, 182, 182).image;
    const RgbImage back = remap(square, Mapping::equal_area, Mapping::equirect, 256, 128).image;
    double worst = 0, mean = 0;
    for (size_t i = 0; i < sky.pixels.size(); ++i) {
        const double e = std::abs(back.pixels[i].r - sky.pixels[i].r) / sky.pixels[i].r;
        worst = std::max(worst, e);
        mean += e / static_cast<double>(sky.pixels.size());
    }
    EXPECT_LT(mean, 0.01);
    EXPECT_LT(worst, 0.08);
}

// The converted map lights a surface as the original does: the quadrature reference
// (which handles both mappings) agrees within the conversion's filtering.
TEST(Remap, ConvertedMapGivesTheSameLighting) {
    const RgbImage sky = test::sun_sky_map(128, 64, 2e3f);
    const EnvMap original = build_env_map(sky, {});
    EnvMapOptions o;
    o.mapping = Mapping::equal_area;
    const EnvMap square = build_env_map(remap(sky, Mapping::equirect, Mapping::equal_area, 96, 96).image, o);
    for (const Vec3 n : {Vec3{0, 0, 1}, Vec3{0.6f, 0, 0.8f}, Vec3{0, -1, 0}})
        for (const Bsdf& bsdf : {Bsdf::lambert(), Bsdf::phong(20)}) {
            const ShadingPoint point{n, n};
            const double a = reflected_radiance(original, bsdf, point).luminance;
            const double b = reflected_radiance(square, bsdf, point).luminance;
            EXPECT_NEAR(b, a, 0.02 * a) << bsdf.name() << " normal " << n.x << "," << n.y << "," << n.z;
        }
}

TEST(Remap, BadPixelsAreCountedAndRejectedSizesThrow) {
    RgbImage map = test::constant_map(8, 4, {1, 1, 1});
    map.pixels[3] = {NAN, -1.0f, INFINITY};
    const RemapResult r = remap(map, Mapping::equirect, Mapping::equal_area, 8, 8);
    EXPECT_EQ(r.bad_pixels.total(), 3u);
    for (const Rgb& p : r.image.pixels) ASSERT_TRUE(std::isfinite(p.r) && p.r >= 0);
    EXPECT_THROW(remap(map, Mapping::equirect, Mapping::equal_area, 8, 4), std::invalid_argument);  // not square
    EXPECT_THROW(remap(map, Mapping::equirect, Mapping::equirect, 0, 4), std::invalid_argument);
    EXPECT_THROW(remap(map, Mapping::equal_area, Mapping::equirect, 8, 4), std::invalid_argument);  // input not square
}

}  // namespace
}  // namespace envmis
