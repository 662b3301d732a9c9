// Internal: steps of the estimator's side-by-side lanes (estimator.cpp) eight lanes at a
// time with AVX2 (estimator_simd.cpp): the BSDF's lobes (bsdf.h) and the frame's turns
// (frame.h) instantiated on eight lanes, and the lanes' sums, so that a lane's result is
// bit-identical to an estimate made alone (tests/study/techniques/estimator_test.cpp
// compares estimates made at once and one at a time, for Lambert, Phong and GGX).
// Lane counts are multiples of kSimdWidth: callers pad their arrays with valid inputs.
// The functions are declared on x86-64 only (ENVMIS_AVX2_BATCHES); call them where
// batch_paths().lanes is AVX2 (envmis/cpu.h).
#pragma once

#include <cstdint>

#include "detail/simd.h"
#include "envmis/sampling/envmap.h"
#include "envmis/study/shading/bsdf.h"
#include "envmis/study/shading/frame.h"

namespace envmis::detail {

// The fixed MIS weights of the lanes' techniques (estimator.cpp, fixed_weight): 1 for a
// single technique, the balance or the power heuristic.
enum class Weighting { one, balance, power };

}  // namespace envmis::detail

#ifdef ENVMIS_AVX2_BATCHES
namespace envmis::detail {

inline constexpr uint32_t kSimdWidth = 8;

// Bsdf::sample for a view direction wo above the surface (wo.z > 0; below it, every
// kind's sample is empty and the caller stays scalar), then Frame::to_world of the
// sampled direction, for n points u: the world direction, the pdf and the value (f cos,
// in the r, g, b arrays). Every kind: Lambert, Phong, GGX.
void sample_bsdf(const Frame& frame, const Bsdf& bsdf, Vec3 wo, PointArrays u, SampleArrays out, uint32_t n) noexcept;

// Bsdf::pdf and Bsdf::eval (view direction wo above the surface) at n world directions
// wi, through Frame::to_local.
struct BsdfValueArrays {
    float *pdf, *r, *g, *b;
};
void eval_bsdf(const Frame& frame, const Bsdf& bsdf, Vec3 wo, DirectionArrays wi, BsdfValueArrays out,
               uint32_t n) noexcept;

// One sample per lane of technique k (0: environment, 1: BSDF), added to the lanes'
// sums as the scalar add_lanes (estimator.cpp) adds it: value L v per channel, weight
// from q = n p of both techniques, divided by q_k; nothing where p_k is not > 0.
struct LaneSamples {
    const float *radiance_r, *radiance_g, *radiance_b;  // L
    const float *value_r, *value_g, *value_b;           // v: the BSDF's f cos
    const float *p_env, *p_bsdf;                        // solid-angle densities
};
struct LaneSums {
    float *r, *g, *b;
};
void add_samples(Weighting weighting, const float counts[2], int k, LaneSamples s, LaneSums sums, uint32_t n) noexcept;

}  // namespace envmis::detail
#endif
