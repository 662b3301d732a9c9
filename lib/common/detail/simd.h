// Internal: what the AVX2 paths (envmap_many.cpp, estimator_simd.cpp) share: eight
// floats or 32-bit integers in a register, and the scalar idioms of the sampling code
// (ternaries, clamp, min, max, abs) as lane-by-lane operations with the same IEEE results.
// Functions that use them are compiled for AVX2 one by one (ENVMIS_AVX2) and called only
// where batch_paths() (envmis/cpu.h) chose AVX2: the rest of the library stays runnable on
// any x86-64 CPU.
#pragma once

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define ENVMIS_AVX2_BATCHES 1
#include <immintrin.h>

#define ENVMIS_AVX2 __attribute__((target("avx2")))

namespace envmis::simd {

using F8 = __m256;
using I8 = __m256i;

ENVMIS_AVX2 inline F8 splat(float v) noexcept { return _mm256_set1_ps(v); }
// c ? a : b, lane by lane, for a comparison mask c.
ENVMIS_AVX2 inline F8 select(F8 c, F8 a, F8 b) noexcept { return _mm256_blendv_ps(b, a, c); }
ENVMIS_AVX2 inline F8 less(F8 a, F8 b) noexcept { return _mm256_cmp_ps(a, b, _CMP_LT_OQ); }
// clamp() of math.h: v < lo ? lo : (hi < v ? hi : v), NaN passing through.
ENVMIS_AVX2 inline F8 clamp8(F8 v, float lo, float hi) noexcept {
    return select(less(v, splat(lo)), splat(lo), select(less(splat(hi), v), splat(hi), v));
}
ENVMIS_AVX2 inline F8 abs8(F8 v) noexcept { return _mm256_andnot_ps(splat(-0.0f), v); }
// min(a, b) of math.h: b < a ? b : a.
ENVMIS_AVX2 inline F8 min8(F8 a, F8 b) noexcept { return select(less(b, a), b, a); }
// max(0.0f, v) of math.h: 0 < v ? v : 0.
ENVMIS_AVX2 inline F8 max0(F8 v) noexcept { return select(less(splat(0.0f), v), v, splat(0.0f)); }
ENVMIS_AVX2 inline F8 copysign8(F8 magnitude, F8 sign) noexcept {
    return _mm256_or_ps(abs8(magnitude), _mm256_and_ps(splat(-0.0f), sign));
}

}  // namespace envmis::simd
#endif
