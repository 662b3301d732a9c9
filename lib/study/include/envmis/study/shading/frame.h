// An orthonormal shading frame around a normal, and sampling of the unit disk and the
// cosine-weighted hemisphere in it.
//
// Local coordinates: z is the normal; x and y span the tangent plane. The frame is
// built branch-free from the normal alone (Duff et al. 2017), so the same normal always
// gives the same frame, on the host and on the device.
//
// The direction functions are templates on a vector type V: one direction (Vec3, Vec2)
// or eight (the estimator's AVX2 lanes, lib/common/detail/simd.h), written once in lane
// form (both sides of a test computed, one selected; math.h), so that every lane gives
// what the single call gives, bit for bit. V defaults to Vec3 or Vec2, so braced
// arguments such as to_world({x, y, z}) work.
#pragma once

#include <algorithm>
#include <cmath>

#include "envmis/math/fast_math.h"
#include "envmis/math/math.h"

namespace envmis {

struct Frame {
    Vec3 x, y, z;

    ENVMIS_HD static Frame from_normal(Vec3 n) noexcept {
        const float sign = std::copysign(1.0f, n.z);
        const float a = -1.0f / (sign + n.z), b = n.x * n.y * a;
        return {{1 + sign * n.x * n.x * a, sign * b, -sign * n.x}, {b, sign + n.y * n.y * a, -n.y}, n};
    }
    template <class V = Vec3>
    ENVMIS_HD V to_local(const V& v) const noexcept {
        return {dot(v, x), dot(v, y), dot(v, z)};
    }
    template <class V = Vec3>
    ENVMIS_HD V to_world(const V& v) const noexcept {
        return x * v.x + y * v.y + z * v.z;
    }
};

// Mirror of v about the local z axis: the specular reflection of a direction.
ENVMIS_HD inline Vec3 reflect_z(Vec3 v) noexcept { return {-v.x, -v.y, v.z}; }
// Mirror of v about a unit vector m.
template <class V = Vec3>
ENVMIS_HD inline V reflect(Vec3 v, const V& m) noexcept {
    return m * (2.0f * dot(v, m)) - v;
}

// Concentric map of [0,1)^2 onto the unit disk (Shirley and Chiu 1997): area-preserving
// and low-distortion, so stratified u stays stratified.
template <class V = Vec2>
ENVMIS_HD inline V sample_disk(const V& u) noexcept {
    using F = LaneOf<V>;
    const F a = 2.0f * u.x - 1.0f, b = 2.0f * u.y - 1.0f;
    const auto centre = a == 0.0f && b == 0.0f, wide = abs_of(a) > abs_of(b);
    const F r = select(wide, a, b);
    const SinCosOf<F> p = fast_sincos(select(wide, (kPiF / 4) * (b / a), (kPiF / 2) - (kPiF / 4) * (a / b)));
    return {select(centre, 0.0f, r * p.cos), select(centre, 0.0f, r * p.sin)};
}

// Direction with density cos(theta) / pi on the upper (z > 0) hemisphere.
template <class V = Vec2>
ENVMIS_HD inline Vec3Of<LaneOf<V>> sample_cosine_hemisphere(const V& u) noexcept {
    const V d = sample_disk(u);
    return {d.x, d.y, sqrt_of(max(0.0f, 1.0f - d.x * d.x - d.y * d.y))};
}

}  // namespace envmis
