// Analytic reflection BSDFs: Lambertian, energy-normalised modified Phong, and a GGX
// (Trowbridge-Reitz) microfacet conductor.
//
// Conventions: all directions are unit vectors in the local shading frame (frame.h:
// z is the normal), pointing away from the surface: wo towards the viewer, wi towards
// the light. Reflection only: anything with wo or wi below the surface is 0.
//
// The cosine factor lives here and only here: eval(wo, wi) returns f(wo, wi) cos(theta_i),
// the BSDF part of the direct-lighting integrand L(wi) f cos(theta_i). pdf(wo, wi) is
// the solid-angle density of sample(wo, u) over the whole sphere (Phong and GGX also draw
// directions below the surface, whose value is 0), so it integrates to 1 whenever wo is
// above the surface; sample returns eval(wo, wi) with it, so value / pdf is the
// sampling weight.
//
// Phong's powers are fast_pow (fast_math.h: relative error within 1.5e-7 + 1.5e-7 |n log2 c|),
// not std::pow, whose double-precision internals have no lane form: each kind's sample,
// pdf and eval are written once, as a lobe (LambertLobe, PhongLobe, GgxLobe) templated on
// the vector type, for one direction and for the estimator's eight AVX2 lanes
// (estimator_simd.cpp), in lane form (both sides of a test computed, one selected), so
// that every lane gives the single call's result bit for bit. A lobe is built once per
// view direction: what depends on wo and the parameters alone is computed there.
//
// A Bsdf is a small value type (a kind and its parameters) with branch-on-kind methods:
// no virtual calls, usable on the device.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <string_view>

#include "envmis/math/math.h"
#include "envmis/sampling/binned.h"
#include "envmis/study/shading/frame.h"

namespace envmis {

enum class BsdfKind : uint32_t { lambert, phong, ggx };

// A BSDF's pdf and value (f cos) per channel at a direction, on lane type F.
template <class F>
struct BsdfValues {
    F pdf, r, g, b;
};

struct BsdfSample {
    Vec3 wi;
    float pdf = 0;  // solid angle; 0 means no sample
    Rgb value;      // eval(wo, wi): f cos(theta_i)
};

struct Bsdf {
    BsdfKind kind = BsdfKind::lambert;
    Rgb reflectance{0.8f, 0.8f, 0.8f};  // Lambert: albedo; Phong: specular albedo; GGX: F0 (Schlick)
    float exponent = 0;                 // Phong n
    float alpha = 0;                    // GGX roughness (alpha = perceptual roughness squared)

    static Bsdf lambert(Rgb albedo = {0.8f, 0.8f, 0.8f}) { return {BsdfKind::lambert, albedo, 0, 0}; }
    static Bsdf phong(float n, Rgb albedo = {0.8f, 0.8f, 0.8f}) { return {BsdfKind::phong, albedo, n, 0}; }
    static Bsdf ggx(float alpha, Rgb f0 = {0.95f, 0.64f, 0.54f}) { return {BsdfKind::ggx, f0, 0, alpha}; }
    // "lambert[:ALBEDO]", "phong:N[:ALBEDO]" (0 <= N <= 1e5) or "ggx:A[:F0]" (0.001 <= A <= 1),
    // ALBEDO and F0 a grey reflectance in [0, 1] (the same on r, g and b; default: that
    // of lambert(), phong() and ggx()). Throws std::invalid_argument.
    static Bsdf parse(std::string_view text);
    // The text parse() reads back: "lambert", "phong:50", "ggx:0.1" with the default
    // reflectance, followed by ":ALBEDO" otherwise ("lambert:0.5"; a non-grey one as
    // ":R/G/B", which parse() does not read).
    std::string name() const;
    // The reflectance as text: "0.8" when grey, "0.95/0.64/0.54" otherwise.
    std::string albedo_text() const;
    // The reflectance of lambert(), phong() and ggx() when none is given.
    static Rgb default_reflectance(BsdfKind kind);
    // The lobe's sharpness as a Phong exponent (BinnedEnvMap::lobe_class): 0 for Lambert,
    // n for Phong, ggx_lobe_exponent(alpha) for GGX (binned.h: the Phong lobe of
    // reflected directions as wide as GGX's).
    float phong_exponent() const noexcept {
        if (kind == BsdfKind::phong) return exponent;
        return kind == BsdfKind::ggx ? max(0.0f, ggx_lobe_exponent(alpha)) : 0.0f;
    }

    ENVMIS_HD Rgb eval(Vec3 wo, Vec3 wi) const noexcept;
    ENVMIS_HD float pdf(Vec3 wo, Vec3 wi) const noexcept;
    // eval and pdf at once.
    ENVMIS_HD BsdfValues<float> values(Vec3 wo, Vec3 wi) const noexcept;
    ENVMIS_HD BsdfSample sample(Vec3 wo, Vec2 u) const noexcept;
    // fn(lobe) with this BSDF's lobe for wo, which must be above the surface (wo.z > 0).
    template <class Fn>
    ENVMIS_HD auto with_lobe(Vec3 wo, Fn&& fn) const noexcept;
};

namespace ggx {

// Trowbridge-Reitz normal distribution D(m), m a unit vector in the local frame. Its
// denominator a^2 cos^2 + sin^2 as written: the textbook's cos^2 (a^2 - 1) + 1 cancels to
// a^2 cos^2 near the peak, where a float cos^2 carries an error of 6e-8, a^2's size at
// a = 0.00025 (at a = 0.001 the pdf then integrated to 1.08 head-on).
template <class V>
ENVMIS_HD inline LaneOf<V> distribution(const V& m, float alpha) noexcept {
    const float a2 = alpha * alpha;
    const LaneOf<V> t = a2 * (m.z * m.z) + (m.x * m.x + m.y * m.y);
    return select(m.z <= 0.0f, 0.0f, a2 / (kPiF * t * t));
}
// Smith's Lambda(v) for GGX.
template <class V>
ENVMIS_HD inline LaneOf<V> lambda(const V& v, float alpha) noexcept {
    const LaneOf<V> c2 = v.z * v.z, s2 = max(0.0f, 1.0f - c2);
    return select(c2 > 0.0f, 0.5f * (sqrt_of(1.0f + alpha * alpha * s2 / c2) - 1.0f), 0.0f);
}
// Schlick's Fresnel is f0 + (1 - f0) w for this w: (1 - cos)^5.
template <class F>
ENVMIS_HD inline F schlick_weight(F cos_theta) noexcept {
    const F m = 1.0f - clamp(cos_theta, F(0.0f), F(1.0f));
    return m * m * m * m * m;
}
// What sample_visible_normal's hemisphere depends on besides u: wo stretched by alpha
// (vh) and two tangents to it.
struct VisibleNormalFrame {
    Vec3 vh, t1, t2;
};
ENVMIS_HD inline VisibleNormalFrame visible_normal_frame(Vec3 wo, float alpha) noexcept {
    const Vec3 vh = normalize(Vec3{alpha * wo.x, alpha * wo.y, wo.z});
    const float len2 = vh.x * vh.x + vh.y * vh.y;
    const Vec3 t1 = len2 > 0 ? Vec3{-vh.y, vh.x, 0} * (1 / std::sqrt(len2)) : Vec3{1, 0, 0};
    return {vh, t1, cross(vh, t1)};
}
// A visible normal for wo (Heitz 2018): sampled proportionally to G1(wo) max(0, wo.m) D(m) / wo.z.
template <class V = Vec2>
ENVMIS_HD inline Vec3Of<LaneOf<V>> sample_visible_normal(const VisibleNormalFrame& frame, float alpha,
                                                         const V& u) noexcept {
    using F = LaneOf<V>;
    const auto [vh, t1, t2] = frame;
    const F r = sqrt_of(u.x);
    const SinCosOf<F> phi = fast_sincos(2 * kPiF * u.y);
    const float s = 0.5f * (1 + vh.z);
    const F p1 = r * phi.cos;
    const F p2 = (1 - s) * sqrt_of(max(0.0f, 1.0f - p1 * p1)) + s * r * phi.sin;
    const Vec3Of<F> nh = t1 * p1 + t2 * p2 + vh * sqrt_of(max(0.0f, 1.0f - p1 * p1 - p2 * p2));
    return normalize(Vec3Of<F>{alpha * nh.x, alpha * nh.y, max(1e-7f, nh.z)});
}

}  // namespace ggx

// A lobe's pdf at wi and its value c s per channel where `valid`, 0 elsewhere.
template <class F, class M>
ENVMIS_HD inline BsdfValues<F> lobe_values(F pdf, Rgb c, F s, M valid) noexcept {
    return {pdf, select(valid, c.r * s, 0.0f), select(valid, c.g * s, 0.0f), select(valid, c.b * s, 0.0f)};
}

// Each kind's lobe for a view direction above the surface: values(wi) at local
// directions wi (any: eval is 0 below the surface), sample(u) a local direction.
struct LambertLobe {
    Rgb albedo;

    // pdf and value share cos theta_i / pi where the direction is above the surface.
    template <class V>
    ENVMIS_HD BsdfValues<LaneOf<V>> values(const V& wi) const noexcept {
        const LaneOf<V> s = wi.z / kPiF;
        return lobe_values(select(wi.z > 0.0f, s, 0.0f), albedo, s, !(wi.z <= 0.0f));
    }
    template <class V>
    ENVMIS_HD Vec3Of<LaneOf<V>> sample(const V& u) const noexcept {
        return sample_cosine_hemisphere(u);
    }
};

// The normalised lobe cos^n around the mirror direction, drawn below the surface too:
// such samples carry no value, but their density is part of the pdf.
struct PhongLobe {
    Rgb albedo;
    Vec3 mirror;  // reflect_z(wo)
    Frame axis;   // around mirror
    float n, pdf_scale, eval_scale, sample_power;

    ENVMIS_HD PhongLobe(const Bsdf& bsdf, Vec3 wo) noexcept
        : albedo(bsdf.reflectance),
          mirror(reflect_z(wo)),
          axis(Frame::from_normal(mirror)),
          n(bsdf.exponent),
          pdf_scale((n + 1) / (2 * kPiF)),
          eval_scale((n + 2) / (2 * kPiF)),
          sample_power(1 / (n + 1)) {}
    template <class V>
    ENVMIS_HD BsdfValues<LaneOf<V>> values(const V& wi) const noexcept {
        using F = LaneOf<V>;
        const F c = dot(wi, mirror), power = fast_pow(c, F(n));
        const auto in_lobe = c > 0.0f;
        return lobe_values(select(in_lobe, pdf_scale * power, 0.0f), albedo, eval_scale * power * wi.z,
                           !(wi.z <= 0.0f) && in_lobe);
    }
    template <class V>
    ENVMIS_HD Vec3Of<LaneOf<V>> sample(const V& u) const noexcept {
        using F = LaneOf<V>;
        const F cos_a = fast_pow(u.x, F(sample_power)), sin_a = sqrt_of(max(0.0f, 1.0f - cos_a * cos_a));
        const SinCosOf<F> phi = fast_sincos(2 * kPiF * u.y);
        return axis.to_world(Vec3Of<F>{sin_a * phi.cos, sin_a * phi.sin, cos_a});
    }
};

// Reflections of wo about visible normals; those that go below the surface are drawn
// too (with no value), so the density covers them, as for Phong: it integrates to 1 over
// the sphere, as optimal MIS's control variates must.
struct GgxLobe {
    Rgb f0;
    Vec3 wo;
    float alpha;
    ggx::VisibleNormalFrame visible;
    float one_plus_lambda_wo, g1, four_wo_z;  // 1 + Lambda(wo), G1(wo), 4 wo.z

    ENVMIS_HD GgxLobe(const Bsdf& bsdf, Vec3 view) noexcept
        : f0(bsdf.reflectance),
          wo(view),
          alpha(bsdf.alpha),
          visible(ggx::visible_normal_frame(wo, alpha)),
          one_plus_lambda_wo(1 + ggx::lambda(wo, alpha)),
          g1(1 / one_plus_lambda_wo),
          four_wo_z(4 * wo.z) {}
    template <class V>
    ENVMIS_HD BsdfValues<LaneOf<V>> values(const V& wi) const noexcept {
        using F = LaneOf<V>;
        const V m = normalize(wo + wi);
        const F d = ggx::distribution(m, alpha), g2 = 1.0f / (one_plus_lambda_wo + ggx::lambda(wi, alpha));
        const F c5 = ggx::schlick_weight(dot(wi, m)), scale = d * g2 / four_wo_z;
        const auto valid = !(wi.z <= 0.0f);
        const auto fresnel = [&](float f) { return select(valid, (f + (1 - f) * c5) * scale, 0.0f); };
        const F pdf = select(dot(wo, m) > 0.0f, g1 * d / four_wo_z, 0.0f);
        return {pdf, fresnel(f0.r), fresnel(f0.g), fresnel(f0.b)};
    }
    template <class V>
    ENVMIS_HD Vec3Of<LaneOf<V>> sample(const V& u) const noexcept {
        return reflect(wo, ggx::sample_visible_normal(visible, alpha, u));
    }
};

template <class Fn>
ENVMIS_HD inline auto Bsdf::with_lobe(Vec3 wo, Fn&& fn) const noexcept {
    switch (kind) {
        case BsdfKind::phong: return fn(PhongLobe(*this, wo));
        case BsdfKind::ggx: return fn(GgxLobe(*this, wo));
        default: return fn(LambertLobe{reflectance});
    }
}

ENVMIS_HD inline BsdfValues<float> Bsdf::values(Vec3 wo, Vec3 wi) const noexcept {
    if (wo.z <= 0) return {};
    return with_lobe(wo, [&](const auto& lobe) { return lobe.values(wi); });
}
ENVMIS_HD inline Rgb Bsdf::eval(Vec3 wo, Vec3 wi) const noexcept {
    const BsdfValues<float> v = values(wo, wi);
    return {v.r, v.g, v.b};
}
ENVMIS_HD inline float Bsdf::pdf(Vec3 wo, Vec3 wi) const noexcept { return values(wo, wi).pdf; }

ENVMIS_HD inline BsdfSample Bsdf::sample(Vec3 wo, Vec2 u) const noexcept {
    if (wo.z <= 0) return {};
    return with_lobe(wo, [&](const auto& lobe) {
        const Vec3 wi = lobe.sample(u);
        const BsdfValues<float> v = lobe.values(wi);
        return BsdfSample{wi, v.pdf, {v.r, v.g, v.b}};
    });
}

}  // namespace envmis
