// Single-precision sin, cos, atan2 and acos for the sampling hot path, inline and
// branch-light (libm's calls cost more than the rest of an MIS estimate together).
// sin and cos after Cephes (Moshier 1989): Cody-Waite range reduction to [-pi/4, pi/4],
// then minimax polynomials; atan and acos after Abramowitz and Stegun 4.4.49 and 4.4.46.
// Accuracy, against double precision: within 2e-7 absolute for sin and cos on
// |x| <= 8 pi, within 4e-7 (1.5 float ulps of pi) for atan2 everywhere, within 4.5e-7
// for acos on [-1, 1]; checked in tests/core/math/fast_math_test.cpp.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "envmis/math/math.h"

namespace envmis {

struct SinCos {
    float sin = 0, cos = 1;
};

// On one float or eight lanes (math.h's lane types), as everything below but
// make_turn_table.
template <class F>
ENVMIS_HD inline SinCosOf<F> fast_sincos(F x) noexcept {
    const F sign = select(x < 0.0f, -1.0f, 1.0f);
    x = abs_of(x);
    // Quadrant j of x (even), and x - j pi/4 in three exactly representable parts.
    const IntOf<F> j = (truncate(x * 1.27323954473516f) + 1u) & ~1u;
    const F y = to_float(j);
    const F r = ((x - y * 0.78515625f) - y * 2.4187564849853515625e-4f) - y * 3.77489497744594108e-8f;
    const F z = r * r;
    const F s = ((-1.9515295891e-4f * z + 8.3321608736e-3f) * z - 1.6666654611e-1f) * z * r + r;
    const F c =
        ((2.443315711809948e-5f * z - 1.388731625493765e-3f) * z + 4.166664568298827e-2f) * z * z - 0.5f * z + 1.0f;
    const IntOf<F> q = (j >> 1) & 3u;  // which quarter turn
    const auto odd = (q & 1u) == 1u;
    const F sin_x = select(odd, c, s), cos_x = select(odd, s, c);
    return {select((q & 2u) == 2u, -sin_x, sin_x) * sign, select(((q + 1u) & 2u) == 2u, -cos_x, cos_x)};
}

// atan(q) for |q| <= 1: q times a degree-8 polynomial in q^2 (Abramowitz and Stegun
// 4.4.49, within 2e-8 in exact arithmetic).
template <class F>
ENVMIS_HD inline F atan_unit(F q) noexcept {
    const F z = q * q;
    F p = 2.8662257e-3f * z - 1.61657367e-2f;
    p = p * z + 4.29096138e-2f;
    p = p * z - 7.52896400e-2f;
    p = p * z + 1.065626393e-1f;
    p = p * z - 1.420889944e-1f;
    p = p * z + 1.999355085e-1f;
    p = p * z - 3.333314528e-1f;
    return (p * z) * q + q;
}

// atan(min(a, b) / max(a, b)) in [0, pi/4] for a, b >= 0 (0 for (0, 0)): no range
// reduction, the ratio being at most 1.
template <class F>
ENVMIS_HD inline F atan_octant(F a, F b) noexcept {
    return atan_unit(min(a, b) / max(max(a, b), F(0x1p-126f)));
}

// atan2(y, x) in [-pi, pi]; 0 for (0, 0). The octant's arc tangent, then each reflection
// (about pi/4 where |y| > |x|, about pi/2 where x < 0, about 0 where y < 0) as a sign
// copied onto a distance from the mirror, a bit operation: a select would compile to a
// jump, which directions in random octants mispredict half the time (measured:
// docs/performance-log.md, 'fast_atan2').
template <class F>
ENVMIS_HD inline F fast_atan2(F y, F x) noexcept {
    const F ax = abs_of(x), ay = abs_of(y);
    const F b = kPiF / 4 - copysign_of(kPiF / 4 - atan_octant(ax, ay), ax - ay);  // atan(|y| / |x|)
    return copysign_of(kPiF / 2 - copysign_of(kPiF / 2 - b, x), y);
}

// atan(y / x) in quarter turns, [0, 1], for x, y >= 0 (0 for (0, 0)): fast_atan2's first
// quadrant in its own unit, one reflection, about an eighth of a turn. The equal-area
// map's azimuth within its quadrant.
template <class F>
ENVMIS_HD inline F fast_atan_quarter_turns(F y, F x) noexcept {
    const F a = atan_octant(x, y) * static_cast<float>(2 / kPi);  // [0, 1/2]
    return 0.5f - copysign_of(0.5f - a, x - y);
}

// acos(z) in [0, pi] for z in [-1, 1], without a division or a branch: sqrt(1 - |z|)
// times a degree-7 polynomial in |z| (Abramowitz and Stegun 4.4.46, within 2e-8 in exact
// arithmetic), mirrored for z < 0 by the sign bit. The equirectangular map's inverse
// takes its theta from here, where atan2(sqrt(1 - z^2), z) would cost a division and
// the arc tangent's reflections more (measured: docs/performance-log.md, 'fast_acos').
template <class F>
ENVMIS_HD inline F fast_acos(F z) noexcept {
    const F x = abs_of(z);
    F p = -1.2624911e-3f * x + 6.6700901e-3f;
    p = p * x - 1.70881256e-2f;
    p = p * x + 3.08918810e-2f;
    p = p * x - 5.01743046e-2f;
    p = p * x + 8.89789874e-2f;
    p = p * x - 2.145988016e-1f;
    p = p * x + 1.5707963050f;
    const F a = sqrt_of(1.0f - x) * p;  // acos |z|
    return kPiF / 2 - copysign_of(kPiF / 2 - a, z);
}

// x^y for x >= 0 and y >= 0 (x^y <= FLT_MAX), as 2^(y log2 x) in float multiplies, adds,
// one division and bit manipulation: Phong's lobe (cos^n and u^(1/(n+1)), bsdf.h) gets the
// same bits from it on one float and in the estimator's eight AVX2 lanes, which std::pow
// (glibc's powf works in double) cannot give. log: FreeBSD's logf (x = m 2^e with m in
// [sqrt(1/2), sqrt(2)), log m = log1p(m - 1) by a minimax polynomial in s = f / (2 + f),
// within an ulp); 2^t: nearest integer k plus a Cephes polynomial for t - k in
// [-1/2, 1/2]. The error grows with |t| = |y log2 x|, as t's rounding scales the result:
// relative error against double within 1.5e-7 + 1.5e-7 |t| (measured: 1e-7 + 1.23e-7 |t|,
// so 5e-6 at t = -32, a result of 2e-10; tests/core/math/fast_math_test.cpp). Subnormal
// x are scaled into range first; results below 2^-126 (t < -126) are 0, as is 0^y (also
// for y = 0, where std::pow gives 1); x^0 = 1 and 1^y = 1 exactly. About 30 flops.
template <class F>
ENVMIS_HD inline F fast_pow(F x, F y) noexcept {
    // log2 x = e + log(m) / ln 2
    const auto subnormal = x < 0x1p-126f;
    const IntOf<F> bits = to_bits(select(subnormal, x * 0x1p24f, x)) + (0x3f800000u - 0x3f3504f3u);
    const F e = to_float((bits >> 23) - select(subnormal, IntOf<F>(127u + 24u), IntOf<F>(127u)));
    const F f = from_bits((bits & 0x007fffffu) + 0x3f3504f3u) - 1.0f;
    const F s = f / (2.0f + f), z = s * s, w = z * z;
    const F r = z * (0.66666662693f + w * 0.28498786688f) + w * (0.40000972152f + w * 0.24279078841f);
    const F half_f2 = 0.5f * f * f;
    const F t = y * ((f - (half_f2 - s * (half_f2 + r))) * 1.44269504089f + e);
    // 2^t = 2^k 2^(t - k), k = t rounded to the nearest integer in the low mantissa bits
    constexpr float kRound = 0x1.8p23f;
    const F shifted = t + kRound, g = t - (shifted - kRound);
    F p = 1.535336188319500e-4f * g + 1.339887440266574e-3f;
    p = p * g + 9.618437357674640e-3f;
    p = p * g + 5.550332471162809e-2f;
    p = p * g + 2.402264791363012e-1f;
    p = p * g + 6.931472028550421e-1f;
    p = p * g + 1.0f;
    const F scale = from_bits((to_bits(shifted) + (127u - 0x4b400000u)) << 23);
    return select(x > 0.0f && t >= -126.0f, p * scale, 0.0f);
}

// sin and cos of a whole turn's fraction, 2 pi t, from a table of kTurnSteps entries and
// the angle-sum identity: the remainder d is at most half a step, pi / 1024 = 0.0031,
// where sin d = d - d^3/6 and cos d = 1 - d^2/2 are exact to 4e-12, so the result is
// within two float ulps of sin and cos. About fifteen flops and two L1 loads, without
// fast_sincos's range reduction: the samplers, which need two angles per sample, use it.
inline constexpr int32_t kTurnSteps = 1024;

namespace detail {

// sin and cos of 2 pi x / kTurnSteps for |x| < 2^22. The nearest step is found by
// adding 1.5 * 2^23, which rounds x to an integer in the low mantissa bits: a float
// add instead of two int/float conversions, the slowest part of this function
// (measured). It relies on IEEE addition, as every compiler does unless told to
// reassociate (-ffast-math would fold (x + c) - c to x).
ENVMIS_HD inline SinCos turn_entry(const SinCos* table, uint32_t k) noexcept { return table[k]; }

template <class F>
ENVMIS_HD ENVMIS_INLINE SinCosOf<F> sincos_steps(const SinCos* table, F x) noexcept {
    constexpr float kRound = 0x1.8p23f;
    const F rounded = x + kRound;
    // sin d and cos d of the remainder d = c f, written in f so that each term is one
    // multiply nearer to f (the samplers wait on this chain).
    constexpr float c = 2 * kPiF / kTurnSteps;
    const F f = x - (rounded - kRound), f2 = f * f;
    const F sin_d = c * f - f2 * (c * c * c / 6 * f), cos_d = 1.0f - (c * c / 2) * f2;
    const SinCosOf<F> e = turn_entry(table, to_bits(rounded) & (kTurnSteps - 1));  // periodic
    return {e.sin * cos_d + e.cos * sin_d, e.cos * cos_d - e.sin * sin_d};
}

}  // namespace detail

// For |t| < 4096; the scale by kTurnSteps is exact. Always inlined, as the step above:
// EnvMapView::sample waits on them (performance-log.md, 'sincos_turns').
template <class F>
ENVMIS_HD ENVMIS_INLINE SinCosOf<F> sincos_turns(const SinCos* table, F t) noexcept {
    return detail::sincos_steps(table, t * static_cast<float>(kTurnSteps));
}
// sin and cos of pi t (half turns), as precise: the equirectangular map's theta = pi v.
template <class F>
ENVMIS_HD ENVMIS_INLINE SinCosOf<F> sincos_half_turns(const SinCos* table, F t) noexcept {
    return detail::sincos_steps(table, t * static_cast<float>(kTurnSteps / 2));
}

// The table sincos_turns reads: entry k holds sin and cos of 2 pi k / kTurnSteps,
// rounded from double. 8 KiB; copy data() to the device with the other arrays.
inline std::vector<SinCos> make_turn_table() {
    std::vector<SinCos> table(kTurnSteps);
    for (int32_t k = 0; k < kTurnSteps; ++k) {
        const double a = 2 * kPi * k / kTurnSteps;
        table[k] = {static_cast<float>(std::sin(a)), static_cast<float>(std::cos(a))};
    }
    return table;
}

}  // namespace envmis
