// Internal: the mappings of mapping.h for eight lanes in AVX2 (fast_atan2, equirect_uv,
// equal_area_uv, equal_area_direction, to_world, to_canonical), with the same IEEE
// operations in the same order and no fused multiply-add, so that every lane is
// bit-identical to the scalar call: what sample_many and lookup_many (envmap_many.cpp)
// map with, apart so that a test can compare them with the scalar functions directly
// (tests/core/image/mapping8_test.cpp). An error in the inverse mappings that stays inside
// a texel does not show in a lookup's result; that test sees it.
#pragma once

#include "detail/simd.h"
#include "envmis/image/mapping.h"

#ifdef ENVMIS_AVX2_BATCHES
namespace envmis::simd {

// fast_atan2 (fast_math.h).
ENVMIS_AVX2 inline F8 atan2_8(F8 y, F8 x) noexcept {
    const F8 ax = abs8(x), ay = abs8(y);
    const F8 swap = _mm256_cmp_ps(ay, ax, _CMP_GT_OQ);
    const F8 n = select(swap, ax, ay), d = select(swap, ay, ax);
    const F8 reduce = _mm256_cmp_ps(n, _mm256_mul_ps(splat(0.41421356237309515f), d), _CMP_GT_OQ);
    const F8 num = select(reduce, _mm256_sub_ps(n, d), n), den = select(reduce, _mm256_add_ps(n, d), d);
    const F8 r = select(_mm256_cmp_ps(den, splat(0.0f), _CMP_GT_OQ), _mm256_div_ps(num, den), splat(0.0f));
    const F8 z = _mm256_mul_ps(r, r);
    F8 p = _mm256_sub_ps(_mm256_mul_ps(splat(8.05374449538e-2f), z), splat(1.38776856032e-1f));
    p = _mm256_add_ps(_mm256_mul_ps(p, z), splat(1.99777106478e-1f));
    p = _mm256_sub_ps(_mm256_mul_ps(p, z), splat(3.33329491539e-1f));
    F8 a = _mm256_add_ps(_mm256_mul_ps(_mm256_mul_ps(p, z), r), r);
    a = _mm256_add_ps(a, select(reduce, splat(kPiF / 4), splat(0.0f)));
    a = select(swap, _mm256_sub_ps(splat(kPiF / 2), a), a);
    a = select(less(x, splat(0.0f)), _mm256_sub_ps(splat(kPiF), a), a);
    return copysign8(a, y);
}

// A direction in eight lanes.
struct Vec8 {
    F8 x, y, z;
};

// to_world and to_canonical (mapping.h): a signed permutation, exact.
ENVMIS_AVX2 inline F8 axis_component8(const Vec8& v, int8_t code) noexcept {
    const int axis = code < 0 ? -code : code;
    const F8 c = axis == 1 ? v.x : (axis == 2 ? v.y : v.z);
    return code < 0 ? _mm256_xor_ps(c, splat(-0.0f)) : c;
}
ENVMIS_AVX2 inline Vec8 to_world8(const Axes& a, const Vec8& canonical) noexcept {
    if (a.identity()) return canonical;
    return {axis_component8(canonical, a.code[0]), axis_component8(canonical, a.code[1]),
            axis_component8(canonical, a.code[2])};
}
ENVMIS_AVX2 inline Vec8 to_canonical8(const Axes& a, const Vec8& world) noexcept {
    if (a.identity()) return world;
    F8 c[3];
    const F8 w[3] = {world.x, world.y, world.z};
    for (int i = 0; i < 3; ++i) {
        const int8_t code = a.code[i];
        c[(code < 0 ? -code : code) - 1] = code < 0 ? _mm256_xor_ps(w[i], splat(-0.0f)) : w[i];
    }
    return {c[0], c[1], c[2]};
}

// equal_area_direction (mapping.h).
ENVMIS_AVX2 inline Vec8 equal_area_direction8(F8 uv_x, F8 uv_y) noexcept {
    const F8 one = splat(1.0f);
    const F8 u = _mm256_sub_ps(_mm256_mul_ps(splat(2.0f), uv_x), one);
    const F8 v = _mm256_sub_ps(_mm256_mul_ps(splat(2.0f), uv_y), one);
    const F8 au = abs8(u), av = abs8(v);
    const F8 signed_distance = _mm256_sub_ps(one, _mm256_add_ps(au, av));
    const F8 r = _mm256_sub_ps(one, abs8(signed_distance));
    const F8 a = select(_mm256_cmp_ps(r, splat(0.0f), _CMP_EQ_OQ), splat(0.0f),
                        _mm256_div_ps(_mm256_mul_ps(_mm256_sub_ps(av, au), splat(kPiF / 4)), r));
    const F8 a2 = _mm256_mul_ps(a, a), a3 = _mm256_mul_ps(a2, a), a4 = _mm256_mul_ps(a2, a2);
    F8 sin_a = _mm256_sub_ps(_mm256_mul_ps(splat(8.3321608736e-3f), a2), splat(1.6666654611e-1f));
    sin_a = _mm256_add_ps(sin_a, _mm256_mul_ps(a4, splat(-1.9515295891e-4f)));
    sin_a = _mm256_add_ps(_mm256_mul_ps(a3, sin_a), a);
    F8 cos_a = _mm256_add_ps(_mm256_mul_ps(splat(-1.388731625493765e-3f), a2), splat(4.166664568298827e-2f));
    cos_a = _mm256_add_ps(cos_a, _mm256_mul_ps(a4, splat(2.443315711809948e-5f)));
    cos_a = _mm256_add_ps(_mm256_mul_ps(a4, cos_a), _mm256_sub_ps(one, _mm256_mul_ps(splat(0.5f), a2)));
    const F8 r2 = _mm256_mul_ps(r, r);
    const F8 s = _mm256_mul_ps(r, _mm256_sqrt_ps(_mm256_sub_ps(one, _mm256_mul_ps(_mm256_mul_ps(splat(0.5f), r), r))));
    return {_mm256_mul_ps(copysign8(_mm256_sub_ps(cos_a, sin_a), u), s),
            _mm256_mul_ps(copysign8(_mm256_add_ps(cos_a, sin_a), v), s),
            copysign8(_mm256_sub_ps(one, r2), signed_distance)};
}

// An image point in eight lanes.
struct Uv8 {
    F8 u, v;
};

// equirect_uv (mapping.h).
ENVMIS_AVX2 inline Uv8 equirect_uv8(const Vec8& d) noexcept {
    constexpr float kInvPi = static_cast<float>(1 / kPi);
    const F8 z = clamp8(d.z, -1.0f, 1.0f);
    const F8 s2 = _mm256_mul_ps(_mm256_sub_ps(splat(1.0f), z), _mm256_add_ps(splat(1.0f), z));
    const F8 sin_theta = _mm256_sqrt_ps(max0(s2));
    const F8 theta = atan2_8(sin_theta, z);
    const F8 phi = atan2_8(d.y, d.x);
    const F8 turn = select(less(phi, splat(0.0f)), _mm256_add_ps(phi, splat(2 * kPiF)), phi);
    return {clamp8(_mm256_mul_ps(splat(0.5f * kInvPi), turn), 0.0f, kOneMinusEpsilon),
            clamp8(_mm256_mul_ps(theta, splat(kInvPi)), 0.0f, kOneMinusEpsilon)};
}

// equal_area_uv (mapping.h).
ENVMIS_AVX2 inline Uv8 equal_area_uv8(const Vec8& d) noexcept {
    const F8 one = splat(1.0f), abs_z = abs8(d.z);
    const F8 r = _mm256_sqrt_ps(_mm256_sub_ps(one, min8(abs_z, one)));
    const F8 t = _mm256_mul_ps(atan2_8(abs8(d.y), abs8(d.x)), splat(static_cast<float>(2 / kPi)));
    const F8 north_v = _mm256_mul_ps(t, r), north_u = _mm256_sub_ps(r, north_v);
    const F8 south = less(d.z, splat(0.0f));
    const F8 u = select(south, _mm256_sub_ps(one, north_v), north_u);
    const F8 v = select(south, _mm256_sub_ps(one, north_u), north_v);
    return {clamp8(_mm256_mul_ps(splat(0.5f), _mm256_add_ps(copysign8(u, d.x), one)), 0.0f, kOneMinusEpsilon),
            clamp8(_mm256_mul_ps(splat(0.5f), _mm256_add_ps(copysign8(v, d.y), one)), 0.0f, kOneMinusEpsilon)};
}

}  // namespace envmis::simd
#endif
