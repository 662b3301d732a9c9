// Choosing the compensation strength alpha (compensation.h) per map, before any
// sampling.
//
// Criterion: the exact variance of one mis-balance-comp estimate over that of one
// mis-balance estimate (quadrature.h, exact_variance), the ratio taken per (BSDF, shading
// point) and then averaged geometrically over all of them -- the figure `compare`
// reports as var/mis, without its noise. The alpha with the lowest criterion among a
// fixed grid of candidates wins; alpha = 0 (the plain density, criterion exactly 1) is
// always a candidate, so the choice never predicts a loss.
//
// Why this criterion: compensation exists to lower the variance of MIS with BSDF
// sampling, and this measures exactly that, for the caller's BSDFs and shading points.
// It is noise-free (a quadrature, not a pilot run that a tiny sun can fool), and cheap:
// it runs on a downsampled copy of the map (128 texels wide by default), where one
// exact variance costs a few thousand BSDF evaluations. A pilot render would need
// thousands of estimates per point to rank candidates a few percent apart.
//
// Cost: (candidates + 1) x BSDFs x points exact variances on the downsampled map, each
// O(w h) BSDF and pdf evaluations, parallel over rows, plus one downsampling pass over
// the full map (O(W H)). Defaults (9 candidates, 3 BSDFs, 16 points, 128 x 64): 480
// quadratures of 8192 texels, whatever the map's size, plus the downsampling (timings:
// docs/performance-log.md, 'choose_alpha').
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "envmis/image/image.h"
#include "envmis/sampling/envmap.h"
#include "envmis/study/comparison/comparison.h"
#include "envmis/study/shading/bsdf.h"
#include "envmis/study/techniques/estimator.h"

namespace envmis {

// Halves the image in both directions until its width is <= max_width (or it is one
// texel wide or high). Each new texel is the solid-angle-weighted mean of the 2 x 2
// texels it covers (rows weighted by sin(theta) at their centres); a last odd row or
// column joins the texels before it. For even sizes the solid-angle mean luminance
// (compensation.h) is kept exactly, up to float rounding: the weights of every merged
// pair of rows sum to the new row's sin(theta) times one constant, 2 cos(pi / 2h).
// NaN, infinite and negative channel values count as 0, as EnvMap's build treats them.
// An equal-area map's texels all weigh the same.
// Cost: O(W H), one pass per halving.
RgbImage downsample(RgbImageView image, uint32_t max_width, Mapping mapping = Mapping::equirect);

// The exact variance (exact_variance, at `subdivisions`) of `technique` sampling `env`,
// at every (BSDF, point): element b * points.size() + p. Throws Interrupted once `stop` is set.
std::vector<double> exact_variances(const EnvMap& env, Technique technique, Allocation allocation,
                                    std::span<const Bsdf> bsdfs, std::span<const ShadingPoint> points, int subdivisions,
                                    StopFlag stop = nullptr);

// The geometric mean, over points, of variances[b, p] / baseline[b, p] for each BSDF b,
// both laid out as exact_variances() returns them for `bsdfs` BSDFs; pairs in which
// either variance is not positive (a point the map leaves dark) are left out, as
// compare() does. A BSDF without any pair gets 1.
std::vector<double> geometric_mean_ratios(std::span<const double> variances, std::span<const double> baseline,
                                          size_t bsdfs);

struct AlphaOptions {
    // Finite and >= 0; tried in ascending order, alpha = 0 added if missing.
    std::vector<float> candidates = {0, 0.25f, 0.5f, 0.75f, 1, 1.25f, 1.5f, 2, 3};
    std::vector<Bsdf> bsdfs = ComparisonOptions{}.bsdfs;
    std::vector<ShadingPoint> points = sphere_points(16);
    Allocation allocation;     // samples per MIS estimate, as the estimates will use
    uint32_t max_width = 128;  // of the downsampled copy the quadratures run on
};

struct AlphaCandidate {
    float alpha = 0;
    // Geometric mean over all (BSDF, point) pairs of exact variance of mis-balance-comp
    // over mis-balance: < 1 where compensation helps.
    double criterion = 1;
    std::vector<double> per_bsdf;  // the same over points only, in AlphaOptions::bsdfs order
};

// The choice, per BSDF and for the whole map. Each picks the candidate with the lowest
// criterion (the smallest alpha on a tie, within 1e-6 relative: float rounding). BSDFs disagree: a diffuse lobe gains
// most from strong compensation, a glossy one often from mild compensation, so a map-wide alpha can be well off the
// best for some BSDFs. Over the 14 bundled and shared maps with lambert, phong:50 and ggx:0.1 (42 cases; exact
// variances at full resolution against a sweep of alpha = 0, 0.25, ..., 3), the map-wide choice is over 5% worse than
// the case's best in 6 cases (up to 27%), each BSDF's own choice in none (at most 3.9%). `compare` therefore uses one
// compensated map per BSDF; a table file, which holds one density, takes the map-wide alpha.
struct AlphaChoice {
    std::vector<float> bsdf_alphas;          // lowest AlphaCandidate::per_bsdf, per BSDF
    float alpha = 0;                         // lowest AlphaCandidate::criterion
    std::vector<AlphaCandidate> candidates;  // ascending alpha
    uint32_t width = 0, height = 0;          // of the downsampled copy
    double seconds = 0;                      // wall time of the choice, downsampling included
};

// Chooses alpha for `radiance` as AlphaOptions says. `map` gives the luma coefficients
// and axes (its compensation settings are ignored). Throws std::invalid_argument for an
// empty image, no BSDF or point, or a negative or non-finite candidate.
AlphaChoice choose_alpha(RgbImageView radiance, const EnvMapOptions& map, const AlphaOptions& options = {});

}  // namespace envmis
