// Turning an environment map at render time: a rotation given to a view, applied to the
// directions that go in (pdf, eval, lookup, a shading point's normal) and come out
// (sample), so that a renderer can spin a sky, or follow a scene's light transform,
// without rebuilding its table.
//
// Why a wrapper and not a wider Axes: the table's frame (Axes, fixed at precompute time:
// mapping.h) is a signed permutation, free for the default frame; a general rotation
// costs nine multiplies each way, which only a renderer that turns its map pays.
//
// Measure: a rotation preserves solid angle, so densities are unchanged: pdf(R d) of the
// rotated view is the view's pdf(d). Exactness: R and its transpose are applied in float,
// so pdf(sample(u).direction) may land in a neighbouring texel where the unrotated one
// would not (as it may without rotation; envmap.h). The batch forms are bit-identical to
// single calls. Cost: sample, pdf, eval and lookup as the view's plus one 3x3 product.
#pragma once

#include <cstdint>

#include "envmis/core_export.h"
#include "envmis/math/math.h"
#include "envmis/sampling/binned.h"
#include "envmis/sampling/envmap.h"

namespace envmis {

// A proper rotation (orthonormal, determinant +1) from the map's world frame, the one its
// table was built for, to the renderer's: world = M local.
struct Rotation {
    float m[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};  // rows

    // Right-hand rule about `axis` (any length > 0), by `radians`. Throws
    // std::invalid_argument on a zero or non-finite axis or angle.
    ENVMIS_CORE_API static Rotation about(Vec3 axis, float radians);
    // From a 3x3 matrix's rows, checked to be a rotation within 1e-4 (a renderer's
    // light-to-world transform without its scale); re-orthonormalised. Throws
    // std::invalid_argument naming the problem (not orthonormal, a reflection).
    ENVMIS_CORE_API static Rotation from_rows(const float (&rows)[3][3]);
    // Rotation about the axis of the frame a map was built for (Axes): z for z up.
    ENVMIS_CORE_API static Rotation about_up(const Axes& axes, float radians);

    ENVMIS_HD Vec3 to_world(Vec3 v) const noexcept {
        return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
                m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
    }
    ENVMIS_HD Vec3 to_local(Vec3 v) const noexcept {
        return {m[0][0] * v.x + m[1][0] * v.y + m[2][0] * v.z, m[0][1] * v.x + m[1][1] * v.y + m[2][1] * v.z,
                m[0][2] * v.x + m[1][2] * v.y + m[2][2] * v.z};
    }
};

// A view (EnvMapView, a binned map's BinView) turned by a rotation: the same interface.
template <class View>
struct Rotated {
    View view;
    Rotation rotation;

    ENVMIS_HD EnvSample sample(Vec2 u) const noexcept {
        EnvSample s = view.sample(u);
        s.direction = rotation.to_world(s.direction);
        return s;
    }
    ENVMIS_HD float pdf(Vec3 direction) const noexcept { return view.pdf(rotation.to_local(direction)); }
    ENVMIS_HD Rgb eval(Vec3 direction) const noexcept { return view.eval(rotation.to_local(direction)); }
    ENVMIS_HD EnvMapView::Lookup lookup(Vec3 direction) const noexcept {
        return view.lookup(rotation.to_local(direction));
    }
};

// A normal-aware map turned by a rotation: the shading point's axis is turned into the
// map's frame to pick its bin, and the bin is returned turned.
struct RotatedBinned {
    const BinnedEnvMapView* map = nullptr;  // must outlive this and the bins it returns
    Rotation rotation;

    ENVMIS_HD Rotated<BinView> bin(LobeAxis at, uint32_t lobe, float choice) const noexcept {
        return {map->bin({rotation.to_local(at.axis), at.view_cos}, lobe, choice), rotation};
    }
    ENVMIS_HD Rgb eval(Vec3 direction) const noexcept { return map->eval(rotation.to_local(direction)); }
};

// The batch forms (envmap.h, binned.h) in the rotated frame, bit-identical to single
// calls of Rotated; host only, noexcept and allocation-free (directions turned in blocks
// on the stack).
ENVMIS_CORE_API void lookup_many(const Rotated<EnvMapView>& env, DirectionArrays in, LookupArrays out,
                                 uint32_t n) noexcept;
ENVMIS_CORE_API void sample_many(const Rotated<EnvMapView>& env, PointArrays in, SampleArrays out, uint32_t n) noexcept;
ENVMIS_CORE_API void lookup_many(const RotatedBinned& env, uint32_t lobe, LobeAxisArrays axes, const float* choices,
                                 DirectionArrays in, LookupArrays out, uint32_t n) noexcept;
ENVMIS_CORE_API void sample_many(const RotatedBinned& env, uint32_t lobe, LobeAxisArrays axes, const float* choices,
                                 PointArrays in, SampleArrays out, uint32_t n) noexcept;

}  // namespace envmis
