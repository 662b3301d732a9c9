// Specification of the MIS weight functions and of optimal MIS's linear solve
// (mis_weights.h).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "envmis/study/weights/mis_weights.h"

namespace envmis {
namespace {

const std::vector<std::vector<float>> kDensities = {{1, 3},     {0.2f, 0},    {5, 5},   {1e-23f, 0},
                                                    {1e20f, 2}, {0.5f, 2, 7}, {0, 0, 4}};

TEST(MisWeights, BalancePowerAndVarianceAwareWeightsSumToOne) {
    for (const auto& q : kDensities) {
        const int m = static_cast<int>(q.size());
        const float nu[3] = {0.5f, 4, 1};
        float balance = 0, power = 0, aware = 0;
        for (int k = 0; k < m; ++k) {
            const float w[3] = {balance_weight(q.data(), m, k), power_weight(q.data(), m, k),
                                variance_aware_weight(q.data(), nu, m, k)};
            for (float x : w) EXPECT_TRUE(x >= 0 && x <= 1) << x;
            balance += w[0], power += w[1], aware += w[2];
        }
        EXPECT_NEAR(balance, 1, 1e-6f);
        EXPECT_NEAR(power, 1, 1e-6f);
        EXPECT_NEAR(aware, 1, 1e-6f);
    }
}

TEST(MisWeights, KnownValues) {
    const float q[2] = {1, 3}, nu[2] = {3, 1};
    EXPECT_FLOAT_EQ(balance_weight(q, 2, 0), 0.25f);
    EXPECT_FLOAT_EQ(power_weight(q, 2, 0), 0.1f);
    EXPECT_FLOAT_EQ(variance_aware_weight(q, nu, 2, 0), 0.5f);  // nu 3:1 evens out q 1:3
    const float ones[2] = {1, 1};
    EXPECT_FLOAT_EQ(variance_aware_weight(q, ones, 2, 1), balance_weight(q, 2, 1));
    const float none[2] = {0, 0};
    EXPECT_EQ(balance_weight(none, 2, 0), 0.0f);
    EXPECT_EQ(power_weight(none, 2, 0), 0.0f);
}

TEST(MisWeights, OptimalWeightsSumToOneAndMayBeNegative) {
    const float p[2] = {2, 0.5f}, n[2] = {1, 1};
    bool negative = false;
    for (float f : {0.1f, 1.0f, 3.0f, -2.0f})
        for (float a0 : {-1.0f, 0.0f, 0.3f, 2.0f})
            for (float a1 : {-0.5f, 0.0f, 1.0f}) {
                const float alpha[2] = {a0, a1};
                const float w0 = optimal_weight(p, n, alpha, f, 2, 0), w1 = optimal_weight(p, n, alpha, f, 2, 1);
                EXPECT_NEAR(w0 + w1, 1, 1e-5f);
                negative = negative || w0 < 0 || w1 < 0;
            }
    EXPECT_TRUE(negative) << "control-variate weights leave [0, 1]";
    // alpha = 0 is the balance heuristic.
    const float zero[2] = {0, 0}, q[2] = {2, 0.5f};
    EXPECT_FLOAT_EQ(optimal_weight(p, n, zero, 1.7f, 2, 0), balance_weight(q, 2, 0));
}

TEST(OptimalAlpha, SolvesAKnownSystemForEachChannel) {
    // A = [[4, 1], [1, 3]]; alpha = (1, 2), (0, -1), (0.5, 0.5) per channel.
    const double a[4] = {4, 1, 1, 3};
    const double alpha[2][3] = {{1, 0, 0.5}, {2, -1, 0.5}};
    double b[6];
    for (int c = 0; c < 3; ++c) {
        b[0 * 3 + c] = 4 * alpha[0][c] + 1 * alpha[1][c];
        b[1 * 3 + c] = 1 * alpha[0][c] + 3 * alpha[1][c];
    }
    const OptimalAlpha s = solve_optimal_alpha(a, b, 2);
    ASSERT_TRUE(s.solved);
    EXPECT_GT(s.rcond, 0.1);
    for (int k = 0; k < 2; ++k)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(s.alpha[k][c], alpha[k][c], 1e-6);
}

TEST(OptimalAlpha, SolvesThreeTechniques) {
    const double a[9] = {2, 0.5, 0.1, 0.5, 1, 0.2, 0.1, 0.2, 3};
    const double x[3] = {0.3, -0.7, 1.1};
    double b[9];
    for (int i = 0; i < 3; ++i)
        for (int c = 0; c < 3; ++c)
            b[i * 3 + c] = (a[i * 3] * x[0] + a[i * 3 + 1] * x[1] + a[i * 3 + 2] * x[2]) * (c + 1);
    const OptimalAlpha s = solve_optimal_alpha(a, b, 3);
    ASSERT_TRUE(s.solved);
    for (int k = 0; k < 3; ++k)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(s.alpha[k][c], x[k] * (c + 1), 1e-6);
}

TEST(OptimalAlpha, SingularOrBrokenSystemsFallBackToBalance) {
    const double b[9] = {1, 1, 1, 1, 1, 1, 1, 1, 1};
    const double identical_techniques[4] = {1, 1, 1, 1};  // two copies of one density
    const double unused_technique[4] = {1, 0, 0, 0};      // a density that is 0 everywhere
    const double nearly_singular[4] = {1, 1, 1, 1 + 1e-12};
    const double nan[4] = {1, 0, 0, std::numeric_limits<double>::quiet_NaN()};
    for (const double* a : {identical_techniques, unused_technique, nearly_singular, nan}) {
        const OptimalAlpha s = solve_optimal_alpha(a, b, 2);
        EXPECT_FALSE(s.solved);
        for (int k = 0; k < 2; ++k)
            for (int c = 0; c < 3; ++c) EXPECT_EQ(s.alpha[k][c], 0.0f);
    }
    EXPECT_FALSE(solve_optimal_alpha(identical_techniques, b, 0).solved);
    EXPECT_FALSE(solve_optimal_alpha(identical_techniques, b, 4).solved);
}

}  // namespace
}  // namespace envmis
