// An orthonormal shading frame around a normal, and sampling of the unit disk and the
// cosine-weighted hemisphere in it.
//
// Local coordinates: z is the normal; x and y span the tangent plane. The frame is
// built branch-free from the normal alone (Duff et al. 2017), so the same normal always
// gives the same frame, on the host and on the device.
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
    ENVMIS_HD Vec3 to_local(Vec3 v) const noexcept { return {dot(v, x), dot(v, y), dot(v, z)}; }
    ENVMIS_HD Vec3 to_world(Vec3 v) const noexcept { return x * v.x + y * v.y + z * v.z; }
};

// Mirror of v about the local z axis: the specular reflection of a direction.
ENVMIS_HD inline Vec3 reflect_z(Vec3 v) noexcept { return {-v.x, -v.y, v.z}; }
// Mirror of v about a unit vector m.
ENVMIS_HD inline Vec3 reflect(Vec3 v, Vec3 m) noexcept { return m * (2 * dot(v, m)) - v; }

// Concentric map of [0,1)^2 onto the unit disk (Shirley and Chiu 1997): area-preserving
// and low-distortion, so stratified u stays stratified.
ENVMIS_HD inline Vec2 sample_disk(Vec2 u) noexcept {
    const float a = 2 * u.x - 1, b = 2 * u.y - 1;
    if (a == 0 && b == 0) return {0, 0};
    const bool wide = std::abs(a) > std::abs(b);
    const float r = wide ? a : b;
    const SinCos p = fast_sincos(wide ? (kPiF / 4) * (b / a) : (kPiF / 2) - (kPiF / 4) * (a / b));
    return {r * p.cos, r * p.sin};
}

// Direction with density cos(theta) / pi on the upper (z > 0) hemisphere.
ENVMIS_HD inline Vec3 sample_cosine_hemisphere(Vec2 u) noexcept {
    const Vec2 d = sample_disk(u);
    return {d.x, d.y, std::sqrt(max(0.0f, 1 - d.x * d.x - d.y * d.y))};
}

}  // namespace envmis
