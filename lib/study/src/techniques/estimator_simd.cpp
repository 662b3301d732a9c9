// The estimator's lanes in AVX2; see estimator_simd.h. The scalar code each function
// repeats: sample_disk, fast_sincos, fast_pow, sample_cosine_hemisphere, Frame::to_world
// and to_local, reflect, normalize, Bsdf::sample, pdf and eval of every kind with the
// ggx:: functions they call (frame.h, fast_math.h, bsdf.h), and the lanes' add_lanes,
// fixed_weight, balance_weight and power_weight (estimator.cpp, mis_weights.h): the same
// IEEE operations in the same order, no fused multiply-add. What depends on wo and the
// BSDF's parameters alone (Phong's lobe frame, GGX's Lambda(wo) and visible-normal
// frame) is computed once per call by the scalar functions themselves. If one of them
// changes, this file must change with it; the tests that compare estimates made together
// and alone fail until it does.
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

// !(z <= 0): where eval's early return (wi.z <= 0) does not apply.
ENVMIS_AVX2 F8 not_below(F8 z) noexcept { return _mm256_cmp_ps(z, _mm256_setzero_ps(), _CMP_NLE_UQ); }
ENVMIS_AVX2 F8 both(F8 a, F8 b) noexcept { return _mm256_and_ps(a, b); }
ENVMIS_AVX2 F8 sqrt8(F8 v) noexcept { return _mm256_sqrt_ps(v); }
ENVMIS_AVX2 I8 bits_of(F8 v) noexcept { return _mm256_castps_si256(v); }
ENVMIS_AVX2 F8 float_of(I8 v) noexcept { return _mm256_castsi256_ps(v); }
ENVMIS_AVX2 I8 splat_int(uint32_t v) noexcept { return _mm256_set1_epi32(static_cast<int32_t>(v)); }

// fast_pow (fast_math.h).
ENVMIS_AVX2 F8 fast_pow8(F8 x, F8 y) noexcept {
    const F8 subnormal = less(x, splat(0x1p-126f));
    const I8 bits =
        _mm256_add_epi32(bits_of(select(subnormal, mul(x, splat(0x1p24f)), x)), splat_int(0x3f800000u - 0x3f3504f3u));
    const I8 bias = _mm256_add_epi32(splat_int(127), _mm256_and_si256(bits_of(subnormal), splat_int(24)));
    const F8 e = _mm256_cvtepi32_ps(_mm256_sub_epi32(_mm256_srli_epi32(bits, 23), bias));
    const F8 f = sub(float_of(_mm256_add_epi32(_mm256_and_si256(bits, splat_int(0x007fffffu)), splat_int(0x3f3504f3u))),
                     splat(1.0f));
    const F8 s = div(f, add(splat(2.0f), f)), z = mul(s, s), w = mul(z, z);
    const F8 r = add(mul(z, add(splat(0.66666662693f), mul(w, splat(0.28498786688f)))),
                     mul(w, add(splat(0.40000972152f), mul(w, splat(0.24279078841f)))));
    const F8 half_f2 = mul(mul(splat(0.5f), f), f);
    const F8 t = mul(y, add(mul(sub(f, sub(half_f2, mul(s, add(half_f2, r)))), splat(1.44269504089f)), e));
    const F8 round = splat(0x1.8p23f), shifted = add(t, round), g = sub(t, sub(shifted, round));
    F8 p = add(mul(splat(1.535336188319500e-4f), g), splat(1.339887440266574e-3f));
    p = add(mul(p, g), splat(9.618437357674640e-3f));
    p = add(mul(p, g), splat(5.550332471162809e-2f));
    p = add(mul(p, g), splat(2.402264791363012e-1f));
    p = add(mul(p, g), splat(6.931472028550421e-1f));
    p = add(mul(p, g), splat(1.0f));
    const F8 scale = float_of(_mm256_slli_epi32(_mm256_add_epi32(bits_of(shifted), splat_int(127u - 0x4b400000u)), 23));
    const F8 defined = both(greater(x, splat(0.0f)), _mm256_cmp_ps(t, splat(-126.0f), _CMP_GE_OQ));
    return select(defined, mul(p, scale), splat(0.0f));
}

// Eight directions.
struct Dir8 {
    F8 x, y, z;
};
ENVMIS_AVX2 Dir8 load_directions(DirectionArrays d, uint32_t l) noexcept {
    return {load(d.x + l), load(d.y + l), load(d.z + l)};
}

// dot(a, b) for a vector of lanes and one fixed vector, in dot()'s order.
ENVMIS_AVX2 F8 dot8(Dir8 a, Vec3 b) noexcept {
    return add(add(mul(a.x, splat(b.x)), mul(a.y, splat(b.y))), mul(a.z, splat(b.z)));
}
ENVMIS_AVX2 F8 dot8(Dir8 a, Dir8 b) noexcept { return add(add(mul(a.x, b.x), mul(a.y, b.y)), mul(a.z, b.z)); }
// normalize (math.h): v * (1 / sqrt(v . v)).
ENVMIS_AVX2 Dir8 normalize8(Dir8 v) noexcept {
    const F8 inverse = div(splat(1.0f), sqrt8(dot8(v, v)));
    return {mul(v.x, inverse), mul(v.y, inverse), mul(v.z, inverse)};
}
// a x + b y + c z, in that order: a component of a vector sum such as Frame::to_world's.
ENVMIS_AVX2 F8 combine8(float a, F8 x, float b, F8 y, float c, F8 z) noexcept {
    return add(add(mul(splat(a), x), mul(splat(b), y)), mul(splat(c), z));
}
// Frame::to_world: x v.x + y v.y + z v.z, component by component.
ENVMIS_AVX2 Dir8 to_world8(const Frame& f, Dir8 v) noexcept {
    return {combine8(f.x.x, v.x, f.y.x, v.y, f.z.x, v.z), combine8(f.x.y, v.x, f.y.y, v.y, f.z.y, v.z),
            combine8(f.x.z, v.x, f.y.z, v.y, f.z.z, v.z)};
}
ENVMIS_AVX2 Dir8 to_local8(const Frame& f, Dir8 v) noexcept { return {dot8(v, f.x), dot8(v, f.y), dot8(v, f.z)}; }

// A BSDF's pdf and value (f cos) in eight lanes.
struct Values8 {
    F8 pdf, r, g, b;
};
// scale(c, s) (bsdf.h) where `valid`, 0 elsewhere.
ENVMIS_AVX2 Values8 values8(F8 pdf, Rgb c, F8 s, F8 valid) noexcept {
    const F8 zero = splat(0.0f);
    return {pdf, select(valid, mul(splat(c.r), s), zero), select(valid, mul(splat(c.g), s), zero),
            select(valid, mul(splat(c.b), s), zero)};
}

// Bsdf::sample's direction (local frame), pdf and eval of each kind for a view direction
// above the surface: values(wi) at a local direction, sample(u) a local direction.
struct LambertLobe {
    Rgb albedo;

    // pdf and value share cos theta_i / pi where the direction is above the surface.
    ENVMIS_AVX2 Values8 values(Dir8 wi) const noexcept {
        const F8 s = div(wi.z, splat(kPiF));
        return values8(select(greater(wi.z, splat(0.0f)), s, splat(0.0f)), albedo, s, not_below(wi.z));
    }
    // sample_cosine_hemisphere after sample_disk.
    ENVMIS_AVX2 Dir8 sample(F8 ux, F8 uy) const noexcept {
        const F8 a = sub(mul(splat(2.0f), ux), splat(1.0f)), b = sub(mul(splat(2.0f), uy), splat(1.0f));
        const F8 centre =
            _mm256_and_ps(_mm256_cmp_ps(a, splat(0.0f), _CMP_EQ_OQ), _mm256_cmp_ps(b, splat(0.0f), _CMP_EQ_OQ));
        const F8 wide = greater(abs8(a), abs8(b));
        const F8 radius = select(wide, a, b);
        const F8 angle =
            select(wide, mul(splat(kPiF / 4), div(b, a)), sub(splat(kPiF / 2), mul(splat(kPiF / 4), div(a, b))));
        const SinCos8 p = fast_sincos8(angle);
        const F8 dx = select(centre, splat(0.0f), mul(radius, p.cos)),
                 dy = select(centre, splat(0.0f), mul(radius, p.sin));
        return {dx, dy, sqrt8(max0(sub(sub(splat(1.0f), mul(dx, dx)), mul(dy, dy))))};
    }
};

struct PhongLobe {
    Rgb albedo;
    Vec3 mirror;  // reflect_z(wo)
    Frame lobe;   // Frame::from_normal(mirror)
    float n, pdf_scale, eval_scale, sample_power;

    PhongLobe(const Bsdf& bsdf, Vec3 view) noexcept
        : albedo(bsdf.reflectance),
          mirror(reflect_z(view)),
          lobe(Frame::from_normal(mirror)),
          n(bsdf.exponent),
          pdf_scale((n + 1) / (2 * kPiF)),
          eval_scale((n + 2) / (2 * kPiF)),
          sample_power(1 / (n + 1)) {}
    ENVMIS_AVX2 Values8 values(Dir8 wi) const noexcept {
        const F8 c = dot8(wi, mirror), power = fast_pow8(c, splat(n)), in_lobe = greater(c, splat(0.0f));
        const F8 pdf = select(in_lobe, mul(splat(pdf_scale), power), splat(0.0f));
        return values8(pdf, albedo, mul(mul(splat(eval_scale), power), wi.z), both(not_below(wi.z), in_lobe));
    }
    ENVMIS_AVX2 Dir8 sample(F8 ux, F8 uy) const noexcept {
        const F8 cos_a = fast_pow8(ux, splat(sample_power)), sin_a = sqrt8(max0(sub(splat(1.0f), mul(cos_a, cos_a))));
        const SinCos8 phi = fast_sincos8(mul(splat(2 * kPiF), uy));
        return to_world8(lobe, {mul(sin_a, phi.cos), mul(sin_a, phi.sin), cos_a});
    }
};

struct GgxLobe {
    Rgb f0;
    Vec3 wo;
    ggx::VisibleNormalFrame visible;
    float alpha, a2, one_plus_lambda_wo, g1, four_wo_z, s;

    GgxLobe(const Bsdf& bsdf, Vec3 view) noexcept
        : f0(bsdf.reflectance),
          wo(view),
          visible(ggx::visible_normal_frame(wo, bsdf.alpha)),
          alpha(bsdf.alpha),
          a2(alpha * alpha),
          one_plus_lambda_wo(1 + ggx::lambda(wo, alpha)),
          g1(1 / one_plus_lambda_wo),
          four_wo_z(4 * wo.z),
          s(0.5f * (1 + visible.vh.z)) {}
    // ggx::lambda of each lane's wi.
    ENVMIS_AVX2 F8 lambda(F8 z) const noexcept {
        const F8 c2 = mul(z, z), s2 = max0(sub(splat(1.0f), c2));
        const F8 l = mul(splat(0.5f), sub(sqrt8(add(splat(1.0f), div(mul(splat(a2), s2), c2))), splat(1.0f)));
        return select(greater(c2, splat(0.0f)), l, splat(0.0f));
    }
    ENVMIS_AVX2 Values8 values(Dir8 wi) const noexcept {
        const Dir8 m = normalize8({add(splat(wo.x), wi.x), add(splat(wo.y), wi.y), add(splat(wo.z), wi.z)});
        // ggx::distribution(m)
        const F8 t = add(mul(mul(m.z, m.z), splat(a2 - 1)), splat(1.0f));
        const F8 d = select(_mm256_cmp_ps(m.z, splat(0.0f), _CMP_LE_OQ), splat(0.0f),
                            div(splat(a2), mul(mul(splat(kPiF), t), t)));
        const F8 g2 = div(splat(1.0f), add(splat(one_plus_lambda_wo), lambda(wi.z)));
        // ggx::schlick(f0, wi . m)
        const F8 c = sub(splat(1.0f), clamp8(dot8(wi, m), 0.0f, 1.0f)), c5 = mul(mul(mul(mul(c, c), c), c), c);
        const F8 scale = div(mul(d, g2), splat(four_wo_z)), valid = not_below(wi.z), zero = splat(0.0f);
        const auto fresnel = [&](float f) ENVMIS_AVX2 {
            return select(valid, mul(add(splat(f), mul(splat(1 - f), c5)), scale), zero);
        };
        const F8 pdf = select(greater(dot8(m, wo), zero), div(mul(splat(g1), d), splat(four_wo_z)), zero);
        return {pdf, fresnel(f0.r), fresnel(f0.g), fresnel(f0.b)};
    }
    // reflect(wo, ggx::sample_visible_normal(visible, alpha, u))
    ENVMIS_AVX2 Dir8 sample(F8 ux, F8 uy) const noexcept {
        const auto [vh, t1, t2] = visible;
        const F8 r = sqrt8(ux);
        const SinCos8 phi = fast_sincos8(mul(splat(2 * kPiF), uy));
        const F8 p1 = mul(r, phi.cos), rest1 = sub(splat(1.0f), mul(p1, p1));
        const F8 p2 = add(mul(splat(1 - s), sqrt8(max0(rest1))), mul(mul(splat(s), r), phi.sin));
        const F8 h = sqrt8(max0(sub(rest1, mul(p2, p2))));
        // nh = t1 p1 + t2 p2 + vh h, stretched back by alpha, its z at least 1e-7
        const F8 least = splat(1e-7f), nz = combine8(t1.z, p1, t2.z, p2, vh.z, h);
        const Dir8 m =
            normalize8({mul(splat(alpha), combine8(t1.x, p1, t2.x, p2, vh.x, h)),
                        mul(splat(alpha), combine8(t1.y, p1, t2.y, p2, vh.y, h)), select(less(least, nz), nz, least)});
        const F8 twice = mul(splat(2.0f), dot8(m, wo));
        return {sub(mul(m.x, twice), splat(wo.x)), sub(mul(m.y, twice), splat(wo.y)),
                sub(mul(m.z, twice), splat(wo.z))};
    }
};

template <class Lobe>
ENVMIS_AVX2 void sample_with(const Lobe& lobe, const Frame& frame, PointArrays u, SampleArrays out,
                             uint32_t n) noexcept {
    for (uint32_t l = 0; l < n; l += kSimdWidth) {
        const Dir8 wi = lobe.sample(load(u.x + l), load(u.y + l));
        const Values8 v = lobe.values(wi);
        const Dir8 world = to_world8(frame, wi);
        _mm256_storeu_ps(out.x + l, world.x);
        _mm256_storeu_ps(out.y + l, world.y);
        _mm256_storeu_ps(out.z + l, world.z);
        _mm256_storeu_ps(out.pdf + l, v.pdf);
        _mm256_storeu_ps(out.r + l, v.r);
        _mm256_storeu_ps(out.g + l, v.g);
        _mm256_storeu_ps(out.b + l, v.b);
    }
}

template <class Lobe>
ENVMIS_AVX2 void eval_with(const Lobe& lobe, const Frame& frame, DirectionArrays wi, BsdfValueArrays out,
                           uint32_t n) noexcept {
    for (uint32_t l = 0; l < n; l += kSimdWidth) {
        const Values8 v = lobe.values(to_local8(frame, load_directions(wi, l)));
        _mm256_storeu_ps(out.pdf + l, v.pdf);
        _mm256_storeu_ps(out.r + l, v.r);
        _mm256_storeu_ps(out.g + l, v.g);
        _mm256_storeu_ps(out.b + l, v.b);
    }
}

}  // namespace

void sample_bsdf(const Frame& frame, const Bsdf& bsdf, Vec3 wo, PointArrays u, SampleArrays out, uint32_t n) noexcept {
    switch (bsdf.kind) {
        case BsdfKind::lambert: return sample_with(LambertLobe{bsdf.reflectance}, frame, u, out, n);
        case BsdfKind::phong: return sample_with(PhongLobe(bsdf, wo), frame, u, out, n);
        case BsdfKind::ggx: return sample_with(GgxLobe(bsdf, wo), frame, u, out, n);
    }
}

void eval_bsdf(const Frame& frame, const Bsdf& bsdf, Vec3 wo, DirectionArrays wi, BsdfValueArrays out,
               uint32_t n) noexcept {
    switch (bsdf.kind) {
        case BsdfKind::lambert: return eval_with(LambertLobe{bsdf.reflectance}, frame, wi, out, n);
        case BsdfKind::phong: return eval_with(PhongLobe(bsdf, wo), frame, wi, out, n);
        case BsdfKind::ggx: return eval_with(GgxLobe(bsdf, wo), frame, wi, out, n);
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
