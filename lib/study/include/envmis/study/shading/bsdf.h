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
// not std::pow: the estimator's AVX2 lanes (estimator_simd.cpp) repeat sample, pdf and
// eval operation for operation, bit for bit, which std::pow's double-precision
// internals would not allow. Everything else here is IEEE-exact arithmetic, sqrt and
// fast_sincos, which the lanes repeat as they are.
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
    ENVMIS_HD BsdfSample sample(Vec3 wo, Vec2 u) const noexcept;
};

namespace ggx {

// Trowbridge-Reitz normal distribution D(m), m in the local frame.
ENVMIS_HD inline float distribution(Vec3 m, float alpha) noexcept {
    if (m.z <= 0) return 0;
    const float a2 = alpha * alpha, t = m.z * m.z * (a2 - 1) + 1;
    return a2 / (kPiF * t * t);
}
// Smith's Lambda(v) for GGX.
ENVMIS_HD inline float lambda(Vec3 v, float alpha) noexcept {
    const float c2 = v.z * v.z, s2 = max(0.0f, 1 - c2);
    return c2 > 0 ? 0.5f * (std::sqrt(1 + alpha * alpha * s2 / c2) - 1) : 0.0f;
}
ENVMIS_HD inline Rgb schlick(Rgb f0, float cos_theta) noexcept {
    const float m = 1 - clamp(cos_theta, 0.0f, 1.0f), m5 = m * m * m * m * m;
    return {f0.r + (1 - f0.r) * m5, f0.g + (1 - f0.g) * m5, f0.b + (1 - f0.b) * m5};
}
// What sample_visible_normal's hemisphere depends on besides u: wo stretched by alpha
// (vh) and two tangents to it. The estimator's lanes (one wo, many u) compute it once.
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
ENVMIS_HD inline Vec3 sample_visible_normal(const VisibleNormalFrame& frame, float alpha, Vec2 u) noexcept {
    const auto [vh, t1, t2] = frame;
    const float r = std::sqrt(u.x);
    const SinCos phi = fast_sincos(2 * kPiF * u.y);
    const float p1 = r * phi.cos, s = 0.5f * (1 + vh.z);
    const float p2 = (1 - s) * std::sqrt(max(0.0f, 1 - p1 * p1)) + s * r * phi.sin;
    const Vec3 nh = t1 * p1 + t2 * p2 + vh * std::sqrt(max(0.0f, 1 - p1 * p1 - p2 * p2));
    return normalize(Vec3{alpha * nh.x, alpha * nh.y, max(1e-7f, nh.z)});
}
ENVMIS_HD inline Vec3 sample_visible_normal(Vec3 wo, float alpha, Vec2 u) noexcept {
    return sample_visible_normal(visible_normal_frame(wo, alpha), alpha, u);
}

}  // namespace ggx

ENVMIS_HD inline Rgb scale(Rgb c, float s) noexcept { return {c.r * s, c.g * s, c.b * s}; }

ENVMIS_HD inline Rgb Bsdf::eval(Vec3 wo, Vec3 wi) const noexcept {
    if (wo.z <= 0 || wi.z <= 0) return {};
    switch (kind) {
        case BsdfKind::lambert: return scale(reflectance, wi.z / kPiF);
        case BsdfKind::phong: {
            const float c = dot(wi, reflect_z(wo));
            return c > 0 ? scale(reflectance, (exponent + 2) / (2 * kPiF) * fast_pow(c, exponent) * wi.z) : Rgb{};
        }
        case BsdfKind::ggx: {
            const Vec3 m = normalize(wo + wi);
            const float g2 = 1 / (1 + ggx::lambda(wo, alpha) + ggx::lambda(wi, alpha));
            return scale(ggx::schlick(reflectance, dot(wi, m)), ggx::distribution(m, alpha) * g2 / (4 * wo.z));
        }
    }
    return {};
}

ENVMIS_HD inline float Bsdf::pdf(Vec3 wo, Vec3 wi) const noexcept {
    if (wo.z <= 0) return 0;
    switch (kind) {
        case BsdfKind::lambert: return wi.z > 0 ? wi.z / kPiF : 0.0f;
        case BsdfKind::phong: {
            // The lobe around the mirror direction, below the surface too: such samples
            // are drawn (and carry no value), so their density is part of the pdf.
            const float c = dot(wi, reflect_z(wo));
            return c > 0 ? (exponent + 1) / (2 * kPiF) * fast_pow(c, exponent) : 0.0f;
        }
        case BsdfKind::ggx: {
            // Reflections of wo about a visible normal; those that go below the surface
            // are drawn too (with no value), so the density covers them, as for Phong:
            // it integrates to 1 over the sphere, as optimal MIS's control variates must.
            const Vec3 m = normalize(wo + wi);
            const float g1 = 1 / (1 + ggx::lambda(wo, alpha));
            return dot(wo, m) > 0 ? g1 * ggx::distribution(m, alpha) / (4 * wo.z) : 0.0f;
        }
    }
    return 0;
}

ENVMIS_HD inline BsdfSample Bsdf::sample(Vec3 wo, Vec2 u) const noexcept {
    if (wo.z <= 0) return {};
    Vec3 wi;
    switch (kind) {
        case BsdfKind::lambert: wi = sample_cosine_hemisphere(u); break;
        case BsdfKind::phong: {
            const float cos_a = fast_pow(u.x, 1 / (exponent + 1)), sin_a = std::sqrt(max(0.0f, 1 - cos_a * cos_a));
            const SinCos phi = fast_sincos(2 * kPiF * u.y);
            wi = Frame::from_normal(reflect_z(wo)).to_world({sin_a * phi.cos, sin_a * phi.sin, cos_a});
            break;
        }
        case BsdfKind::ggx: wi = reflect(wo, ggx::sample_visible_normal(wo, alpha, u)); break;
    }
    return {wi, pdf(wo, wi), eval(wo, wi)};
}

}  // namespace envmis
