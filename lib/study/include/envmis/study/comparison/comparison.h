// The variance study: each technique (estimator.h) on each BSDF at a set of shading
// points, at equal sample count, against quadrature references (quadrature.h).
//
// Per point, `spp` estimates of each technique give its mean and the variance of one
// estimate; the tables aggregate over points as follows (for one point they are simply
// that point's figures):
//   mean, reference, variance   arithmetic means over points
//   std_error                   standard error of the aggregated mean
//   rel_mse                     mean over points and estimates of ((F - ref) / ref)^2
//   ns_per_estimate             wall time per estimate, all estimates of the technique
//                               (the estimator's own time, without the statistics kept)
//   efficiency                  1 / (variance * seconds per estimate)
//   variance_ratio_vs_mis       geometric mean over points of variance / variance of
//                               mis-balance (each point counts equally, bright or dim)
//   variance_ratio_log_std_error  standard error of log(variance_ratio_vs_mis): the
//                               noise of each point's variance estimate, measured as
//                               the spread of the variances of 8 interleaved batches
//
// Determinism: every (point, BSDF, technique) draws from its own PCG32 stream derived
// from the seed, so the estimates do not depend on the number of threads.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "envmis/sampling/binned.h"
#include "envmis/sampling/envmap.h"
#include "envmis/study/reference/quadrature.h"
#include "envmis/study/shading/bsdf.h"
#include "envmis/study/techniques/estimator.h"

namespace envmis {

struct ComparisonOptions {
    std::vector<Bsdf> bsdfs = {Bsdf::lambert(), Bsdf::phong(50), Bsdf::ggx(0.1f)};
    std::vector<Technique> techniques = default_techniques();
    Allocation allocation;
    uint32_t spp = 1024;  // estimates per point, BSDF and technique
    uint64_t seed = 1;
    uint32_t threads = 0;  // 0: all cores
    QuadratureOptions quadrature{1e-3, 32};

    static std::vector<Technique> default_techniques();
};

// A technique's figures on one BSDF over the shading points. Each point is its own case
// (a bright normal's variance would otherwise swamp the others), so the headline figures
// are per-point ratios to mis-balance, summarised by their geometric mean; 0 where they
// are undefined (no mis-balance in the run, a variance of 0).
struct TechniqueStats {
    Technique technique;
    // mean and reference: the estimates' mean and the quadrature reference (luminance of
    // the reflected radiance, the map's units), averaged over points; std_error the mean's
    // standard error; variance the variance of one estimate, averaged over points;
    // rel_mse the mean over estimates of ((estimate - reference) / reference)^2, the
    // relative mean squared error of one estimate (its bias included).
    double mean = 0, reference = 0, variance = 0, std_error = 0, rel_mse = 0;
    // ns_per_estimate: time per estimate, timed apart from the run on one thread, the
    // techniques in turn at up to 8 of the points spread evenly, 5 rounds of up to 256
    // estimates, per point the median of its rounds, then the mean over the points (0 in a
    // run stopped early); efficiency: 1 / (variance x that time in seconds).
    double ns_per_estimate = 0, efficiency = 0;
    // Per point: variance / mis-balance's, geometric mean and worst (largest) over points
    // (infinite where mis-balance's is 0 and this technique's is not);
    // efficiency_ratio_vs_mis: at equal time, mis-balance's time per estimate /
    // (variance_ratio_vs_mis x this technique's): > 1 is better.
    double variance_ratio_vs_mis = 0, variance_ratio_worst = 0, efficiency_ratio_vs_mis = 0;
    uint64_t estimates = 0;
    double variance_ratio_log_std_error = 0;
    // Optimal MIS: points whose linear system stayed singular, so that their estimates
    // kept the balance heuristic's weights.
    uint32_t ill_conditioned_points = 0;
    // Per point, in order: the variance of one estimate and its relative standard error.
    std::vector<double> point_variances, point_variance_rel_se;
};

struct BsdfComparison {
    Bsdf bsdf;
    std::vector<TechniqueStats> techniques;  // in ComparisonOptions::techniques order
    // The references' largest error estimate over the points, relative to their value
    // (QuadratureResult::error / luminance): above ComparisonOptions::quadrature's
    // tolerance where a reference stopped at its most subdivisions unconverged (a lobe
    // far sharper than a texel), which rel_mse and the reference column then carry.
    double reference_error = 0;

    const TechniqueStats* find(std::string_view technique) const;
};

struct Comparison {
    std::vector<BsdfComparison> bsdfs;
    size_t points_done = 0, points_total = 0;  // fewer done if stopped early
};

// K normals spread evenly over the sphere (a spherical Fibonacci lattice), each viewed
// head-on (wo = normal), or `view_degrees` (0 to 89.9) away from it, towards an azimuth
// about the normal that turns by the golden angle from point to point: renderers see
// surfaces at every angle, and a glossy lobe's axis, the mirror direction, moves with it.
std::vector<ShadingPoint> sphere_points(uint32_t k, double view_degrees = 0);

// A map compensated with each BSDF's strength: one map per distinct alpha, and the one
// each BSDF (in ComparisonOptions::bsdfs order) samples. Building one costs a new
// density over the map's radiance (tens of ms for a 1k map).
struct CompensatedMaps {
    std::vector<float> alphas;  // distinct
    std::vector<EnvMap> maps;   // maps[i] is compensated with alphas[i]
    std::vector<size_t> of_bsdf;

    float alpha_of(size_t bsdf) const { return alphas[of_bsdf[bsdf]]; }
};

// `plain` compensated with strength alpha (a new build from its radiance; throws
// Interrupted once `stop` is set, as EnvMap's build does).
EnvMap compensated_map(const EnvMap& plain, float alpha, StopFlag stop = nullptr);
// One map per distinct value of bsdf_alphas, each BSDF's alpha.
CompensatedMaps compensated_maps(const EnvMap& plain, std::span<const float> bsdf_alphas, StopFlag stop = nullptr);

// What a study runs on: the same map without compensation (`plain`, sampled by the
// techniques that do not compensate, and the quadrature references' radiance) and with
// it (`compensated`, each BSDF's own), the shading points and the options; `binned`, the
// normal-aware bins over `plain` that the -bins techniques sample (built from `plain`
// with BinnedOptions{} where they are asked for and it is null). The maps and points are
// borrowed: they must outlive the call.
struct StudyInputs {
    const EnvMap& plain;
    const CompensatedMaps& compensated;
    std::span<const ShadingPoint> points;
    ComparisonOptions options;
    const BinnedEnvMap* binned = nullptr;
};

// True if one of `techniques` samples a binned map.
bool uses_bins(std::span<const Technique> techniques);

// The estimator of `technique` in a study: over `binned` for a -bins technique (which
// then must not be null), else over `plain` and `compensated`. Throws as
// DirectLightingEstimator does, and std::invalid_argument for bins without a map.
DirectLightingEstimator study_estimator(const EnvMap& plain, const EnvMap& compensated, const BinnedEnvMap* binned,
                                        const Technique& technique, Allocation allocation);

// The exact variance (quadrature.h, `subdivisions`) of one estimate by `technique` at
// every point for BSDF number `bsdf` of inputs.options, over the map it samples (the
// BSDF's compensated map, the plain map or inputs.binned, which a -bins technique
// needs). Throws std::invalid_argument as exact_variance does, and Interrupted once `stop` is set.
std::vector<double> exact_point_variances(const StudyInputs& inputs, const Technique& technique, size_t bsdf,
                                          int subdivisions, StopFlag stop = nullptr);

// How a long run is watched and stopped: `stop` is checked between points and every
// 4096 estimates within one (the run returns the points completed; a point cut short
// is dropped); `progress(done, total)` is called as each run starts and after each
// point, in units the caller does not need to know (points times runs).
struct RunControl {
    const std::atomic<bool>* stop = nullptr;
    std::function<void(size_t done, size_t total)> progress = {};

    bool stopped() const { return stop && stop->load(); }
};

// Runs the study: every technique on every BSDF at every point, each BSDF sampling its
// own compensated map (one run per map, over the BSDFs that use it, merged in BSDF
// order). Throws std::invalid_argument for an invalid technique (env-comp), an empty
// list or spp of 0. Stopped early, it holds the BSDFs whose run started, and
// points_done is the fewest points any BSDF covers (0 for those whose run did not
// start). Cost: points x BSDFs x techniques x spp estimates (tens of ns each) plus a
// quadrature reference per point and BSDF.
Comparison compare(const StudyInputs& inputs, const RunControl& control = {});

// Runs `spp` estimates of `technique` at one point, learning as adaptive techniques do,
// and returns their mean (RGB): one pixel of a rendered comparison.
Rgb average_estimate(const DirectLightingEstimator& estimator, const ShadingPoint& point, const Bsdf& bsdf,
                     uint32_t spp, uint64_t seed, uint64_t stream);

}  // namespace envmis
