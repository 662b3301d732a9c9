// The studies of `envmis compare` beyond one comparison: the compensation strength
// (--alpha auto, --alpha-sweep) and the sample allocation (--allocation-sweep), with
// their tables, JSON and CSV rows and plots.
//
// Every study runs compare() (comparison.h) at the same points, spp and seed for each
// setting, so the settings are compared with common random numbers. The sweeps report
// variances, ratios and efficiencies, none of which depends on compare()'s quadrature
// reference (it feeds mean error and rel_mse only): they compute it at one subdivision,
// which would otherwise take most of their time, once per setting.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <ostream>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "envmis/pictures/plot.h"
#include "envmis/study/comparison/alpha.h"
#include "envmis/study/comparison/comparison.h"

namespace envmis::cli {

// `plain` compensated with strength alpha (a new build from its radiance).
EnvMap compensated_map(const EnvMap& plain, float alpha);

// The compensated maps of a study: one per distinct alpha, and the one each BSDF
// (in ComparisonOptions::bsdfs order) samples.
struct CompensatedMaps {
    std::vector<float> alphas;  // distinct
    std::vector<EnvMap> maps;   // maps[i] is compensated with alphas[i]
    std::vector<size_t> of_bsdf;

    float alpha_of(size_t bsdf) const { return alphas[of_bsdf[bsdf]]; }
};
// One map per distinct value of bsdf_alphas, each BSDF's alpha.
CompensatedMaps compensated_maps(const EnvMap& plain, std::span<const float> bsdf_alphas);

// compare() with each BSDF's own compensated map: one run per map, over the BSDFs that
// use it, merged in BSDF order (a single map is a single run). Stopped early, it holds
// the BSDFs whose run started, and points_done is the fewest points any BSDF covers (0
// for those whose run did not start).
Comparison compare_each(const EnvMap& plain, const CompensatedMaps& compensated, std::span<const ShadingPoint> points,
                        const ComparisonOptions& options, const std::atomic<bool>* stop,
                        const std::function<void(size_t, size_t)>& progress = {});

// The table of --alpha auto's candidates, per BSDF and over all, the choices marked.
void print_alpha_choice(std::ostream& out, const AlphaChoice& choice, std::span<const Bsdf> bsdfs);
nlohmann::json alpha_choice_json(const AlphaChoice& choice, std::span<const Bsdf> bsdfs);

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
// `requested` that sample a compensated density; by default (`requested` empty) also
// mis-power-comp and mis-optimal-comp.
std::vector<Technique> alpha_sweep_techniques(std::span<const Technique> requested);

// Runs options.techniques (see alpha_sweep_techniques) at every alpha, with Progress
// on stderr; stops cleanly (interrupted = true) at `stop`, keeping the alphas done.
AlphaSweep run_alpha_sweep(const EnvMap& plain, std::span<const float> alphas, std::span<const ShadingPoint> points,
                           const ComparisonOptions& options, bool exact, const std::atomic<bool>* stop);

// The table, then per BSDF the best alpha and, with `auto_alphas` (per BSDF, each one
// of the sweep's alphas), where --alpha auto's choice stands: its ratio over the
// best's and over alpha = 0's (when 0 was swept).
void print_alpha_sweep(std::ostream& out, const AlphaSweep& sweep, const std::vector<float>* auto_alphas);

// Per BSDF, the summary print_alpha_sweep() prints, as JSON objects.
nlohmann::json alpha_sweep_summary_json(const AlphaSweep& sweep, const std::vector<float>* auto_alphas);

// mis-balance-comp's ratio() against alpha, one series per BSDF, log y.
pictures::LinePlot alpha_sweep_plot(const AlphaSweep& sweep, const std::string& map_name);

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

// Runs options.techniques at every allocation of `total` (>= 2) samples, compensated
// as `compensated` says; Progress and `stop` as for the alpha sweep.
AllocationSweep run_allocation_sweep(const EnvMap& plain, const CompensatedMaps& compensated, uint32_t total,
                                     std::span<const ShadingPoint> points, const ComparisonOptions& options,
                                     const std::atomic<bool>* stop);

// The table, then the best allocation per BSDF and technique.
void print_allocation_sweep(std::ostream& out, const AllocationSweep& sweep);

// Efficiency against n_env, one series per BSDF and technique, log y.
pictures::LinePlot allocation_plot(const AllocationSweep& sweep, const std::string& map_name);

// Every technique's var/mis per BSDF (groups: BSDFs, bars: techniques), log y, a
// reference line at 1.
pictures::BarChart variance_chart(const Comparison& comparison, const std::string& map_name);

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

nlohmann::json sweep_row_json(const SweepRow& row);
// The CSV header (no newline) and one row: `prefix` holds the leading map,spp,seed,points
// fields with their trailing comma.
extern const char* const kSweepCsvHeader;
void write_sweep_csv_row(std::ostream& out, const std::string& prefix, const SweepRow& row);

}  // namespace envmis::cli
