#include "envmis/sampling/rotated.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace envmis {

Rotation Rotation::about(Vec3 axis, float radians) {
    const float l = length(axis);
    if (!(l > 0) || !std::isfinite(l) || !std::isfinite(radians))
        throw std::invalid_argument("rotation: the axis must be a finite, non-zero vector and the angle finite");
    const Vec3 a = axis * (1 / l);
    const double c = std::cos(double{radians}), s = std::sin(double{radians}), t = 1 - c;
    const double x = a.x, y = a.y, z = a.z;
    // Rodrigues' formula, in double so that the float matrix is orthonormal to rounding.
    const double rows[3][3] = {{t * x * x + c, t * x * y - s * z, t * x * z + s * y},
                               {t * x * y + s * z, t * y * y + c, t * y * z - s * x},
                               {t * x * z - s * y, t * y * z + s * x, t * z * z + c}};
    Rotation r;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) r.m[i][j] = static_cast<float>(rows[i][j]);
    return r;
}

Rotation Rotation::from_rows(const float (&rows)[3][3]) {
    Vec3 v[3];
    for (int i = 0; i < 3; ++i) v[i] = {rows[i][0], rows[i][1], rows[i][2]};
    constexpr float kTolerance = 1e-4f;
    for (int i = 0; i < 3; ++i) {
        if (!(std::abs(dot(v[i], v[i]) - 1) <= kTolerance))
            throw std::invalid_argument("rotation: row " + std::to_string(i) + " is not a unit vector (a scale?)");
        for (int j = i + 1; j < 3; ++j)
            if (!(std::abs(dot(v[i], v[j])) <= kTolerance))
                throw std::invalid_argument("rotation: rows " + std::to_string(i) + " and " + std::to_string(j) +
                                            " are not orthogonal");
    }
    if (dot(cross(v[0], v[1]), v[2]) < 0)
        throw std::invalid_argument(
            "rotation: the matrix is a reflection (determinant -1); mirror the map with "
            "the table's axes (precompute --axes) instead");
    const Vec3 x = normalize(v[0]), y = normalize(v[1] - x * dot(v[1], x)), z = cross(x, y);
    return {{{x.x, x.y, x.z}, {y.x, y.y, y.z}, {z.x, z.y, z.z}}};
}

Rotation Rotation::about_up(const Axes& axes, float radians) {
    return about(envmis::to_world(axes, Vec3{0, 0, 1}), radians);
}

namespace {

constexpr uint32_t kBlock = 256;

struct Block {
    float x[kBlock], y[kBlock], z[kBlock];
    DirectionArrays arrays() const noexcept { return {x, y, z}; }
    // As lobe axes, with the view cosines of [first, ...) of `axes` (a rotation keeps them).
    LobeAxisArrays axes(LobeAxisArrays axes, uint32_t first) const noexcept { return {x, y, z, axes.view_cos + first}; }
};

// Directions [first, first + count) of `in` into the map's frame.
void to_local(const Rotation& r, DirectionArrays in, uint32_t first, uint32_t count, Block& out) noexcept {
    for (uint32_t i = 0; i < count; ++i) {
        const Vec3 d = r.to_local({in.x[first + i], in.y[first + i], in.z[first + i]});
        out.x[i] = d.x, out.y[i] = d.y, out.z[i] = d.z;
    }
}

// Sampled directions [0, n) of `out`, in place, into the renderer's frame.
void to_world(const Rotation& r, SampleArrays out, uint32_t n) noexcept {
    for (uint32_t i = 0; i < n; ++i) {
        const Vec3 d = r.to_world({out.x[i], out.y[i], out.z[i]});
        out.x[i] = d.x, out.y[i] = d.y, out.z[i] = d.z;
    }
}

}  // namespace

void lookup_many(const Rotated<EnvMapView>& env, DirectionArrays in, LookupArrays out, uint32_t n) noexcept {
    Block local;
    for (uint32_t first = 0; first < n; first += kBlock) {
        const uint32_t count = std::min(kBlock, n - first);
        to_local(env.rotation, in, first, count, local);
        lookup_many(env.view, local.arrays(), from_lane(out, first), count);
    }
}

void sample_many(const Rotated<EnvMapView>& env, PointArrays in, SampleArrays out, uint32_t n) noexcept {
    sample_many(env.view, in, out, n);
    to_world(env.rotation, out, n);
}

void lookup_many(const RotatedBinned& env, uint32_t lobe, LobeAxisArrays axes, const float* choices, DirectionArrays in,
                 LookupArrays out, uint32_t n) noexcept {
    Block local_axes, local;
    for (uint32_t first = 0; first < n; first += kBlock) {
        const uint32_t count = std::min(kBlock, n - first);
        to_local(env.rotation, {axes.x, axes.y, axes.z}, first, count, local_axes);
        to_local(env.rotation, in, first, count, local);
        lookup_many(*env.map, lobe, local_axes.axes(axes, first), choices + first, local.arrays(),
                    from_lane(out, first), count);
    }
}

void sample_many(const RotatedBinned& env, uint32_t lobe, LobeAxisArrays axes, const float* choices, PointArrays in,
                 SampleArrays out, uint32_t n) noexcept {
    Block local_axes;
    for (uint32_t first = 0; first < n; first += kBlock) {
        const uint32_t count = std::min(kBlock, n - first);
        to_local(env.rotation, {axes.x, axes.y, axes.z}, first, count, local_axes);
        sample_many(*env.map, lobe, local_axes.axes(axes, first), choices + first, from_lane(in, first),
                    from_lane(out, first), count);
    }
    to_world(env.rotation, out, n);
}

}  // namespace envmis
