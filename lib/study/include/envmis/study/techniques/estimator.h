// Estimators of unoccluded direct lighting from an environment map at a shading point:
//
//   L_o(wo) = integral over the sphere of L(wi) f(wo, wi) cos(theta_i) dwi
//
// by environment sampling, BSDF sampling, or multiple importance sampling of both
// (Veach 1995) with the balance, power, variance-aware (Grittmann et al. 2019) or
// optimal (Kondapaneni et al. 2019) weights of mis_weights.h, over the plain (luminance)
// or the MIS-compensated environment density (Karlik et al. 2019); and one-sample MIS,
// which picks one technique at random per sample (balance heuristic).
//
// Equal sample count: every technique spends Allocation::total() samples per estimate
// (1 environment + 1 BSDF sample for MIS by default, 2 samples of its one kind for a
// single technique, 2 randomly chosen ones for one-sample MIS), so variances compare
// directly.
//
// Adaptive techniques learn at each shading point from the estimates made there before:
// optimal MIS the moments of its linear system, variance-aware MIS each technique's
// variance. The learnt values change at 8, 16, 32, ... estimates (progressively, as in
// both papers); until the 8th estimate both are the balance heuristic. An estimate uses
// only what earlier, independent estimates learnt, so every estimate is unbiased.
//
// A compensated density is zero where the radiance is not (envmap.h): sampling it
// alone is biased, so an environment-only technique over an incomplete map is refused
// at construction. Under MIS the BSDF technique covers what it leaves out.
//
// The -bins techniques sample a normal-aware density (sampling/binned.h): per estimate,
// its first random number picks one of the bins around the shading point's lobe axis
// (blending, binned.h), in the BSDF's lobe class; that bin's density both draws the
// environment samples and weighs the BSDF samples, so the MIS weights match what was
// drawn.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "envmis/math/random.h"
#include "envmis/sampling/binned.h"
#include "envmis/sampling/envmap.h"
#include "envmis/study/shading/bsdf.h"
#include "envmis/study/weights/mis_weights.h"

namespace envmis {

enum class Strategy : uint32_t { env, bsdf, mis, one_sample };
enum class Heuristic : uint32_t { balance, power, optimal, variance_aware };

struct Technique {
    Strategy strategy = Strategy::mis;
    Heuristic heuristic = Heuristic::balance;
    bool compensated = false;  // the environment technique samples the compensated density
    // The environment technique samples the equal mixture of the plain and the
    // compensated density (-all); optimal MIS then takes all three densities (plain,
    // compensated, BSDF) as control variates: a 3 x 3 system.
    bool mixture = false;
    // The environment technique samples the bin of a BinnedEnvMap that the point's
    // normal and the BSDF's lobe class pick (MIS only).
    bool bins = false;

    // Names: env, env-comp, bsdf, mis-balance, mis-power, mis-optimal, mis-var, each
    // MIS name also with -comp, mis-balance-all and mis-optimal-all (the mixture),
    // mis-balance-bins, mis-power-bins and mis-optimal-bins, one-sample and
    // one-sample-comp. Throws std::invalid_argument for other text.
    static Technique parse(std::string_view name);
    static std::vector<Technique> all();
    std::string name() const;
    // Learns at each shading point (PointState).
    bool adaptive() const noexcept {
        return strategy == Strategy::mis && (heuristic == Heuristic::optimal || heuristic == Heuristic::variance_aware);
    }
    friend bool operator==(const Technique&, const Technique&) = default;
};

// Samples per estimate. A single technique spends total() samples of its own kind.
struct Allocation {
    uint32_t env = 1, bsdf = 1;
    uint32_t total() const noexcept { return env + bsdf; }
};

// World-space unit vectors: the surface normal, and the direction towards the viewer.
struct ShadingPoint {
    Vec3 normal{0, 0, 1};
    Vec3 wo{0, 0, 1};
};

// MIS weight of a technique with density-times-count a against another with b.
ENVMIS_HD inline float mis_weight(Heuristic h, float a, float b) noexcept {
    const float q[2] = {a, b};
    return h == Heuristic::power ? power_weight(q, 2, 0) : balance_weight(q, 2, 0);
}

// What an adaptive technique has learnt at one shading point. Start a fresh one for
// every point; the techniques that do not learn leave it untouched.
struct PointState {
    uint32_t estimates = 0;    // made at this point so far
    uint32_t next_update = 8;  // the estimate count at which the learnt values change
    // Optimal MIS: sums over samples of c_k c_l / Q^2 and f c_k / Q^2 (Q = sum n p),
    // unbiased estimates of the system's integrals up to a common factor.
    double a[kMaxTechniques * kMaxTechniques] = {};
    double b[kMaxTechniques * 3] = {};
    OptimalAlpha optimal;          // alpha = 0 (balance) until the first update
    uint32_t ill_conditioned = 0;  // updates that found the system singular: balance kept
    // Variance-aware MIS: moments of each technique's own estimate luminance(f) / p.
    double sum[2] = {}, sum2[2] = {};
    uint64_t count[2] = {};
    float nu[2] = {1, 1};
};

class DirectLightingEstimator {
public:
    // `plain` and `compensated` are the same map without and with compensation; the
    // technique samples the one it names (both for the mixture). Throws
    // std::invalid_argument if the technique samples only the environment over an
    // incomplete (compensated) density, if the allocation spends no sample or more than
    // 2^32 - 1, or if MIS is given a zero count for one of its techniques.
    DirectLightingEstimator(const EnvMap& plain, const EnvMap& compensated, Technique technique,
                            Allocation allocation = {});
    // The same for a technique that needs one map (not the mixture): `env` is the map
    // it samples, plain or compensated.
    DirectLightingEstimator(const EnvMap& env, Technique technique, Allocation allocation = {});
    // A -bins technique over `binned`, which must outlive the estimator. Throws
    // std::invalid_argument for a technique without bins, and as above.
    DirectLightingEstimator(const BinnedEnvMap& binned, Technique technique, Allocation allocation = {});

    // One estimate of L_o (RGB radiance), from allocation.total() samples drawn with
    // rng; adaptive techniques read and update `state`, the point's. noexcept and
    // allocation-free.
    Rgb estimate(const ShadingPoint& point, const Bsdf& bsdf, Pcg32& rng, PointState& state) const noexcept;
    // The same with a throwaway state: adaptive techniques act as the balance heuristic.
    Rgb estimate(const ShadingPoint& point, const Bsdf& bsdf, Pcg32& rng) const noexcept {
        PointState state;
        return estimate(point, bsdf, rng, state);
    }

    // out.size() estimates at one point, the same as that many calls of the above in
    // a row (bit-identical, the same random numbers). The techniques with fixed weights
    // (env, bsdf, mis-balance, mis-power; plain, compensated or binned) with at most 8 samples
    // per estimate run up to 64 estimates side by side: the shading frame is built
    // once, and each step runs over all of them before the next, so their cache misses
    // overlap instead of following one another; on x86-64 CPUs with AVX2, eight of them
    // at a time in SIMD lanes. This is the fast path, well ahead of single calls in
    // throughput (measured: docs/performance-log.md,
    // 'DirectLightingEstimator::estimate'). noexcept and allocation-free.
    void estimate(const ShadingPoint& point, const Bsdf& bsdf, Pcg32& rng, PointState& state,
                  std::span<Rgb> out) const noexcept;

    Technique technique() const noexcept { return technique_; }
    Allocation allocation() const noexcept { return allocation_; }

private:
    // The estimate with the environment density `env` (the map's, or a point's bin).
    template <class Env>
    Rgb estimate_with(const Env& env, const ShadingPoint& point, const Bsdf& bsdf, Pcg32& rng,
                      PointState& state) const noexcept;
    // The bin `choice` (uniform in [0,1)) picks for the point and the BSDF's lobe class.
    BinView bin_of(const ShadingPoint& point, const Bsdf& bsdf, float choice) const noexcept;

    EnvMapView env_;    // the sampled density (a binned map's: its radiance alone)
    EnvMapView other_;  // the plain density, which the mixture also samples
    LumaCoefficients luma_;
    Technique technique_;
    Allocation allocation_;
    const BinnedEnvMap* binned_ = nullptr;  // with technique_.bins
    BinnedEnvMapView binned_view_;
};

}  // namespace envmis
