// Internal: eight lanes of AVX2 as value types, so that the sampling code is written once.
// F8 (eight floats), I8 (eight 32-bit integers) and M8 (a lane mask, what F8's and I8's
// comparisons give) have the operators of float, uint32_t and bool and the lane
// functions of math.h (select, abs_of, sqrt_of, copysign_of, min, max, clamp, to_float,
// truncate, to_bits, from_bits), with the same IEEE results; Lanes<F8> names their
// vectors. The functions written as templates on a lane type F (fast_math.h, mapping.h,
// envmap.h) thus give every lane the result the scalar call gives, bit for bit,
// by construction: no fused multiply-add, the operations in the order the template
// writes them (tests/core/image/mapping8_test.cpp checks the mappings, envmap_test.cpp
// the batch calls, estimator_test.cpp the estimator's lanes).
//
// A function that uses them is compiled for AVX2 (ENVMIS_AVX2) and called only where
// batch_paths() (envmis/cpu.h) chose AVX2, so the rest of the library stays runnable on
// any x86-64 CPU. One that calls those templates is also flattened (ENVMIS_AVX2_FLAT):
// every call in it is inlined, so the templates, which stay plain inline functions for
// their scalar callers, are compiled into it for AVX2.
#pragma once

#include "envmis/math/fast_math.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define ENVMIS_AVX2_BATCHES 1
#include <immintrin.h>

#define ENVMIS_AVX2 __attribute__((target("avx2")))
#define ENVMIS_AVX2_FLAT __attribute__((target("avx2"), flatten))

// The lane types are laid out as AVX2 sees them: defined under the default target, a
// struct holding an __m256 has no vector mode in GCC, which copies it through memory in
// 16-byte halves that the next 32-byte load cannot forward from. (Clang has no such pragma.)
#if !defined(__clang__)
#pragma GCC push_options
#pragma GCC target("avx2")
#endif
namespace envmis::simd {

struct M8 {
    __m256 v;
    ENVMIS_AVX2 friend M8 operator&&(M8 a, M8 b) noexcept { return {_mm256_and_ps(a.v, b.v)}; }
    ENVMIS_AVX2 friend M8 operator!(M8 a) noexcept {
        return {_mm256_xor_ps(a.v, _mm256_castsi256_ps(_mm256_set1_epi32(-1)))};
    }
};

// uint32_t's arithmetic: wrapping, >> logical; to_float reads a lane as signed.
struct I8 {
    __m256i v;
    I8() = default;
    ENVMIS_AVX2 I8(__m256i x) noexcept : v(x) {}
    ENVMIS_AVX2 I8(uint32_t x) noexcept : v(_mm256_set1_epi32(static_cast<int32_t>(x))) {}
    ENVMIS_AVX2 operator __m256i() const noexcept { return v; }
    ENVMIS_AVX2 friend I8 operator+(I8 a, I8 b) noexcept { return _mm256_add_epi32(a, b); }
    ENVMIS_AVX2 friend I8 operator-(I8 a, I8 b) noexcept { return _mm256_sub_epi32(a, b); }
    ENVMIS_AVX2 friend I8 operator*(I8 a, I8 b) noexcept { return _mm256_mullo_epi32(a, b); }
    ENVMIS_AVX2 friend I8 operator&(I8 a, I8 b) noexcept { return _mm256_and_si256(a, b); }
    ENVMIS_AVX2 friend I8 operator<<(I8 a, int n) noexcept { return _mm256_slli_epi32(a, n); }
    ENVMIS_AVX2 friend I8 operator>>(I8 a, int n) noexcept { return _mm256_srli_epi32(a, n); }
    ENVMIS_AVX2 friend M8 operator==(I8 a, I8 b) noexcept { return {_mm256_castsi256_ps(_mm256_cmpeq_epi32(a, b))}; }
};

struct F8 {
    __m256 v;
    F8() = default;
    ENVMIS_AVX2 F8(__m256 x) noexcept : v(x) {}
    ENVMIS_AVX2 F8(float x) noexcept : v(_mm256_set1_ps(x)) {}
    ENVMIS_AVX2 operator __m256() const noexcept { return v; }
    ENVMIS_AVX2 friend F8 operator+(F8 a, F8 b) noexcept { return _mm256_add_ps(a, b); }
    ENVMIS_AVX2 friend F8 operator-(F8 a, F8 b) noexcept { return _mm256_sub_ps(a, b); }
    ENVMIS_AVX2 friend F8 operator*(F8 a, F8 b) noexcept { return _mm256_mul_ps(a, b); }
    ENVMIS_AVX2 friend F8 operator/(F8 a, F8 b) noexcept { return _mm256_div_ps(a, b); }
    ENVMIS_AVX2 friend F8 operator-(F8 a) noexcept { return _mm256_xor_ps(a, _mm256_set1_ps(-0.0f)); }
    ENVMIS_AVX2 friend M8 operator<(F8 a, F8 b) noexcept { return {_mm256_cmp_ps(a, b, _CMP_LT_OQ)}; }
    ENVMIS_AVX2 friend M8 operator>(F8 a, F8 b) noexcept { return {_mm256_cmp_ps(a, b, _CMP_GT_OQ)}; }
    ENVMIS_AVX2 friend M8 operator<=(F8 a, F8 b) noexcept { return {_mm256_cmp_ps(a, b, _CMP_LE_OQ)}; }
    ENVMIS_AVX2 friend M8 operator>=(F8 a, F8 b) noexcept { return {_mm256_cmp_ps(a, b, _CMP_GE_OQ)}; }
    ENVMIS_AVX2 friend M8 operator==(F8 a, F8 b) noexcept { return {_mm256_cmp_ps(a, b, _CMP_EQ_OQ)}; }
};

// c ? a : b, lane by lane.
ENVMIS_AVX2 inline F8 select(M8 c, F8 a, F8 b) noexcept { return _mm256_blendv_ps(b, a, c.v); }
ENVMIS_AVX2 inline I8 select(M8 c, I8 a, I8 b) noexcept { return _mm256_blendv_epi8(b, a, _mm256_castps_si256(c.v)); }
ENVMIS_AVX2 inline F8 select(M8 c, float a, float b) noexcept { return select(c, F8(a), F8(b)); }
ENVMIS_AVX2 inline F8 abs_of(F8 v) noexcept { return _mm256_andnot_ps(_mm256_set1_ps(-0.0f), v); }
ENVMIS_AVX2 inline F8 sqrt_of(F8 v) noexcept { return _mm256_sqrt_ps(v); }
ENVMIS_AVX2 inline F8 copysign_of(F8 magnitude, F8 sign) noexcept {
    return _mm256_or_ps(abs_of(magnitude), _mm256_and_ps(_mm256_set1_ps(-0.0f), sign));
}
// min, max and clamp of math.h: b < a ? b : a, a < b ? b : a, and
// v < lo ? lo : (hi < v ? hi : v), NaN passing through as there.
ENVMIS_AVX2 inline F8 min(F8 a, F8 b) noexcept { return select(b < a, b, a); }
ENVMIS_AVX2 inline F8 max(F8 a, F8 b) noexcept { return select(a < b, b, a); }
ENVMIS_AVX2 inline F8 clamp(F8 v, F8 lo, F8 hi) noexcept { return select(v < lo, lo, select(hi < v, hi, v)); }
ENVMIS_AVX2 inline F8 to_float(I8 v) noexcept { return _mm256_cvtepi32_ps(v); }
ENVMIS_AVX2 inline I8 truncate(F8 v) noexcept { return _mm256_cvttps_epi32(v); }
ENVMIS_AVX2 inline I8 to_bits(F8 v) noexcept { return _mm256_castps_si256(v); }
ENVMIS_AVX2 inline F8 from_bits(I8 v) noexcept { return _mm256_castsi256_ps(v); }

ENVMIS_AVX2 inline F8 load(const float* p) noexcept { return _mm256_loadu_ps(p); }
ENVMIS_AVX2 inline void store(float* p, F8 v) noexcept { _mm256_storeu_ps(p, v); }
ENVMIS_AVX2 inline I8 load(const uint32_t* p) noexcept {
    return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p));
}

struct Vec2x8 {
    F8 x, y;
};
struct Vec3x8 {
    F8 x, y, z;
    Vec3x8() = default;
    ENVMIS_AVX2 Vec3x8(F8 x_, F8 y_, F8 z_) noexcept : x(x_), y(y_), z(z_) {}
    // One vector in every lane, so that Vec3's operations mix with eight lanes'.
    ENVMIS_AVX2 Vec3x8(Vec3 v) noexcept : x(v.x), y(v.y), z(v.z) {}
    // A copy, not a reference: selecting among references would keep the vector in memory.
    ENVMIS_AVX2 F8 operator[](int i) const noexcept { return i == 0 ? F8(x) : (i == 1 ? F8(y) : F8(z)); }
};
// Vec3's operators, dot and normalize (math.h), component by component in its order.
ENVMIS_AVX2 inline Vec3x8 operator+(const Vec3x8& a, const Vec3x8& b) noexcept {
    return {a.x + b.x, a.y + b.y, a.z + b.z};
}
ENVMIS_AVX2 inline Vec3x8 operator-(const Vec3x8& a, const Vec3x8& b) noexcept {
    return {a.x - b.x, a.y - b.y, a.z - b.z};
}
ENVMIS_AVX2 inline Vec3x8 operator*(const Vec3x8& a, F8 s) noexcept { return {a.x * s, a.y * s, a.z * s}; }
ENVMIS_AVX2 inline F8 dot(const Vec3x8& a, const Vec3x8& b) noexcept { return a.x * b.x + a.y * b.y + a.z * b.z; }
ENVMIS_AVX2 inline Vec3x8 normalize(const Vec3x8& a) noexcept { return a * (1.0f / sqrt_of(dot(a, a))); }
struct SinCos8 {
    F8 sin, cos;
};

ENVMIS_AVX2 inline I8 gather(const uint32_t* a, I8 i) noexcept {
    return _mm256_i32gather_epi32(reinterpret_cast<const int*>(a), i, 4);
}
// a[i] and a[i + 1] in eight lanes, from two gathers of 64-bit pairs: a gather's cost
// grows with its elements, so two values a lane come cheaper as pairs (measured:
// docs/performance-log.md, 'gather_pairs').
struct Pair8 {
    I8 first, second;
};
ENVMIS_AVX2 inline Pair8 gather_pairs(const void* a, I8 i) noexcept {
    const auto* q = static_cast<const long long*>(a);
    // lo holds a0 b0 a1 b1 | a2 b2 a3 b3 and hi a4 b4 ... a7 b7 (b: the second values);
    // in_order puts the eight lanes of a0 a1 a4 a5 | a2 a3 a6 a7 in order.
    const __m256 lo = _mm256_castsi256_ps(_mm256_i32gather_epi64(q, _mm256_castsi256_si128(i), 4));
    const __m256 hi = _mm256_castsi256_ps(_mm256_i32gather_epi64(q, _mm256_extracti128_si256(i, 1), 4));
    const auto in_order = [](__m256 v) ENVMIS_AVX2 {
        return I8(_mm256_castpd_si256(_mm256_permute4x64_pd(_mm256_castps_pd(v), _MM_SHUFFLE(3, 1, 2, 0))));
    };
    return {in_order(_mm256_shuffle_ps(lo, hi, _MM_SHUFFLE(2, 0, 2, 0))),
            in_order(_mm256_shuffle_ps(lo, hi, _MM_SHUFFLE(3, 1, 3, 1)))};
}
// The turn table's entries k (fast_math.h's turn_entry).
ENVMIS_AVX2 inline SinCos8 turn_entry(const SinCos* table, I8 k) noexcept {
    const Pair8 e = gather_pairs(table, k + k);
    return {from_bits(e.first), from_bits(e.second)};
}

}  // namespace envmis::simd
#if !defined(__clang__)
#pragma GCC pop_options
#endif

namespace envmis {
template <>
struct Lanes<simd::F8> {
    using Int = simd::I8;
    using Vec2 = simd::Vec2x8;
    using Vec3 = simd::Vec3x8;
    using SinCos = simd::SinCos8;
};
}  // namespace envmis
#endif
