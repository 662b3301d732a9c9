// The exact variance of a multi-sample MIS estimator of two techniques, one sampling the
// environment (n_env samples) and one the BSDF (n_bsdf), as a sum over quadrature nodes:
// the one kernel that both choosers of the compensation's alpha rank candidates with,
// the map's (envmis::study's choose_alpha, through its exact_variance) and each bin's
// (build_bins, bins.h). Each chooser brings its own nodes and lobe.
//
// For technique t with weights w_t, the estimate sum_t (1/n_t) sum_i f w_t / p_t has the
// variance sum_t (1/n_t) (integral f^2 w_t^2 / p_t - (integral f w_t)^2). Under the
// balance heuristic, w_t = n_t p_t / Q with Q = n_env p_env + n_bsdf p_bsdf, the second
// moments sum to integral f^2 / Q: one division a node, where the chooser of a bin spends
// its time.
//
// Numbers: doubles throughout; the caller's weights are used as given (the study passes
// the float weights its estimator uses). Header-only, allocation-free.
#pragma once

namespace envmis {

// What one node contributes: the integrand f (radiance times BSDF times cosine), the
// node's solid angle and each technique's pdf (solid angle) and sample count there.
struct MisNode {
    double f, solid_angle, p_env, p_bsdf;
};

struct MisCounts {
    double env = 1, bsdf = 1;
};

struct MisMoments {
    double env = 0, bsdf = 0;  // integral f w_t, per technique
    double second = 0;         // sum_t (1/n_t) integral f^2 w_t^2 / p_t

    // A node under any weights (w_t the weight of technique t's sample there). A
    // technique with no samples, or no density at the node, adds nothing.
    void add(const MisNode& node, MisCounts n, double w_env, double w_bsdf) noexcept {
        const bool by_env = n.env > 0 && node.p_env > 0, by_bsdf = n.bsdf > 0 && node.p_bsdf > 0;
        const double fe = by_env ? node.f * w_env : 0, fb = by_bsdf ? node.f * w_bsdf : 0;
        env += fe * node.solid_angle;
        bsdf += fb * node.solid_angle;
        // One sum of both terms, then one add: the two do not wait on each other.
        second += ((by_env ? fe * fe / (n.env * node.p_env) : 0) + (by_bsdf ? fb * fb / (n.bsdf * node.p_bsdf) : 0)) *
                  node.solid_angle;
    }

    // A node under the balance heuristic, whose weights are in double. One division:
    // each term is f omega / Q times f, n_env p_env or n_bsdf p_bsdf.
    void add_balance(const MisNode& node, MisCounts n) noexcept {
        const double pe = n.env * node.p_env, pb = n.bsdf * node.p_bsdf, q = pe + pb;
        if (!(q > 0)) return;
        const double r = node.f * node.solid_angle / q;
        second += node.f * r;
        env += pe * r;
        bsdf += pb * r;
    }

    MisMoments& operator+=(const MisMoments& o) noexcept {
        env += o.env, bsdf += o.bsdf, second += o.second;
        return *this;
    }

    // The estimator's variance; a technique with no samples contributes nothing.
    double variance(MisCounts n) const noexcept {
        double v = second;
        if (n.env > 0) v -= env * env / n.env;
        if (n.bsdf > 0) v -= bsdf * bsdf / n.bsdf;
        return v;
    }
};

}  // namespace envmis
