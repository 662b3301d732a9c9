// The set-up of one variance study, for every front end (`envmis compare` and
// envmis.compare): the request in values, the limits both refuse beyond, the maps, points
// and bins it builds, and the exact figures of --exact. A front end parses its own
// arguments into a CompareRequest; everything from there on is this file's.
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "envmis/interrupt.h"
#include "envmis/sampling/binned.h"
#include "envmis/sampling/envmap.h"
#include "envmis/study/comparison/alpha.h"
#include "envmis/study/comparison/comparison.h"

namespace envmis {

// The limits of the study's arguments, the same in the command and in Python.
inline constexpr uint32_t kMaxStudySamples = 65536;  // per estimate, of each kind
inline constexpr uint32_t kMaxStudyPoints = 1000000;
inline constexpr uint32_t kMaxStudyThreads = 1024;
inline constexpr uint32_t kThreadsPerCore = 4;  // more workers than this per usable core only contend
inline constexpr uint32_t kDefaultStudyBins = 121;

// What a study is asked for; options.threads as worker_threads resolves the count asked.
struct CompareRequest {
    ComparisonOptions options;
    std::vector<ShadingPoint> points;
    std::optional<float> alpha;      // every BSDF's compensation strength; empty: choose_alpha per BSDF
    std::optional<float> bin_alpha;  // every bin's; empty: each bin chooses its own (BinnedOptions::auto_alpha)
    uint32_t bins = 0;               // K = g*g normal bins; 0: kDefaultStudyBins where a -bins technique runs
    float bin_cost = BinnedOptions{}.cost;
    uint32_t cell_columns = 0;  // of the bins' cell grid (BinnedOptions::cell_columns)
};

// Workers for `asked` threads: 0 is every usable core (usable_cores: CPU affinity, cgroup
// quota); more than kThreadsPerCore per usable core are reduced to that, and `note` (when given) says so in a sentence
// naming both counts; otherwise it is left empty.
uint32_t worker_threads(uint32_t asked, std::string* note = nullptr);

// g of K = g*g bins (0: kDefaultStudyBins), or 0 without a -bins technique. Throws
// std::invalid_argument "bins K: expected a square number ..." for K not g*g, g 1 to 64.
uint32_t bins_per_side(uint32_t bins, std::span<const Technique> techniques);

// The items of a comma-separated list ("lambert,phong:50"), empty items skipped.
std::vector<std::string> split_list(std::string_view text);

// Everything a study runs on.
struct CompareSetup {
    std::shared_ptr<const EnvMap> plain;  // the map without compensation
    std::vector<ShadingPoint> points;
    ComparisonOptions options;
    std::optional<AlphaChoice> choice;  // with alpha chosen
    float map_alpha = 0;                // the choice's map-wide alpha, or the fixed one
    std::vector<float> bsdf_alphas;     // in options.bsdfs order
    CompensatedMaps compensated;
    std::shared_ptr<const BinnedEnvMap> binned;  // with a -bins technique
    bool bins_auto = false;                      // the bins' alpha chosen per bin

    StudyInputs inputs() const { return {*plain, compensated, points, options, binned.get()}; }
    // The alpha of the map `bsdf` samples (map_alpha for a BSDF not in the study).
    float alpha_of(const Bsdf& bsdf) const;
};

// Builds the study's maps: `map` rebuilt without compensation where it has some (from
// its radiance and options), the alpha choice where asked, one compensated map per
// distinct alpha, and the bins. Throws std::invalid_argument for bad bins (bins_per_side)
// and what the builds throw; Interrupted once `stop` is set. Cost: the builds (O(texels)
// each), the alpha choice on a 128-wide copy, the bins' build with their alpha choices.
CompareSetup prepare_compare(std::shared_ptr<const EnvMap> map, CompareRequest request, StopFlag stop = nullptr);

// compare --exact's figures for one technique on one BSDF: its exact variance
// (quadrature, one subdivision) over mis-balance's, at each point (0 where either is 0),
// their geometric mean and the worst point.
struct ExactRatio {
    size_t bsdf = 0;  // in options.bsdfs order
    Technique technique;
    double ratio = 0;            // NaN where no point has both variances > 0
    std::vector<double> points;  // per point; 0 where either variance is 0
    double worst() const noexcept { return points.empty() ? 0 : *std::max_element(points.begin(), points.end()); }
};

// The exact ratios of every fixed-weight technique of the setup (adaptive and mixture
// techniques have none), BSDF by BSDF in technique order. control.progress is called
// after each exact computation; once control.stop is set it throws Interrupted. Cost:
// BSDFs x (techniques + 1) quadratures over every point.
std::vector<ExactRatio> exact_ratios(const CompareSetup& setup, const RunControl& control = {});

}  // namespace envmis
