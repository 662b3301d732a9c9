// The batch calls of envmis._maps over NumPy's interleaved arrays: points (N, 2),
// directions and radiance (N, 3), where the core's batch calls (envmap.h sample_many,
// lookup_many; binned.h) take one array per coordinate. Each call goes through the
// arrays in chunks of kChunk, deinterleaving a chunk's inputs into arrays on the stack,
// running the core's batch call on it and interleaving its outputs: the chunk stays in
// the L1/L2 cache, and nothing is allocated. Bit-identical to the core's calls (and to
// their single forms). Host only, noexcept; the caller releases the GIL around them.
#pragma once

#include <cstddef>
#include <cstdint>

#include "envmis/sampling/binned.h"
#include "envmis/sampling/envmap.h"

namespace envmis::python {

inline constexpr uint32_t kChunk = 1024;

// Outputs of sample: direction and radiance n x 3, pdf n, uv n x 2 (row-major).
struct InterleavedSamples {
    float *direction, *pdf, *radiance, *uv;
};
// Outputs of a lookup: either may be null (not written).
struct InterleavedLookups {
    float *pdf, *radiance;
};

// u: n x 2 points in [0,1)^2.
void sample(const EnvMapView& env, const float* u, InterleavedSamples out, size_t n) noexcept;
// normals: n x 3 (world frame), one per point, or lobe axes (lobe_axis) with their view
// cosines `view_cos` (n); choices: n picks in [0,1) among the bins around each normal
// (BinnedEnvMapView::bin).
void sample(const BinnedEnvMapView& env, uint32_t lobe, const float* normals, const float* view_cos,
            const float* choices, const float* u, InterleavedSamples out, size_t n) noexcept;
// directions: n x 3 unit vectors (world frame). Without out.pdf from a map without a
// distribution (BinnedEnvMap::radiance_map), the radiance alone.
void lookup(const EnvMapView& env, const float* directions, InterleavedLookups out, size_t n) noexcept;
void lookup(const BinnedEnvMapView& env, uint32_t lobe, const float* normals, const float* view_cos,
            const float* choices, const float* directions, InterleavedLookups out, size_t n) noexcept;

// The median of `repeats` wall times (seconds) of the core's sample_many on n points
// given as one array per coordinate (u's columns), writing every output sample writes
// (the image point too) into arrays of n: the reference that sample()'s cost is compared
// with (scripts/python_bench.py). Allocates its arrays before timing.
double time_sample_many(const EnvMapView& env, const float* u, size_t n, int repeats, bool fresh_outputs);

}  // namespace envmis::python
