// The estimator's lanes in AVX2; see estimator_simd.h. The angles and powers they take
// (fast_sincos, fast_pow) are fast_math.h's own functions on eight lanes (detail/simd.h).
// The rest repeats scalar code: sample_disk, sample_cosine_hemisphere, Frame::to_world
// and to_local, reflect, normalize, Bsdf::sample, pdf and eval of every kind with the
// ggx:: functions they call (frame.h, bsdf.h), and the lanes' add_lanes, fixed_weight,
// balance_weight and power_weight (estimator.cpp, mis_weights.h): the same IEEE
// operations in the same order, no fused multiply-add. What depends on wo and the
// BSDF's parameters alone (Phong's lobe frame, GGX's Lambda(wo) and visible-normal
// frame) is computed once per call by the scalar functions themselves. If one of them
// changes, this file must change with it; the tests that compare estimates made together
// and alone fail until it does.
#include "estimator_simd.h"

#ifdef ENVMIS_AVX2_BATCHES
namespace envmis::detail {
namespace {

using namespace simd;

// !(z <= 0): where eval's early return (wi.z <= 0) does not apply.
ENVMIS_AVX2 M8 not_below(F8 z) noexcept { return {_mm256_cmp_ps(z, _mm256_setzero_ps(), _CMP_NLE_UQ)}; }

ENVMIS_AVX2 Vec3x8 load_directions(DirectionArrays d, uint32_t l) noexcept {
    return {load(d.x + l), load(d.y + l), load(d.z + l)};
}

// dot(a, b) for a vector of lanes and one fixed vector, in dot()'s order.
ENVMIS_AVX2 F8 dot8(const Vec3x8& a, Vec3 b) noexcept { return a.x * b.x + a.y * b.y + a.z * b.z; }
ENVMIS_AVX2 F8 dot8(const Vec3x8& a, const Vec3x8& b) noexcept { return a.x * b.x + a.y * b.y + a.z * b.z; }
// normalize (math.h): v * (1 / sqrt(v . v)).
ENVMIS_AVX2 Vec3x8 normalize8(const Vec3x8& v) noexcept {
    const F8 inverse = 1.0f / sqrt_of(dot8(v, v));
    return {v.x * inverse, v.y * inverse, v.z * inverse};
}
// a x + b y + c z, in that order: a component of a vector sum such as Frame::to_world's.
ENVMIS_AVX2 F8 combine8(float a, F8 x, float b, F8 y, float c, F8 z) noexcept { return a * x + b * y + c * z; }
// Frame::to_world: x v.x + y v.y + z v.z, component by component.
ENVMIS_AVX2 Vec3x8 to_world8(const Frame& f, const Vec3x8& v) noexcept {
    return {combine8(f.x.x, v.x, f.y.x, v.y, f.z.x, v.z), combine8(f.x.y, v.x, f.y.y, v.y, f.z.y, v.z),
            combine8(f.x.z, v.x, f.y.z, v.y, f.z.z, v.z)};
}
ENVMIS_AVX2 Vec3x8 to_local8(const Frame& f, const Vec3x8& v) noexcept {
    return {dot8(v, f.x), dot8(v, f.y), dot8(v, f.z)};
}

// A BSDF's pdf and value (f cos) in eight lanes.
struct Values8 {
    F8 pdf, r, g, b;
};
// scale(c, s) (bsdf.h) where `valid`, 0 elsewhere.
ENVMIS_AVX2 Values8 values8(F8 pdf, Rgb c, F8 s, M8 valid) noexcept {
    return {pdf, select(valid, c.r * s, 0.0f), select(valid, c.g * s, 0.0f), select(valid, c.b * s, 0.0f)};
}

// Bsdf::sample's direction (local frame), pdf and eval of each kind for a view direction
// above the surface: values(wi) at a local direction, sample(u) a local direction.
struct LambertLobe {
    Rgb albedo;

    // pdf and value share cos theta_i / pi where the direction is above the surface.
    ENVMIS_AVX2 Values8 values(const Vec3x8& wi) const noexcept {
        const F8 s = wi.z / kPiF;
        return values8(select(wi.z > 0.0f, s, 0.0f), albedo, s, not_below(wi.z));
    }
    // sample_cosine_hemisphere after sample_disk.
    ENVMIS_AVX2_FLAT Vec3x8 sample(F8 ux, F8 uy) const noexcept {
        const F8 a = 2.0f * ux - 1.0f, b = 2.0f * uy - 1.0f;
        const M8 centre = a == 0.0f && b == 0.0f, wide = abs_of(a) > abs_of(b);
        const F8 radius = select(wide, a, b);
        const F8 angle = select(wide, kPiF / 4 * (b / a), kPiF / 2 - kPiF / 4 * (a / b));
        const SinCos8 p = fast_sincos(angle);
        const F8 dx = select(centre, 0.0f, radius * p.cos), dy = select(centre, 0.0f, radius * p.sin);
        return {dx, dy, sqrt_of(max(0.0f, 1.0f - dx * dx - dy * dy))};
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
    ENVMIS_AVX2_FLAT Values8 values(const Vec3x8& wi) const noexcept {
        const F8 c = dot8(wi, mirror), power = fast_pow(c, F8(n));
        const M8 in_lobe = c > 0.0f;
        return values8(select(in_lobe, pdf_scale * power, 0.0f), albedo, eval_scale * power * wi.z,
                       not_below(wi.z) && in_lobe);
    }
    ENVMIS_AVX2_FLAT Vec3x8 sample(F8 ux, F8 uy) const noexcept {
        const F8 cos_a = fast_pow(ux, F8(sample_power)), sin_a = sqrt_of(max(0.0f, 1.0f - cos_a * cos_a));
        const SinCos8 phi = fast_sincos(2 * kPiF * uy);
        return to_world8(lobe, {sin_a * phi.cos, sin_a * phi.sin, cos_a});
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
        const F8 c2 = z * z, s2 = max(0.0f, 1.0f - c2);
        return select(c2 > 0.0f, 0.5f * (sqrt_of(1.0f + a2 * s2 / c2) - 1.0f), 0.0f);
    }
    ENVMIS_AVX2 Values8 values(const Vec3x8& wi) const noexcept {
        const Vec3x8 m = normalize8({wo.x + wi.x, wo.y + wi.y, wo.z + wi.z});
        // ggx::distribution(m)
        const F8 t = m.z * m.z * (a2 - 1) + 1.0f, d = select(m.z <= 0.0f, 0.0f, a2 / (kPiF * t * t));
        const F8 g2 = 1.0f / (one_plus_lambda_wo + lambda(wi.z));
        // ggx::schlick(f0, wi . m)
        const F8 c = 1.0f - clamp(dot8(wi, m), 0.0f, 1.0f), c5 = c * c * c * c * c;
        const F8 scale = d * g2 / four_wo_z;
        const M8 valid = not_below(wi.z);
        const auto fresnel = [&](float f) ENVMIS_AVX2 { return select(valid, (f + (1 - f) * c5) * scale, 0.0f); };
        const F8 pdf = select(dot8(m, wo) > 0.0f, g1 * d / four_wo_z, 0.0f);
        return {pdf, fresnel(f0.r), fresnel(f0.g), fresnel(f0.b)};
    }
    // reflect(wo, ggx::sample_visible_normal(visible, alpha, u))
    ENVMIS_AVX2_FLAT Vec3x8 sample(F8 ux, F8 uy) const noexcept {
        const auto [vh, t1, t2] = visible;
        const F8 r = sqrt_of(ux);
        const SinCos8 phi = fast_sincos(2 * kPiF * uy);
        const F8 p1 = r * phi.cos, rest1 = 1.0f - p1 * p1;
        const F8 p2 = (1 - s) * sqrt_of(max(0.0f, rest1)) + s * r * phi.sin;
        const F8 h = sqrt_of(max(0.0f, rest1 - p2 * p2));
        // nh = t1 p1 + t2 p2 + vh h, stretched back by alpha, its z at least 1e-7
        const F8 nz = combine8(t1.z, p1, t2.z, p2, vh.z, h);
        const Vec3x8 m = normalize8({alpha * combine8(t1.x, p1, t2.x, p2, vh.x, h),
                                     alpha * combine8(t1.y, p1, t2.y, p2, vh.y, h), max(1e-7f, nz)});
        const F8 twice = 2.0f * dot8(m, wo);
        return {m.x * twice - wo.x, m.y * twice - wo.y, m.z * twice - wo.z};
    }
};

template <class Lobe>
ENVMIS_AVX2 void sample_with(const Lobe& lobe, const Frame& frame, PointArrays u, SampleArrays out,
                             uint32_t n) noexcept {
    for (uint32_t l = 0; l < n; l += kSimdWidth) {
        const Vec3x8 wi = lobe.sample(load(u.x + l), load(u.y + l));
        const Values8 v = lobe.values(wi);
        const Vec3x8 world = to_world8(frame, wi);
        store(out.x + l, world.x);
        store(out.y + l, world.y);
        store(out.z + l, world.z);
        store(out.pdf + l, v.pdf);
        store(out.r + l, v.r);
        store(out.g + l, v.g);
        store(out.b + l, v.b);
    }
}

template <class Lobe>
ENVMIS_AVX2 void eval_with(const Lobe& lobe, const Frame& frame, DirectionArrays wi, BsdfValueArrays out,
                           uint32_t n) noexcept {
    for (uint32_t l = 0; l < n; l += kSimdWidth) {
        const Values8 v = lobe.values(to_local8(frame, load_directions(wi, l)));
        store(out.pdf + l, v.pdf);
        store(out.r + l, v.r);
        store(out.g + l, v.g);
        store(out.b + l, v.b);
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
    for (uint32_t l = 0; l < n; l += kSimdWidth) {
        const F8 q0 = counts[0] * load(s.p_env + l), q1 = counts[1] * load(s.p_bsdf + l);
        const F8 qk = k == 0 ? q0 : q1;
        const M8 positive = qk > 0.0f;
        F8 weight = 1.0f;
        if (weighting == Weighting::balance) {
            weight = select(positive, qk / (0.0f + q0 + q1), 0.0f);
        } else if (weighting == Weighting::power) {
            const F8 a = q0 / qk, b = q1 / qk;
            weight = select(positive, 1.0f / (0.0f + a * a + b * b), 0.0f);
        }
        const F8 scale = weight / qk;
        const M8 sampled = load(k == 0 ? s.p_env + l : s.p_bsdf + l) > 0.0f;
        const auto accumulate = [&](float* sum, const float* radiance, const float* value) ENVMIS_AVX2 {
            const F8 old = load(sum + l);
            store(sum + l, select(sampled, old + load(radiance + l) * load(value + l) * scale, old));
        };
        accumulate(sums.r, s.radiance_r, s.value_r);
        accumulate(sums.g, s.radiance_g, s.value_g);
        accumulate(sums.b, s.radiance_b, s.value_b);
    }
}

}  // namespace envmis::detail
#endif
