// Test support for estimators: the batch call against the same estimates one at a time.
#pragma once

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "envmis/study/techniques/estimator.h"

namespace envmis::test {

// 100 estimates at once must equal 100 single calls bit for bit, from the same random
// numbers, leaving the generator and the point's state where the single calls leave them.
inline void expect_batch_equals_single(const DirectLightingEstimator& estimator, const ShadingPoint& point,
                                       const Bsdf& bsdf, const std::string& label) {
    Pcg32 rng(7), mine(7);
    PointState state, my_state;
    std::vector<Rgb> got(100);
    estimator.estimate(point, bsdf, rng, state, got);
    for (size_t i = 0; i < got.size(); ++i) {
        const Rgb expected = estimator.estimate(point, bsdf, mine, my_state);
        ASSERT_EQ(std::memcmp(&got[i], &expected, sizeof(Rgb)), 0) << label << " estimate " << i;
    }
    EXPECT_EQ(rng.uniform(), mine.uniform()) << label << ": not the same random numbers";
    EXPECT_EQ(state.estimates, my_state.estimates) << label;
}

}  // namespace envmis::test
