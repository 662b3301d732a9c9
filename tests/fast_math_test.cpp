// Specification of the fast trigonometry (fast_math.h): close to double precision.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "envmis/fast_math.h"

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
    EXPECT_EQ(fast_atan2(0, 0), 0.0f);
    EXPECT_FLOAT_EQ(fast_atan2(1, 0), kPiF / 2);
    EXPECT_FLOAT_EQ(fast_atan2(0, -1), kPiF);
    EXPECT_FLOAT_EQ(fast_atan2(-1, 0), -kPiF / 2);
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

}  // namespace
}  // namespace envmis
