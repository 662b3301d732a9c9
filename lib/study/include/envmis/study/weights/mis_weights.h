// Multiple importance sampling weights for m <= kMaxTechniques sampling techniques, and
// the linear system behind optimal MIS.
//
// Technique k draws n_k samples with solid-angle density p_k. The weights below take the
// effective densities q_k = n_k p_k (count times pdf), so that an estimate sums
// w_k(x) f(x) / q_k(x) over every sample x of every technique (Veach 1995). They are
// noexcept, allocation-free and usable on the device.
//
//   balance          w_k = q_k / sum q                 (Veach 1995; optimal for one-sample MIS)
//   power (beta 2)   w_k = q_k^2 / sum q^2
//   variance-aware   w_k = nu_k q_k / sum nu q          (Grittmann et al. 2019; nu from a pilot)
//   optimal          w_k = alpha_k p_k / f + (q_k / sum q) (1 - sum alpha p / f)
//                                                       (Kondapaneni et al. 2019)
//
// Balance, power and variance-aware weights lie in [0, 1] and sum to 1 wherever some
// q_k > 0. Optimal weights also sum to 1 but may be negative or exceed 1: they are
// those of a control variate, and `solve_optimal_alpha` finds the alpha that minimises
// the estimate's second moment.
#pragma once

#include <cstdint>

#include "envmis/math/math.h"

namespace envmis {

inline constexpr int kMaxTechniques = 3;

ENVMIS_HD inline float balance_weight(const float* q, int m, int k) noexcept {
    float sum = 0;
    for (int i = 0; i < m; ++i) sum += q[i];
    return q[k] > 0 ? q[k] / sum : 0.0f;
}

// As 1 / sum (q_i / q_k)^2: squaring the densities themselves underflows (a tail pdf
// of 1e-23) or overflows (1e20 at a pole) in float.
ENVMIS_HD inline float power_weight(const float* q, int m, int k) noexcept {
    if (!(q[k] > 0)) return 0;
    float sum = 0;
    for (int i = 0; i < m; ++i) sum += (q[i] / q[k]) * (q[i] / q[k]);
    return 1 / sum;
}

// nu_k > 0 scales technique k's trust: nu_k = 1 for all k is the balance heuristic.
ENVMIS_HD inline float variance_aware_weight(const float* q, const float* nu, int m, int k) noexcept {
    float scaled[kMaxTechniques];
    for (int i = 0; i < m; ++i) scaled[i] = nu[i] * q[i];
    return balance_weight(scaled, m, k);
}

// p: the techniques' densities (they are also the control variates), n: their counts,
// alpha: the control-variate coefficients, f: the integrand at the point (f != 0).
ENVMIS_HD inline float optimal_weight(const float* p, const float* n, const float* alpha, float f, int m,
                                      int k) noexcept {
    float q_sum = 0, alpha_p = 0;
    for (int i = 0; i < m; ++i) q_sum += n[i] * p[i], alpha_p += alpha[i] * p[i];
    return alpha[k] * p[k] / f + (q_sum > 0 ? n[k] * p[k] / q_sum : 0.0f) * (1 - alpha_p / f);
}

// The coefficients alpha of optimal MIS for three channels (RGB): the solution of
// A alpha = b, A symmetric positive semi-definite (m x m, row-major), b m x 3
// (row-major). A_kl = integral of c_k c_l / sum q, b_k = integral of f c_k / sum q, for
// control variates c_k (normally the techniques' densities). Solved by LDLT (Eigen).
// When A is singular or ill-conditioned (reciprocal condition number below 1e-9, or a
// non-finite entry), alpha is 0 -- the balance heuristic -- and `solved` is false.
// Allocation-free: Eigen works on the stack at these sizes.
struct OptimalAlpha {
    float alpha[kMaxTechniques][3] = {};
    bool solved = false;
    double rcond = 0;  // A's smallest over largest eigenvalue
};
OptimalAlpha solve_optimal_alpha(const double* a, const double* b, int m) noexcept;

}  // namespace envmis
