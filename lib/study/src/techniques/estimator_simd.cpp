// The estimator's lanes in AVX2; see estimator_simd.h. The scalar code each function
// repeats: sample_disk, fast_sincos, sample_cosine_hemisphere, Frame::to_world and
// to_local, Bsdf::sample, pdf and eval for BsdfKind::lambert (frame.h, fast_math.h,
// bsdf.h), and the lanes' add_lanes, fixed_weight, balance_weight and power_weight
// (estimator.cpp, mis_weights.h). If one of them changes, this file must change with
// it; the test that compares estimates made together and alone fails until it does.
#include "estimator_simd.h"

#ifdef ENVMIS_AVX2_BATCHES
namespace envmis::detail {
namespace {

using namespace simd;

ENVMIS_AVX2 F8 load(const float* p) noexcept { return _mm256_loadu_ps(p); }
ENVMIS_AVX2 F8 add(F8 a, F8 b) noexcept { return _mm256_add_ps(a, b); }
ENVMIS_AVX2 F8 sub(F8 a, F8 b) noexcept { return _mm256_sub_ps(a, b); }
ENVMIS_AVX2 F8 mul(F8 a, F8 b) noexcept { return _mm256_mul_ps(a, b); }
ENVMIS_AVX2 F8 div(F8 a, F8 b) noexcept { return _mm256_div_ps(a, b); }
ENVMIS_AVX2 F8 greater(F8 a, F8 b) noexcept { return _mm256_cmp_ps(a, b, _CMP_GT_OQ); }
ENVMIS_AVX2 F8 negate(F8 v) noexcept { return _mm256_xor_ps(v, splat(-0.0f)); }
// An integer lane mask (all ones or zeros) as a float select mask.
ENVMIS_AVX2 F8 mask_of(I8 m) noexcept { return _mm256_castsi256_ps(m); }

struct SinCos8 {
    F8 sin, cos;
};

// fast_sincos (fast_math.h).
ENVMIS_AVX2 SinCos8 fast_sincos8(F8 x) noexcept {
    const F8 sign = select(less(x, splat(0.0f)), splat(-1.0f), splat(1.0f));
    x = abs8(x);
    I8 j = _mm256_cvttps_epi32(mul(x, splat(1.27323954473516f)));
    j = _mm256_and_si256(_mm256_add_epi32(j, _mm256_set1_epi32(1)), _mm256_set1_epi32(~1));
    const F8 y = _mm256_cvtepi32_ps(j);
    const F8 r = sub(sub(sub(x, mul(y, splat(0.78515625f))), mul(y, splat(2.4187564849853515625e-4f))),
                     mul(y, splat(3.77489497744594108e-8f)));
    const F8 z = mul(r, r);
    F8 s = add(mul(splat(-1.9515295891e-4f), z), splat(8.3321608736e-3f));
    s = add(mul(mul(sub(mul(s, z), splat(1.6666654611e-1f)), z), r), r);
    F8 c = sub(mul(splat(2.443315711809948e-5f), z), splat(1.388731625493765e-3f));
    c = add(mul(c, z), splat(4.166664568298827e-2f));
    c = add(sub(mul(mul(c, z), z), mul(splat(0.5f), z)), splat(1.0f));
    const I8 q = _mm256_and_si256(_mm256_srai_epi32(j, 1), _mm256_set1_epi32(3));
    const I8 zero = _mm256_setzero_si256();
    const F8 odd = mask_of(_mm256_cmpgt_epi32(_mm256_and_si256(q, _mm256_set1_epi32(1)), zero));
    const F8 sin_x = select(odd, c, s), cos_x = select(odd, s, c);
    const F8 sin_negative = mask_of(_mm256_cmpgt_epi32(_mm256_and_si256(q, _mm256_set1_epi32(2)), zero));
    const I8 q1 = _mm256_add_epi32(q, _mm256_set1_epi32(1));
    const F8 cos_negative = mask_of(_mm256_cmpgt_epi32(_mm256_and_si256(q1, _mm256_set1_epi32(2)), zero));
    return {mul(select(sin_negative, negate(sin_x), sin_x), sign), select(cos_negative, negate(cos_x), cos_x)};
}

// The lanes' common part of a Lambertian pdf and value: cos theta_i / pi where the
// direction is above the surface, 0 elsewhere (both are 0 there).
struct Lambert8 {
    F8 pdf, r, g, b;
};
ENVMIS_AVX2 Lambert8 lambert8(Rgb albedo, F8 cos_i) noexcept {
    const F8 above = greater(cos_i, splat(0.0f)), s = div(cos_i, splat(kPiF)), zero = splat(0.0f);
    return {select(above, s, zero), select(above, mul(splat(albedo.r), s), zero),
            select(above, mul(splat(albedo.g), s), zero), select(above, mul(splat(albedo.b), s), zero)};
}

// a . b for a vector of lanes and one fixed vector, in dot()'s order.
ENVMIS_AVX2 F8 dot8(F8 x, F8 y, F8 z, Vec3 b) noexcept {
    return add(add(mul(x, splat(b.x)), mul(y, splat(b.y))), mul(z, splat(b.z)));
}

}  // namespace

ENVMIS_AVX2 void sample_lambert(const Frame& frame, Rgb albedo, PointArrays u, SampleArrays out, uint32_t n) noexcept {
    for (uint32_t l = 0; l < n; l += kSimdWidth) {
        // sample_disk
        const F8 a = sub(mul(splat(2.0f), load(u.x + l)), splat(1.0f));
        const F8 b = sub(mul(splat(2.0f), load(u.y + l)), splat(1.0f));
        const F8 centre =
            _mm256_and_ps(_mm256_cmp_ps(a, splat(0.0f), _CMP_EQ_OQ), _mm256_cmp_ps(b, splat(0.0f), _CMP_EQ_OQ));
        const F8 wide = greater(abs8(a), abs8(b));
        const F8 radius = select(wide, a, b);
        const F8 angle =
            select(wide, mul(splat(kPiF / 4), div(b, a)), sub(splat(kPiF / 2), mul(splat(kPiF / 4), div(a, b))));
        const SinCos8 p = fast_sincos8(angle);
        const F8 dx = select(centre, splat(0.0f), mul(radius, p.cos)),
                 dy = select(centre, splat(0.0f), mul(radius, p.sin));
        // sample_cosine_hemisphere: z = sqrt(max(0, 1 - dx^2 - dy^2))
        const F8 rest = sub(sub(splat(1.0f), mul(dx, dx)), mul(dy, dy));
        const F8 dz = _mm256_sqrt_ps(select(less(splat(0.0f), rest), rest, splat(0.0f)));
        const Lambert8 v = lambert8(albedo, dz);
        // Frame::to_world: x wi.x + y wi.y + z wi.z, component by component
        const auto world = [&](float fx, float fy, float fz) ENVMIS_AVX2 {
            return add(add(mul(splat(fx), dx), mul(splat(fy), dy)), mul(splat(fz), dz));
        };
        _mm256_storeu_ps(out.x + l, world(frame.x.x, frame.y.x, frame.z.x));
        _mm256_storeu_ps(out.y + l, world(frame.x.y, frame.y.y, frame.z.y));
        _mm256_storeu_ps(out.z + l, world(frame.x.z, frame.y.z, frame.z.z));
        _mm256_storeu_ps(out.pdf + l, v.pdf);
        _mm256_storeu_ps(out.r + l, v.r);
        _mm256_storeu_ps(out.g + l, v.g);
        _mm256_storeu_ps(out.b + l, v.b);
    }
}

ENVMIS_AVX2 void eval_lambert(const Frame& frame, Rgb albedo, DirectionArrays wi, BsdfValueArrays out,
                              uint32_t n) noexcept {
    for (uint32_t l = 0; l < n; l += kSimdWidth) {
        const Lambert8 v = lambert8(albedo, dot8(load(wi.x + l), load(wi.y + l), load(wi.z + l), frame.z));
        _mm256_storeu_ps(out.pdf + l, v.pdf);
        _mm256_storeu_ps(out.r + l, v.r);
        _mm256_storeu_ps(out.g + l, v.g);
        _mm256_storeu_ps(out.b + l, v.b);
    }
}

ENVMIS_AVX2 void add_samples(Weighting weighting, const float counts[2], int k, LaneSamples s, LaneSums sums,
                             uint32_t n) noexcept {
    const F8 zero = splat(0.0f);
    for (uint32_t l = 0; l < n; l += kSimdWidth) {
        const F8 q0 = mul(splat(counts[0]), load(s.p_env + l)), q1 = mul(splat(counts[1]), load(s.p_bsdf + l));
        const F8 qk = k == 0 ? q0 : q1;
        const F8 positive = greater(qk, zero);
        F8 weight = splat(1.0f);
        if (weighting == Weighting::balance) {
            weight = select(positive, div(qk, add(add(zero, q0), q1)), zero);
        } else if (weighting == Weighting::power) {
            const F8 a = div(q0, qk), b = div(q1, qk);
            weight = select(positive, div(splat(1.0f), add(add(zero, mul(a, a)), mul(b, b))), zero);
        }
        const F8 scale = div(weight, qk);
        const F8 sampled = greater(load(k == 0 ? s.p_env + l : s.p_bsdf + l), zero);
        const auto accumulate = [&](float* sum, const float* radiance, const float* value) ENVMIS_AVX2 {
            const F8 old = load(sum + l);
            const F8 updated = add(old, mul(mul(load(radiance + l), load(value + l)), scale));
            _mm256_storeu_ps(sum + l, select(sampled, updated, old));
        };
        accumulate(sums.r, s.radiance_r, s.value_r);
        accumulate(sums.g, s.radiance_g, s.value_g);
        accumulate(sums.b, s.radiance_b, s.value_b);
    }
}

}  // namespace envmis::detail
#endif
