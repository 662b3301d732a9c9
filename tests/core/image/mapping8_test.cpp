// The mappings and angles of mapping.h and fast_math.h on eight AVX2 lanes (the lane
// types of lib/common/detail/simd.h, as the batch calls use them) against the same
// functions on one float, lane by lane and bit for bit: the lane types' operators must
// give float's IEEE results, at signed zeros, NaN and clamps included. The batch tests of envmap_test
// compare whole lookups, whose radiance and pdf are constant over a texel: an inverse
// mapping off by an ulp, or wrong only at z = -0 or |z| > 1, passes them. Here the image
// points and directions themselves are compared, on the inputs where the branches and
// clamps decide. Builds without the AVX2 path have no such tests.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "detail/simd.h"
#include "envmis/cpu.h"
#include "envmis/image/mapping.h"
#include "stats.h"

#ifdef ENVMIS_AVX2_BATCHES
namespace envmis {
namespace {

using test::Rng;

uint32_t bits(float f) { return bit_cast<uint32_t>(f); }

// Each float and the floats one ulp either side of it.
std::vector<float> with_neighbours(std::vector<float> values) {
    const size_t n = values.size();
    for (size_t i = 0; i < n; ++i) {
        values.push_back(std::nextafter(values[i], -std::numeric_limits<float>::infinity()));
        values.push_back(std::nextafter(values[i], std::numeric_limits<float>::infinity()));
    }
    return values;
}

// Directions where the inverse mappings' branches and clamps decide: every triple of
// the special components (signed zeros, tiny and subnormal values, the octahedron's
// edges, |z| at and just past 1, non-unit lengths), then random unit and non-unit ones.
std::vector<Vec3> hard_directions() {
    const std::vector<float> special = with_neighbours(
        {0.0f, -0.0f, 1.0f, -1.0f, 0.5f, -0.5f, 0.70710678f, -0.70710678f, 1e-30f, -1e-30f, 1e-40f, 2.0f, -3.0f});
    std::vector<Vec3> d;
    for (const float x : special)
        for (const float y : special)
            for (const float z : special) d.push_back({x, y, z});
    Rng rng(53);
    for (int i = 0; i < 20000; ++i) {
        const Vec2 u = rng.uniform2();
        const float z = 1 - 2 * u.x, r = std::sqrt(std::max(0.0f, 1 - z * z)), phi = 2 * kPiF * u.y;
        const float scale = i % 4 == 0 ? 0.5f + 2 * rng.uniform() : 1.0f;
        d.push_back({scale * r * std::cos(phi), scale * r * std::sin(phi), scale * z});
        d.push_back({scale * r, scale * r * (i % 2 ? 1.0f : -1.0f), scale * z});  // |x| = |y|
    }
    return d;
}

// Image points at the cell edges of several square sizes (and an ulp either side), the
// square's centre lines, corners and diamond, and random points; all in [0,1).
std::vector<Vec2> hard_points() {
    std::vector<float> special = {0.0f, 0.25f, 0.5f, 0.75f, kOneMinusEpsilon};
    for (const uint32_t n : {2u, 16u, 98u, 5792u})
        for (uint32_t k = 1; k < n; k += n / 16 + 1) special.push_back(static_cast<float>(k) / static_cast<float>(n));
    std::vector<float> coords;
    for (const float c : with_neighbours(special))
        if (c >= 0.0f && c < 1.0f) coords.push_back(c);
    std::vector<Vec2> p;
    for (const float x : coords)
        for (const float y : coords) p.push_back({x, y});
    Rng rng(59);
    for (int i = 0; i < 20000; ++i) {
        const Vec2 u = rng.uniform2();
        p.push_back(u);
        p.push_back({u.x, std::min(std::abs(0.5f - u.x) + (i % 2 ? 0.5f : 0.0f), kOneMinusEpsilon)});  // diamond
    }
    return p;
}

ENVMIS_AVX2 simd::F8 load8(const std::vector<float>& v, size_t l) { return simd::load(v.data() + l); }

// The three coordinates of directions as arrays, padded to a whole number of lanes.
struct Coords {
    std::vector<float> x, y, z;
    explicit Coords(const std::vector<Vec3>& d) {
        for (const Vec3 v : d) x.push_back(v.x), y.push_back(v.y), z.push_back(v.z);
        x.resize(x.size() + 8), y.resize(y.size() + 8), z.resize(z.size() + 8);
    }
    ENVMIS_AVX2 simd::Vec3x8 at(size_t l) const { return {load8(x, l), load8(y, l), load8(z, l)}; }
};

// f(eight lanes) for every direction, as Vec3s.
template <class F>
ENVMIS_AVX2 std::vector<Vec3> per_lane(const std::vector<Vec3>& d, F&& f) {
    const Coords c(d);
    std::vector<Vec3> out(d.size() + 8);
    for (size_t l = 0; l < d.size(); l += 8) {
        const simd::Vec3x8 r = f(c.at(l));
        alignas(32) float x[8], y[8], z[8];
        _mm256_store_ps(x, r.x), _mm256_store_ps(y, r.y), _mm256_store_ps(z, r.z);
        for (int k = 0; k < 8; ++k) out[l + k] = {x[k], y[k], z[k]};
    }
    out.resize(d.size());
    return out;
}

::testing::AssertionResult same_bits(Vec3 got, Vec3 expected, Vec3 input) {
    for (int k = 0; k < 3; ++k)
        if (bits(got[k]) != bits(expected[k]))
            return ::testing::AssertionFailure() << "component " << k << " of (" << input.x << ", " << input.y << ", "
                                                 << input.z << "): " << got[k] << " against " << expected[k];
    return ::testing::AssertionSuccess();
}

class Mapping8 : public ::testing::Test {
protected:
    void SetUp() override {
        if (!cpu_info().avx2) GTEST_SKIP() << "no AVX2 on this CPU";
    }
};

TEST_F(Mapping8, ImagePointsOfDirectionsAreTheScalarOnesInBothMappings) {
    const std::vector<Vec3> d = hard_directions();
    for (const Mapping m : {Mapping::equirect, Mapping::equal_area}) {
        const auto got = per_lane(d, [m](const simd::Vec3x8& v) ENVMIS_AVX2_FLAT {
            const simd::Vec2x8 p = m == Mapping::equal_area ? equal_area_uv<simd::F8>(v) : equirect_uv<simd::F8>(v);
            return simd::Vec3x8{p.x, p.y, 0.0f};
        });
        for (size_t i = 0; i < d.size(); ++i) {
            const Vec2 expected = image_uv(m, d[i]);
            ASSERT_TRUE(same_bits(got[i], {expected.x, expected.y, 0.0f}, d[i])) << to_string(m);
        }
    }
}

TEST_F(Mapping8, EqualAreaDirectionsOfImagePointsAreTheScalarOnes) {
    std::vector<Vec3> points;  // (u, v, unused)
    for (const Vec2 p : hard_points()) points.push_back({p.x, p.y, 0.0f});
    const auto got = per_lane(points, [](const simd::Vec3x8& v) ENVMIS_AVX2_FLAT {
        return equal_area_direction<simd::F8>({v.x, v.y});
    });
    for (size_t i = 0; i < points.size(); ++i)
        ASSERT_TRUE(same_bits(got[i], equal_area_direction({points[i].x, points[i].y}), points[i]));
}

TEST_F(Mapping8, EveryAxesPermutationMovesComponentsAsTheScalarCode) {
    const std::vector<Vec3> d = hard_directions();
    int permutations = 0;
    for (int8_t a : {1, 2, 3})
        for (int8_t b : {1, 2, 3})
            for (int8_t c : {1, 2, 3}) {
                if (a == b || b == c || a == c) continue;
                for (int signs = 0; signs < 8; ++signs) {
                    const Axes axes{{static_cast<int8_t>(signs & 1 ? -a : a), static_cast<int8_t>(signs & 2 ? -b : b),
                                     static_cast<int8_t>(signs & 4 ? -c : c)}};
                    ++permutations;
                    const auto world = per_lane(
                        d, [&](const simd::Vec3x8& v) ENVMIS_AVX2_FLAT { return to_world<simd::F8>(axes, v); });
                    const auto canonical = per_lane(
                        d, [&](const simd::Vec3x8& v) ENVMIS_AVX2_FLAT { return to_canonical<simd::F8>(axes, v); });
                    for (size_t i = 0; i < d.size(); i += 7) {
                        ASSERT_TRUE(same_bits(world[i], to_world(axes, d[i]), d[i])) << axes.to_string();
                        ASSERT_TRUE(same_bits(canonical[i], to_canonical(axes, d[i]), d[i])) << axes.to_string();
                    }
                }
            }
    EXPECT_EQ(permutations, 48);
}

TEST_F(Mapping8, ArctangentsAreTheScalarOnesOnSpecialAndRandomPairs) {
    std::vector<Vec3> pairs;  // (y, x, unused)
    for (const Vec3 v : hard_directions()) pairs.push_back({v.x, v.y, 0.0f}), pairs.push_back({v.z, v.x, 0.0f});
    const auto got = per_lane(pairs, [](const simd::Vec3x8& v) ENVMIS_AVX2_FLAT {
        return simd::Vec3x8{fast_atan2(v.x, v.y), 0.0f, 0.0f};
    });
    for (size_t i = 0; i < pairs.size(); ++i)
        ASSERT_TRUE(same_bits(got[i], {fast_atan2(pairs[i].x, pairs[i].y), 0.0f, 0.0f}, pairs[i]));
}

TEST_F(Mapping8, SinesCosinesAndPowersAreTheScalarOnes) {
    const std::vector<SinCos> turns = make_turn_table();
    std::vector<Vec3> inputs;  // (angle or turn, base, exponent)
    for (const Vec3 v : hard_directions()) inputs.push_back({8 * v.x, std::abs(v.y), 50 * std::abs(v.z)});
    const auto sincos = per_lane(inputs, [](const simd::Vec3x8& v) ENVMIS_AVX2_FLAT {
        const simd::SinCos8 s = fast_sincos(v.x);
        return simd::Vec3x8{s.sin, s.cos, fast_pow(v.y, v.z)};
    });
    const auto turned = per_lane(inputs, [&](const simd::Vec3x8& v) ENVMIS_AVX2_FLAT {
        const simd::SinCos8 t = sincos_turns(turns.data(), v.x), h = sincos_half_turns(turns.data(), v.y);
        return simd::Vec3x8{t.sin, t.cos, h.sin + h.cos};
    });
    for (size_t i = 0; i < inputs.size(); ++i) {
        const Vec3 v = inputs[i];
        const SinCos s = fast_sincos(v.x), t = sincos_turns(turns.data(), v.x),
                     h = sincos_half_turns(turns.data(), v.y);
        ASSERT_TRUE(same_bits(sincos[i], {s.sin, s.cos, fast_pow(v.y, v.z)}, v));
        ASSERT_TRUE(same_bits(turned[i], {t.sin, t.cos, h.sin + h.cos}, v));
    }
}

}  // namespace
}  // namespace envmis
#endif
