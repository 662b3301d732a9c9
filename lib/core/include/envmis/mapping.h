// Equirectangular (latitude-longitude) mapping between image space and directions.
//
// Convention (canonical frame, z up, right-handed), for a point (u, v) in [0,1)^2 of
// the image, u along a row (left to right), v down the columns (v = 0 is the top row):
//   theta = pi v,  phi = 2 pi u,
//   direction = (sin theta cos phi, sin theta sin phi, cos theta).
// Renderers that use another up axis or handedness pick an `Axes` at table-build time;
// it is recorded in the table and applied on the way out (`to_world`) and in
// (`to_canonical`), so the image and its density never change.
//
// Measure: d(omega) = 2 pi^2 sin(theta) du dv, so an image-space density p(u, v) is the
// solid-angle density p / (2 pi^2 sin theta).
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <string_view>

#include "envmis/fast_math.h"
#include "envmis/math.h"

namespace envmis {

// A signed permutation of the axes: world component i = sign(code[i]) * canonical
// component |code[i]| - 1. {1, 2, 3} is the identity (z up); {1, 3, -2} is y up.
struct Axes {
    int8_t code[3] = {1, 2, 3};

    // Parses "x,y,z", "x,z,-y", ... or the presets "z-up" and "y-up".
    // Throws std::invalid_argument naming the text if it is not a signed permutation.
    static Axes parse(std::string_view text);
    std::string to_string() const;
    bool valid() const noexcept;
    friend bool operator==(const Axes&, const Axes&) = default;
};

ENVMIS_HD inline float axis_component(Vec3 v, int8_t code) noexcept {
    const float c = v[(code < 0 ? -code : code) - 1];
    return code < 0 ? -c : c;
}

ENVMIS_HD inline Vec3 to_world(const Axes& a, Vec3 canonical) noexcept {
    return {axis_component(canonical, a.code[0]), axis_component(canonical, a.code[1]),
            axis_component(canonical, a.code[2])};
}

ENVMIS_HD inline Vec3 to_canonical(const Axes& a, Vec3 world) noexcept {
    float c[3] = {0, 0, 0};
    for (int i = 0; i < 3; ++i) {
        const int8_t code = a.code[i];
        c[(code < 0 ? -code : code) - 1] = code < 0 ? -world[i] : world[i];
    }
    return {c[0], c[1], c[2]};
}

// Canonical direction of image point uv, with sin(theta) (>= 0) alongside.
ENVMIS_HD inline Vec3 equirect_direction(Vec2 uv, float* sin_theta = nullptr) noexcept {
    const SinCos t = fast_sincos(kPiF * uv.y), p = fast_sincos(2 * kPiF * uv.x);
    const float st = max(t.sin, 0.0f);
    if (sin_theta) *sin_theta = st;
    return {st * p.cos, st * p.sin, t.cos};
}

// Image point of a canonical unit direction; the inverse of equirect_direction.
ENVMIS_HD inline Vec2 equirect_uv(Vec3 d) noexcept {
    const float z = clamp(d.z, -1.0f, 1.0f);
    const float theta = fast_atan2(std::sqrt(max(0.0f, (1 - z) * (1 + z))), z);
    const float phi = fast_atan2(d.y, d.x);
    constexpr float kInvPi = static_cast<float>(1 / kPi);
    const float u = 0.5f * kInvPi * (phi < 0 ? phi + 2 * kPiF : phi);
    return {clamp(u, 0.0f, kOneMinusEpsilon), clamp(theta * kInvPi, 0.0f, kOneMinusEpsilon)};
}

// sin(theta) at the centre of image row y of h: the row's weight in every
// solid-angle sum over the map (texel solid angle = 2 pi^2 sin(theta_y) / (w h)).
ENVMIS_HD inline float row_sin_theta(uint32_t y, uint32_t h) noexcept {
    return static_cast<float>(std::sin(kPi * (y + 0.5) / h));
}

}  // namespace envmis
