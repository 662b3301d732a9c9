// Specification of the fast trigonometry (fast_math.h): close to double precision.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "envmis/math/fast_math.h"

namespace envmis {
namespace {

TEST(FastMath, SinCosWithin2e7) {
    double worst = 0;
    for (int i = -2000000; i <= 2000000; ++i) {
        const float x = static_cast<float>(i) * 4e-6f * kPiF;  // [-8 pi, 8 pi]
        const SinCos sc = fast_sincos(x);
        worst = std::max({worst, std::abs(sc.sin - std::sin(double{x})), std::abs(sc.cos - std::cos(double{x}))});
    }
    EXPECT_LT(worst, 2e-7);
}

TEST(FastMath, Atan2Within4e7EverywhereIncludingAxes) {
    double worst = 0;
    for (int i = 0; i < 1000000; ++i) {
        const double a = 2 * kPi * i / 1000000.0 - kPi;
        for (double r : {1e-6, 1.0, 1e6}) {
            const auto y = static_cast<float>(r * std::sin(a)), x = static_cast<float>(r * std::cos(a));
            worst = std::max(worst, std::abs(fast_atan2(y, x) - std::atan2(double{y}, double{x})));
        }
    }
    EXPECT_LT(worst, 4e-7);  // 1.5 float ulps at pi
    EXPECT_EQ(fast_atan2(0.0f, 0.0f), 0.0f);
    EXPECT_FLOAT_EQ(fast_atan2(1.0f, 0.0f), kPiF / 2);
    EXPECT_FLOAT_EQ(fast_atan2(0.0f, -1.0f), kPiF);
    EXPECT_FLOAT_EQ(fast_atan2(-1.0f, 0.0f), -kPiF / 2);
}

TEST(FastMath, Atan2IsNotFooledByEachQuadrantsSignsOrSignedZeros) {
    // The reflections meet on the axes (x = -0 and y = -0 pick their side by the sign bit).
    for (const float y : {1.0f, -1.0f, 0.5f, -2.0f})
        for (const float x : {0.0f, -0.0f, 1e-30f, -1e-30f, 3.0f, -3.0f})
            EXPECT_NEAR(fast_atan2(y, x), std::atan2(double{y}, double{x}), 4e-7) << y << ", " << x;
    EXPECT_FLOAT_EQ(fast_atan2(0.0f, -0.0f), kPiF);
    EXPECT_FLOAT_EQ(fast_atan2(-0.0f, -1.0f), -kPiF);
}

TEST(FastMath, QuarterTurnsAtanWithin1p5e7OfAQuarterTurnInTheFirstQuadrant) {
    double worst = 0;
    for (int i = 0; i <= 1000000; ++i) {
        const double a = kPi / 2 * i / 1000000.0;
        for (double r : {1e-6, 1.0, 1e6}) {
            const auto y = static_cast<float>(r * std::sin(a)), x = static_cast<float>(std::abs(r * std::cos(a)));
            worst =
                std::max(worst, std::abs(fast_atan_quarter_turns(y, x) - std::atan2(double{y}, double{x}) / (kPi / 2)));
        }
    }
    EXPECT_LT(worst, 1.5e-7);  // 2.4e-7 radians
    EXPECT_EQ(fast_atan_quarter_turns(0.0f, 0.0f), 0.0f);
    EXPECT_EQ(fast_atan_quarter_turns(0.0f, 1.0f), 0.0f);
    EXPECT_EQ(fast_atan_quarter_turns(1.0f, 0.0f), 1.0f);
    EXPECT_FLOAT_EQ(fast_atan_quarter_turns(2.0f, 2.0f), 0.5f);
}

TEST(FastMath, AcosWithin4p5e7OnMinusOneToOneAndExactAtItsEnds) {
    double worst = 0;
    for (int i = -4000000; i <= 4000000; ++i) {
        const float z = static_cast<float>(i) / 4000000.0f;
        worst = std::max(worst, std::abs(fast_acos(z) - std::acos(double{z})));
    }
    for (float z = 1.0f; z > 0.999f; z = std::nextafter(z, 0.0f))  // the pole, where acos is steep
        worst = std::max(
            {worst, std::abs(fast_acos(z) - std::acos(double{z})), std::abs(fast_acos(-z) - std::acos(double{-z}))});
    EXPECT_LT(worst, 4.5e-7);
    EXPECT_EQ(fast_acos(1.0f), 0.0f);
    EXPECT_EQ(fast_acos(-1.0f), kPiF);
    EXPECT_FLOAT_EQ(fast_acos(0.0f), kPiF / 2);
}

TEST(FastMath, TurnTableSinCosWithin1e7OverTheTurnAndBeyond) {
    const std::vector<SinCos> table = make_turn_table();
    double worst = 0;
    for (int i = -1000000; i <= 3000000; ++i) {
        const float t = static_cast<float>(i) * 1e-6f;  // [-1, 3] turns
        const SinCos sc = sincos_turns(table.data(), t);
        const double a = 2 * kPi * double{t};
        worst = std::max({worst, std::abs(sc.sin - std::sin(a)), std::abs(sc.cos - std::cos(a))});
    }
    EXPECT_LT(worst, 1.2e-7);  // two ulps of 1
    EXPECT_EQ(sincos_turns(table.data(), 0.0f).sin, 0.0f);
    EXPECT_EQ(sincos_turns(table.data(), 0.25f).cos, table[256].cos);
}

// The environment sampler takes sin(theta) = sincos_half_turns(v).sin for v in [0, 1)
// as it is, without clamping: a negative value would flip the sampled direction through
// the pole. Every float in [0, 1) was checked once (31 s); this checks the 2^20 floats
// nearest each end, where theta nears 0 and pi, and a stride through the rest.
TEST(FastMath, HalfTurnSineIsNonNegativeOnTheUnitInterval) {
    const std::vector<SinCos> table = make_turn_table();
    const uint32_t one = bit_cast<uint32_t>(1.0f), ends = 1u << 20;
    uint64_t negative = 0, checked = 0;
    const auto check = [&](uint32_t bits) {
        negative += std::signbit(sincos_half_turns(table.data(), bit_cast<float>(bits)).sin);
        ++checked;
    };
    for (uint32_t b = 0; b < ends; ++b) check(b);
    for (uint32_t b = one - ends; b < one; ++b) check(b);
    for (uint32_t b = ends; b < one - ends; b += 127) check(b);
    EXPECT_EQ(negative, 0u) << "of " << checked;
    EXPECT_EQ(sincos_half_turns(table.data(), 0.5f).sin, table[256].sin);
}

// fast_pow's bound, 1.5e-7 + 1.5e-7 |y log2 x| relative, over a stride through every
// float in (0, 1] (subnormals included) for exponents from Phong's sampling (1 / (n + 1))
// to its lobes (n up to 1e5), wherever the result is at least 2^-126.
TEST(FastMath, PowWithinItsBoundOnTheUnitIntervalAndExactAtItsFixedPoints) {
    double worst = 0;  // the error over the bound
    for (const float y : {0.001f, 0.0099f, 0.05f, 1 / 3.0f, 0.5f, 0.9f, 1.0f, 2.0f, 3.7f, 20.0f, 50.0f, 1e3f, 1e5f})
        for (uint32_t b = 1; b <= bit_cast<uint32_t>(1.0f); b += 4099) {
            const float x = bit_cast<float>(b);
            const double t = y * std::log2(double{x}), exact = std::pow(double{x}, double{y});
            if (t < -126) continue;
            worst = std::max(worst, std::abs(fast_pow(x, y) - exact) / exact / (1.5e-7 + 1.5e-7 * std::abs(t)));
        }
    EXPECT_LT(worst, 1.0);
    EXPECT_EQ(fast_pow(0.3f, 0.0f), 1.0f);
    EXPECT_EQ(fast_pow(1.0f, 1e5f), 1.0f);
    EXPECT_EQ(fast_pow(0.0f, 0.5f), 0.0f);
    EXPECT_EQ(fast_pow(0.5f, 200.0f), 0.0f);  // 2^-200: below 2^-126
    EXPECT_EQ(fast_pow(0.5f, 3.0f), 0.125f);
}

}  // namespace
}  // namespace envmis
