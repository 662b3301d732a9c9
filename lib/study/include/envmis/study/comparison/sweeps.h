// The studies beyond one comparison: the compensation strength (an alpha sweep) and the
// sample allocation (an allocation sweep). Their printing, JSON and plots belong to the
// caller (apps/envmis/sweeps.h).
//
// Every study runs compare() (comparison.h) at the same points, spp and seed for each
// setting, so the settings are compared with common random numbers. The sweeps report
// variances, ratios and efficiencies, none of which depends on compare()'s quadrature
// reference (it feeds mean error and rel_mse only): they compute it at one subdivision,
// which would otherwise take most of their time, once per setting.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "envmis/study/comparison/comparison.h"

namespace envmis {

// --alpha-sweep A0:A1:STEP: A0, A0 + STEP, ... up to A1 (A1 itself if a step lands within
// STEP / 1000 of it). Throws std::runtime_error naming the flag for text that is not
// three numbers, STEP <= 0, A1 < A0, a negative A0, or more than 100 values.
std::vector<float> parse_alpha_sweep(const std::string& text);

// One value per BSDF (NaN where there is none).
using PerBsdf = std::vector<double>;

// The study at each alpha: the comparison of the techniques that depend on alpha, with
// mis-balance as the baseline, and optionally the exact variance ratio of
// mis-balance-comp over mis-balance (geometric mean over points; quadrature at the map's
// full resolution, one subdivision: noise-free).
struct AlphaSweep {
    std::vector<float> alphas;  // those done, ascending
    std::vector<Comparison> comparisons;
    std::vector<PerBsdf> exact;  // per alpha; empty without exact
    Allocation allocation;       // of every estimate
    bool interrupted = false;

    // What the best alpha is chosen by: the exact ratio if there is one, else the
    // measured var/mis of mis-balance-comp.
    double ratio(size_t alpha, size_t bsdf) const;
    // The alpha with the lowest ratio() for a BSDF, as an index into alphas.
    size_t best(size_t bsdf) const;
};

// The techniques an alpha sweep runs: mis-balance, mis-balance-comp and those of
// `requested` that sample a compensated density or bins (at the sweep's fixed alpha); by default (`requested` empty)
// also mis-power-comp and mis-optimal-comp.
std::vector<Technique> alpha_sweep_techniques(std::span<const Technique> requested);

// Runs inputs.options.techniques (see alpha_sweep_techniques) at every alpha, each with
// a map compensated anew (inputs.compensated is not used); stops cleanly (interrupted =
// true) at control.stop, keeping the alphas done. control.progress counts points over
// all alphas. Cost: one compare() per alpha, plus with `exact` a quadrature of the whole
// map per alpha, point and BSDF.
AlphaSweep run_alpha_sweep(const StudyInputs& inputs, std::span<const float> alphas, bool exact,
                           const RunControl& control = {});

// The study at each allocation n_env : n_bsdf = k : (total - k), k = 1 .. total - 1.
struct AllocationSweep {
    std::vector<Allocation> allocations;  // those done
    std::vector<Comparison> comparisons;
    bool interrupted = false;

    // The allocation with the highest efficiency for a BSDF and technique (indices into
    // the comparisons' lists), as an index into allocations.
    size_t best(size_t bsdf, size_t technique) const;
};

// The techniques an allocation sweep runs: those of `requested` that combine
// environment and BSDF samples (MIS and one-sample MIS); by default mis-balance and
// mis-balance-comp. Throws std::runtime_error if `requested` has none.
std::vector<Technique> allocation_sweep_techniques(std::span<const Technique> requested);

// Runs inputs.options.techniques at every allocation of `total` (>= 2) samples, each
// BSDF with its map of inputs.compensated; progress and stop as for the alpha sweep.
// Cost: total - 1 compare() runs.
AllocationSweep run_allocation_sweep(const StudyInputs& inputs, uint32_t total, const RunControl& control = {});

// One row of a sweep, as the JSON arrays and the CSV file hold it.
struct SweepRow {
    const char* sweep;  // "alpha" or "allocation"
    float alpha = 0;
    Allocation allocation;
    const Bsdf* bsdf = nullptr;
    const TechniqueStats* stats = nullptr;
    double exact_ratio = 0;  // NaN where not computed
    bool best = false;       // the best alpha (of mis-balance-comp) or allocation
};
// alpha: one row per alpha, BSDF and technique; allocation: per allocation, BSDF and
// technique. They point into the sweep, which must outlive them.
std::vector<SweepRow> sweep_rows(const AlphaSweep& sweep);
std::vector<SweepRow> sweep_rows(const AllocationSweep& sweep, const CompensatedMaps& compensated);

}  // namespace envmis
