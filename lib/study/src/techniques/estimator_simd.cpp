// The estimator's lanes in AVX2; see estimator_simd.h. A BSDF's values and samples
// are its lobe's own (bsdf.h), the frame's turns frame.h's, on eight lanes (detail/simd.h).
// What remains written here repeats the lanes' add_lanes, fixed_weight, balance_weight and
// power_weight (estimator.cpp, mis_weights.h) in the same IEEE operations and order; the
// tests that compare estimates made together and alone fail until both change together.
#include "estimator_simd.h"

#ifdef ENVMIS_AVX2_BATCHES
namespace envmis::detail {
namespace {

using namespace simd;

template <class Lobe>
ENVMIS_AVX2_FLAT void sample_with(const Lobe& lobe, const Frame& frame, PointArrays u, SampleArrays out,
                                  uint32_t n) noexcept {
    for (uint32_t l = 0; l < n; l += kSimdWidth) {
        const Vec3x8 wi = lobe.sample(Vec2x8{load(u.x + l), load(u.y + l)});
        const BsdfValues<F8> v = lobe.values(wi);
        const Vec3x8 world = frame.to_world(wi);
        store(out.x + l, world.x);
        store(out.y + l, world.y);
        store(out.z + l, world.z);
        store(out.pdf + l, v.pdf);
        store(out.r + l, v.r);
        store(out.g + l, v.g);
        store(out.b + l, v.b);
    }
}

template <class Lobe>
ENVMIS_AVX2_FLAT void eval_with(const Lobe& lobe, const Frame& frame, DirectionArrays wi, BsdfValueArrays out,
                                uint32_t n) noexcept {
    for (uint32_t l = 0; l < n; l += kSimdWidth) {
        const BsdfValues<F8> v = lobe.values(frame.to_local(Vec3x8{load(wi.x + l), load(wi.y + l), load(wi.z + l)}));
        store(out.pdf + l, v.pdf);
        store(out.r + l, v.r);
        store(out.g + l, v.g);
        store(out.b + l, v.b);
    }
}

}  // namespace

void sample_bsdf(const Frame& frame, const Bsdf& bsdf, Vec3 wo, PointArrays u, SampleArrays out, uint32_t n) noexcept {
    bsdf.with_lobe(wo, [&](const auto& lobe) { sample_with(lobe, frame, u, out, n); });
}

void eval_bsdf(const Frame& frame, const Bsdf& bsdf, Vec3 wo, DirectionArrays wi, BsdfValueArrays out,
               uint32_t n) noexcept {
    bsdf.with_lobe(wo, [&](const auto& lobe) { eval_with(lobe, frame, wi, out, n); });
}

ENVMIS_AVX2 void add_samples(Weighting weighting, const float counts[2], int k, LaneSamples s, LaneSums sums,
                             uint32_t n) noexcept {
    for (uint32_t l = 0; l < n; l += kSimdWidth) {
        const F8 q0 = counts[0] * load(s.p_env + l), q1 = counts[1] * load(s.p_bsdf + l);
        const F8 qk = k == 0 ? q0 : q1;
        const M8 positive = qk > 0.0f;
        F8 weight = 1.0f;
        if (weighting == Weighting::balance) {
            weight = select(positive, qk / (0.0f + q0 + q1), 0.0f);
        } else if (weighting == Weighting::power) {
            const F8 a = q0 / qk, b = q1 / qk;
            weight = select(positive, 1.0f / (0.0f + a * a + b * b), 0.0f);
        }
        const F8 scale = weight / qk;
        const M8 sampled = load(k == 0 ? s.p_env + l : s.p_bsdf + l) > 0.0f;
        const auto accumulate = [&](float* sum, const float* radiance, const float* value) ENVMIS_AVX2 {
            const F8 old = load(sum + l);
            store(sum + l, select(sampled, old + load(radiance + l) * load(value + l) * scale, old));
        };
        accumulate(sums.r, s.radiance_r, s.value_r);
        accumulate(sums.g, s.radiance_g, s.value_g);
        accumulate(sums.b, s.radiance_b, s.value_b);
    }
}

}  // namespace envmis::detail
#endif
