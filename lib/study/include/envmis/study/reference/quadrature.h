// Deterministic integrals over the sphere against an environment map: the references
// that estimators are checked against, independent of every sampler.
//
// Each texel (constant radiance, nearest lookup) is split into s x s sub-cells in image
// space and integrated by the midpoint rule with the exact solid-angle measure
// d(omega) = 2 pi^2 sin(theta) du dv. s doubles (1, 2, 4, ...) until two successive
// results agree to the requested relative tolerance; the last difference is returned as
// the error estimate. Black texels and directions below the surface are skipped.
//
// Cost: O(w h s^2) BSDF evaluations, parallel over rows; deterministic for any number of
// threads. Seconds on an 8k map: each call takes an optional StopFlag (interrupt.h) and
// throws Interrupted a row after it is set.
#pragma once

#include "envmis/interrupt.h"
#include "envmis/sampling/envmap.h"
#include "envmis/study/shading/bsdf.h"
#include "envmis/study/techniques/estimator.h"

namespace envmis {

struct QuadratureOptions {
    double tolerance = 1e-4;    // relative, between successive subdivisions
    int max_subdivisions = 32;  // s at most (s^2 sub-cells per texel)
};

struct QuadratureResult {
    Rgb value;             // the integral
    double luminance = 0;  // luminance of value, with the map's luma coefficients
    double error = 0;      // |I(s) - I(s/2)| in luminance: an estimate of the error
    int subdivisions = 0;  // s of the returned value
};

// Reflected radiance L_o = integral of L(wi) f(wo, wi) cos(theta_i) dwi.
QuadratureResult reflected_radiance(const EnvMap& map, const Bsdf& bsdf, const ShadingPoint& point,
                                    const QuadratureOptions& options = {}, StopFlag stop = nullptr);

// The exact variance of one estimate's luminance by `technique` with `allocation`
// (estimator.h), sampling `env` (plain or compensated, as the technique says) and
// taking radiance from it: for MIS, sum over its two techniques of
// (integral of f^2 w^2 / p - (integral of f w)^2) / n; for one-sample MIS,
// integral of f^2 / Q - (integral of f)^2 / total, Q = sum n p; at a fixed subdivision
// s. Throws std::invalid_argument for an adaptive technique (its weights are learnt)
// and for the mixture (it samples two maps).
double exact_variance(const EnvMap& env, Technique technique, Allocation allocation, const Bsdf& bsdf,
                      const ShadingPoint& point, int subdivisions, StopFlag stop = nullptr);
// The same for a -bins technique: the environment density is a bin around the point's
// lobe axis in the BSDF's lobe class, picked at random with the blend's weights
// (binned.h), so the variance is the weights' sum of the bins' variances; the radiance
// the binned map's plain one.
double exact_variance(const BinnedEnvMap& binned, Technique technique, Allocation allocation, const Bsdf& bsdf,
                      const ShadingPoint& point, int subdivisions, StopFlag stop = nullptr);

}  // namespace envmis
