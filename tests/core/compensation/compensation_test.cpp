// Specification of MIS compensation (compensation.h).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "envmis/compensation/compensation.h"

namespace envmis {
namespace {

TEST(Compensation, SubtractsThresholdAndClampsAtZero) {
    EXPECT_EQ(compensate(3.0f, 1.0f), 2.0f);
    EXPECT_EQ(compensate(1.0f, 1.0f), 0.0f);
    EXPECT_EQ(compensate(0.5f, 1.0f), 0.0f);
    EXPECT_EQ(compensate(0.5f, 0.0f), 0.5f);
}

TEST(Compensation, SolidAngleMeanOfAConstantIsTheConstant) {
    const std::vector<float> l(13 * 7, 0.37f);
    EXPECT_FLOAT_EQ(static_cast<float>(solid_angle_mean(l, 13, 7)), 0.37f);
    EXPECT_EQ(compensation_threshold(solid_angle_mean(l, 13, 7), 1.0f), 0.37f);  // so a constant map zeroes fully
}

TEST(Compensation, SolidAngleMeanWeightsRowsBySinTheta) {
    std::vector<float> l(2 * 4, 0.0f);
    l[2] = l[3] = 1.0f;  // row 1 of 4
    const double s = [](int y) { return std::sin(3.14159265358979 * (y + 0.5) / 4); }(1);
    double total = 0;
    for (int y = 0; y < 4; ++y) total += std::sin(3.14159265358979 * (y + 0.5) / 4);
    EXPECT_NEAR(solid_angle_mean(l, 2, 4), s / total, 1e-7);  // row weights are floats
}

TEST(Compensation, RejectsMismatchedSizes) {
    EXPECT_THROW(solid_angle_mean(std::vector<float>(5), 2, 2), std::invalid_argument);
}

}  // namespace
}  // namespace envmis
