// Internal: detail::cell_of and detail::point_in_cell (distribution.h) for eight lanes
// in AVX2, with the same IEEE operations in the same order, so that every lane is
// bit-identical to the scalar call: the placement of sample_many's points
// (envmap_many.cpp), apart so that a test can aim at its rare branches
// (tests/core/sampling/cell8_test.cpp).
#pragma once

#include "detail/simd.h"
#include "envmis/sampling/distribution.h"

#ifdef ENVMIS_AVX2_BATCHES
namespace envmis::simd {

// detail::cell_of: the product in double, truncated, at most n - 1; a NaN (from a NaN
// direction) gets cell 0, as there.
ENVMIS_AVX2 inline I8 cell8(F8 x, uint32_t n) noexcept {
    const F8 c = select(x > 0.0f, min(x, 1.0f), 0.0f);
    const __m256d dn = _mm256_set1_pd(static_cast<double>(n));
    const __m128i lo = _mm256_cvttpd_epi32(_mm256_mul_pd(_mm256_cvtps_pd(_mm256_castps256_ps128(c)), dn));
    const __m128i hi = _mm256_cvttpd_epi32(_mm256_mul_pd(_mm256_cvtps_pd(_mm256_extractf128_ps(c, 1)), dn));
    return _mm256_min_epu32(_mm256_set_m128i(hi, lo), _mm256_set1_epi32(static_cast<int>(n - 1)));
}

// (index + offset) / n in double, rounded to float, for four lanes: by the product with
// 1/n, as detail::quotient_to_float, and by the division when a lane lies next to a
// midpoint between floats or below 2^-126.
ENVMIS_AVX2 inline __m128 quotient4(__m128i index, __m128 offset, uint32_t n) noexcept {
    const __m256d sum = _mm256_add_pd(_mm256_cvtepi32_pd(index), _mm256_cvtps_pd(offset));
    const __m256d product = _mm256_mul_pd(sum, _mm256_set1_pd(1.0 / n));
    const __m256i below_float = _mm256_and_si256(_mm256_castpd_si256(product), _mm256_set1_epi64x((1ll << 29) - 1));
    const __m256i from_edge = _mm256_sub_epi64(below_float, _mm256_set1_epi64x((1ll << 28) - 16));
    const __m256i near_midpoint = _mm256_andnot_si256(_mm256_cmpgt_epi64(_mm256_setzero_si256(), from_edge),
                                                      _mm256_cmpgt_epi64(_mm256_set1_epi64x(32), from_edge));
    const __m256i tiny = _mm256_castpd_si256(_mm256_cmp_pd(product, _mm256_set1_pd(0x1p-126), _CMP_LT_OQ));
    const __m256i divide = _mm256_or_si256(near_midpoint, tiny);
    if (!_mm256_testz_si256(divide, divide)) [[unlikely]]
        return _mm256_cvtpd_ps(_mm256_div_pd(sum, _mm256_set1_pd(static_cast<double>(n))));
    return _mm256_cvtpd_ps(product);
}

// detail::point_in_cell, both of its cases.
ENVMIS_AVX2 inline F8 point_in_cell8(I8 index, F8 offset, uint32_t n) noexcept {
    const F8 i = to_float(index);
    if ((n & (n - 1)) == 0) {
        const float inv_n = 1.0f / static_cast<float>(n);
        const F8 x = i * inv_n + offset * inv_n, next_edge = (i + 1.0f) * inv_n;
        return select(x < next_edge, x, from_bits(to_bits(next_edge) - 1u));
    }
    const F8 x = _mm256_set_m128(quotient4(_mm256_extracti128_si256(index, 1), _mm256_extractf128_ps(offset, 1), n),
                                 quotient4(_mm256_castsi256_si128(index), _mm256_castps256_ps128(offset), n));
    // One float step towards the cell where rounding left it (x > 0 in the first case,
    // x < 1 in the second, so the step is an increment of its bits).
    const I8 c = cell8(x, n);
    const I8 step = _mm256_sub_epi32(_mm256_cmpgt_epi32(index, c), _mm256_cmpgt_epi32(c, index));
    return clamp(from_bits(to_bits(x) - step), 0.0f, kOneMinusEpsilon);
}

}  // namespace envmis::simd
#endif
