// MIS compensation (Karlik et al. 2019): sample the environment map proportionally to
// q = max(L - alpha * Lbar, 0) instead of L, leaving the dim regions to BSDF sampling.
//
// Lbar is the solid-angle mean of the luminance over the sphere. On an equirectangular
// image every texel of row y has solid angle proportional to sin(theta_y) (row centre),
// so Lbar = sum_y sin(theta_y) sum_x L(x, y) / (w sum_y sin(theta_y)); a plain per-texel
// mean would over-weight the poles. On an equal-area image it is the plain mean.
//
// The compensated density is zero where L <= alpha Lbar even if the radiance is not:
// alone it is not a valid importance-sampling density (see EnvMap::complete()).
#pragma once

#include <cstdint>
#include <span>

#include "envmis/core_export.h"
#include "envmis/image/mapping.h"
#include "envmis/math/math.h"

namespace envmis {

struct CompensationOptions {
    bool enabled = true;
    float alpha = 1.0f;  // >= 0; 0 leaves the density unchanged
};

// Solid-angle-weighted mean of a w x h row-major luminance image (double sums).
ENVMIS_CORE_API double solid_angle_mean(std::span<const float> luminance, uint32_t w, uint32_t h,
                                        Mapping mapping = Mapping::equirect);

// The same mean from the row sums (sum over x of L(x, y)) of a w-wide image.
ENVMIS_CORE_API double solid_angle_mean_of_rows(std::span<const double> row_sums, uint32_t w,
                                                Mapping mapping = Mapping::equirect) noexcept;

// The threshold alpha * Lbar, rounded to float once so that every texel is compared
// with the same value: a texel is zeroed exactly when L <= threshold.
inline float compensation_threshold(double mean_luminance, float alpha) noexcept {
    return static_cast<float>(static_cast<double>(alpha) * mean_luminance);
}

ENVMIS_HD inline float compensate(float luminance, float threshold) noexcept {
    return luminance > threshold ? luminance - threshold : 0.0f;
}

}  // namespace envmis
