// Mappings between image space and directions: equirectangular (latitude-longitude,
// the default) and equal-area octahedral (Clarberg 2008, the square maps of pbrt-v4).
//
// Equirectangular convention (canonical frame, z up, right-handed), for a point (u, v)
// in [0,1)^2 of the image, u along a row (left to right), v down the columns (v = 0 is
// the top row):
//   theta = pi v,  phi = 2 pi u,
//   direction = (sin theta cos phi, sin theta sin phi, cos theta).
// Measure: d(omega) = 2 pi^2 sin(theta) du dv, so an image-space density p(u, v) is the
// solid-angle density p / (2 pi^2 sin theta).
//
// Equal-area octahedral: a square image; its centre is +z, the midpoints of its edges
// lie on the equator, its four corners are -z. Every texel covers the same solid angle:
// d(omega) = 4 pi du dv, so the solid-angle density is p / (4 pi). Same (u, v) and
// direction conventions as pbrt-v4's EqualAreaSquareToSphere, so a square map written
// with it is one pbrt-v4's `imagemap` infinite light reads with the same orientation.
//
// Renderers that use another up axis or handedness pick an `Axes` at table-build time;
// it is recorded in the table and applied on the way out (`to_world`) and in
// (`to_canonical`), so the image and its density never change.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <string_view>

#include "envmis/core_export.h"
#include "envmis/math/fast_math.h"
#include "envmis/math/math.h"

namespace envmis {

// A signed permutation of the axes: world component i = sign(code[i]) * canonical
// component |code[i]| - 1. {1, 2, 3} is the identity (z up); {1, 3, -2} is y up.
//
// Renderers' conventions for a latitude-longitude image (the same image, read as each
// renderer reads it, with an identity light or world transform), as presets:
//   pbrt-v4   x,y,z    pbrt-v4's own square mapping and its equirect conversion (imgtool
//                      makeequiarea): u = atan2(y, x) / 2 pi, v = acos(z) / pi, z up
//   mitsuba3  y,z,-x   Mitsuba 3's envmap emitter: u = atan2(x, -z) / 2 pi, v = acos(y) / pi, y up
//   blender   -x,y,z   Cycles' environment texture: u = 1/2 - atan2(y, x) / 2 pi, top row +z
// (v from the image's top row). The last two mirror the first: a panorama's u grows as
// one turns right in Mitsuba and Blender, left in pbrt-v4 (whose scenes often hold
// `Scale -1 1 1` for this). tests/core/image/mapping_test.cpp checks each against the
// renderer's formula.
struct ENVMIS_CORE_API Axes {
    int8_t code[3] = {1, 2, 3};

    // Parses "x,y,z", "x,z,-y", ... or the presets "z-up", "y-up", "pbrt-v4",
    // "mitsuba3" and "blender".
    // Throws std::invalid_argument naming the text if it is not a signed permutation.
    static Axes parse(std::string_view text);
    std::string to_string() const;
    // The preset these axes are ("z-up", "y-up", "mitsuba3", "blender"; pbrt-v4 is z-up),
    // or empty.
    std::string_view preset() const noexcept;
    bool valid() const noexcept;
    ENVMIS_HD bool identity() const noexcept { return code[0] == 1 && code[1] == 2 && code[2] == 3; }
    friend bool operator==(const Axes&, const Axes&) = default;
};

// On one float or eight lanes (math.h's lane types), as the mappings below.
template <class F = float>
ENVMIS_HD inline F axis_component(const Vec3Of<F>& v, int8_t code) noexcept {
    const F c = v[(code < 0 ? -code : code) - 1];
    return code < 0 ? -c : c;
}

// Both return early for the default frame, which most renderers use: the general
// permutation takes some thirty instructions and three branches per call. Always
// inlined: GCC has left them as calls inside a caller's sampling loop, where the early
// return then costs a call (measured: docs/performance-log.md, 'keep_whole').
template <class F = float>
ENVMIS_HD ENVMIS_INLINE Vec3Of<F> to_world(const Axes& a, const Vec3Of<F>& canonical) noexcept {
    if (a.identity()) return canonical;
    return {axis_component<F>(canonical, a.code[0]), axis_component<F>(canonical, a.code[1]),
            axis_component<F>(canonical, a.code[2])};
}

template <class F = float>
ENVMIS_HD ENVMIS_INLINE Vec3Of<F> to_canonical(const Axes& a, const Vec3Of<F>& world) noexcept {
    if (a.identity()) return world;
    F c[3] = {world.x, world.y, world.z};
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
template <class F = float>
ENVMIS_HD inline Vec2Of<F> equirect_uv(const Vec3Of<F>& d) noexcept {
    const F z = clamp(d.z, -1.0f, 1.0f);
    const F theta = fast_acos(z);
    // phi / 2 pi in [0, 1) as 1/2 + atan2(-y, -x) / 2 pi: no wrap of a negative phi by a
    // select, which random directions would mispredict.
    constexpr float kInvPi = static_cast<float>(1 / kPi);
    const F u = 0.5f + (0.5f * kInvPi) * fast_atan2(-d.y, -d.x);
    return {clamp(u, 0.0f, kOneMinusEpsilon), clamp(theta * kInvPi, 0.0f, kOneMinusEpsilon)};
}

enum class Mapping : uint32_t { equirect = 1, equal_area = 2 };
ENVMIS_CORE_API std::string_view to_string(Mapping m) noexcept;  // "equirect", "equal-area"
// Reads the names to_string gives. Throws std::invalid_argument naming the text.
ENVMIS_CORE_API Mapping parse_mapping(std::string_view text);

inline constexpr float kFourPi = 4 * kPiF;

// Canonical direction of point uv of an equal-area square (pbrt-v4's convention).
// The azimuth within the quadrant is phi = pi/4 (1 + t), t in [-1, 1]: its cosine and
// sine are (cos a -+ sin a) / sqrt 2 with a = pi/4 t, from the minimax polynomials of
// fast_sincos, which need no range reduction on |a| <= pi/4. Within 2.4e-7 of the exact
// direction (tests/core/image/mapping_test.cpp); cheaper than fast_sincos, whose
// quadrant selects in a random octant are costly (measured: docs/performance-log.md,
// 'equal_area_direction').
//
// A sample waits on this function: its column decides u last. So the polynomials are
// split in two halves that run side by side (Estrin's scheme, in a^2 and a^4), pi/4
// scales the numerator before the division, and 1/sqrt 2 goes inside the root, which
// leaves fewer operations in a row after the division and the root.
template <class F = float>
ENVMIS_HD inline Vec3Of<F> equal_area_direction(const Vec2Of<F>& uv) noexcept {
    const F u = 2.0f * uv.x - 1.0f, v = 2.0f * uv.y - 1.0f, au = abs_of(u), av = abs_of(v);
    // Signed distance from the diamond |u| + |v| = 1 (the equator); r is the distance
    // from the nearer pole, measured along the square.
    const F signed_distance = 1.0f - (au + av), r = 1.0f - abs_of(signed_distance);
    const F a = select(r == 0.0f, 0.0f, ((av - au) * (kPiF / 4)) / r);
    const F a2 = a * a, a3 = a2 * a, a4 = a2 * a2;
    const F sin_a = a3 * ((8.3321608736e-3f * a2 - 1.6666654611e-1f) + a4 * -1.9515295891e-4f) + a;
    const F cos_a =
        a4 * ((-1.388731625493765e-3f * a2 + 4.166664568298827e-2f) + a4 * 2.443315711809948e-5f) + (1.0f - 0.5f * a2);
    const F z = copysign_of(1.0f - r * r, signed_distance);
    const F s = r * sqrt_of(1.0f - (0.5f * r) * r);  // r sqrt(2 - r^2) / sqrt 2; the root's argument is >= 1/2
    return {copysign_of(cos_a - sin_a, u) * s, copysign_of(cos_a + sin_a, v) * s, z};
}

// Point of an equal-area square for a canonical unit direction; the inverse of
// equal_area_direction.
template <class F = float>
ENVMIS_HD inline Vec2Of<F> equal_area_uv(const Vec3Of<F>& d) noexcept {
    const F r = sqrt_of(1.0f - min(abs_of(d.z), 1.0f));
    // The angle within the quadrant, as a fraction of a quarter turn.
    const F t = fast_atan_quarter_turns(abs_of(d.y), abs_of(d.x));
    const F north_v = t * r, north_u = r - north_v;
    const auto south = d.z < 0.0f;  // mirrored across the equator
    const F u = copysign_of(select(south, 1.0f - north_v, north_u), d.x);
    const F v = copysign_of(select(south, 1.0f - north_u, north_v), d.y);
    return {clamp(0.5f * (u + 1.0f), 0.0f, kOneMinusEpsilon), clamp(0.5f * (v + 1.0f), 0.0f, kOneMinusEpsilon)};
}

// sin(theta) at the centre of image row y of h: the row's weight in every
// solid-angle sum over the map (texel solid angle = 2 pi^2 sin(theta_y) / (w h)).
ENVMIS_HD inline float row_sin_theta(uint32_t y, uint32_t h) noexcept {
    return static_cast<float>(std::sin(kPi * (y + 0.5) / h));
}

// Relative solid angle of the texels of row y of h: sin(theta_y) (row centre) for
// equirect, 1 for equal-area, whose texels all cover 4 pi / (w h).
ENVMIS_HD inline float row_weight(Mapping m, uint32_t y, uint32_t h) noexcept {
    return m == Mapping::equal_area ? 1.0f : row_sin_theta(y, h);
}

// Canonical direction of image point uv under mapping m.
ENVMIS_HD inline Vec3 image_direction(Mapping m, Vec2 uv) noexcept {
    return m == Mapping::equal_area ? equal_area_direction(uv) : equirect_direction(uv);
}

// Image point of a canonical unit direction under mapping m.
ENVMIS_HD inline Vec2 image_uv(Mapping m, Vec3 d) noexcept {
    return m == Mapping::equal_area ? equal_area_uv(d) : equirect_uv(d);
}

}  // namespace envmis
