#include "envmis/study/comparison/sweeps.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <stdexcept>

#include "envmis/build/bins.h"
#include "envmis/study/comparison/alpha.h"

namespace envmis {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

const Technique kBalance = Technique::parse("mis-balance");
const Technique kBalanceComp = Technique::parse("mis-balance-comp");

void add_unique(std::vector<Technique>& list, const Technique& t) {
    if (std::find(list.begin(), list.end(), t) == list.end()) list.push_back(t);
}

// The sweeps' options: a one-subdivision reference (see sweeps.h).
ComparisonOptions sweep_options(const ComparisonOptions& options) {
    ComparisonOptions o = options;
    o.quadrature.max_subdivisions = 1;
    return o;
}

// Progress over several compare() runs of `points` points each, `runs` in all.
RunControl run_control(const RunControl& control, size_t run, size_t runs, size_t points) {
    if (!control.progress) return {control.stop, {}};
    return {control.stop, [&control, run, runs, points](size_t done, size_t) {
                control.progress(run * points + done, runs * points);
            }};
}

}  // namespace

std::vector<float> parse_alpha_sweep(const std::string& text) {
    auto fail = [&](const std::string& why) { return std::runtime_error("--alpha-sweep '" + text + "': " + why); };
    double a0 = 0, a1 = 0, step = 0;
    char tail = 0;
    if (std::sscanf(text.c_str(), "%lf:%lf:%lf%c", &a0, &a1, &step, &tail) != 3 || !std::isfinite(a0) ||
        !std::isfinite(a1) || !std::isfinite(step))
        throw fail("expected A0:A1:STEP, three numbers, e.g. 0:2:0.25");
    if (a0 < 0) throw fail("alpha must be >= 0");
    if (!(step > 0)) throw fail("STEP must be > 0");
    if (a1 < a0) throw fail("A1 must be >= A0");
    const double count = std::floor((a1 - a0) / step + 1e-3) + 1;
    if (count > 100) throw fail("more than 100 values");
    std::vector<float> alphas;
    for (int i = 0; i < static_cast<int>(count); ++i) alphas.push_back(static_cast<float>(a0 + i * step));
    return alphas;
}

double AlphaSweep::ratio(size_t alpha, size_t bsdf) const {
    if (!exact.empty()) return exact[alpha][bsdf];
    const TechniqueStats* s = comparisons[alpha].bsdfs[bsdf].find("mis-balance-comp");
    return s && s->variance_ratio_vs_mis > 0 ? s->variance_ratio_vs_mis : kNaN;
}

size_t AlphaSweep::best(size_t bsdf) const {
    size_t best = 0;
    for (size_t i = 1; i < alphas.size(); ++i)
        if (ratio(i, bsdf) < ratio(best, bsdf) || std::isnan(ratio(best, bsdf))) best = i;
    return best;
}

std::vector<Technique> alpha_sweep_techniques(std::span<const Technique> requested) {
    std::vector<Technique> list = {kBalance, kBalanceComp};
    if (requested.empty()) {
        for (const char* name : {"mis-power-comp", "mis-optimal-comp"}) {
            try {
                add_unique(list, Technique::parse(name));
            } catch (const std::invalid_argument&) {
                // a technique this build does not have
            }
        }
        return list;
    }
    for (const Technique& t : requested)
        if (t.compensated || t.bins) add_unique(list, t);
    return list;
}

AlphaSweep run_alpha_sweep(const StudyInputs& inputs, std::span<const float> alphas, bool exact,
                           const RunControl& control) {
    const ComparisonOptions& options = inputs.options;
    const std::span<const ShadingPoint> points = inputs.points;
    AlphaSweep sweep;
    sweep.allocation = options.allocation;
    // The quadratures stop as the runs do: a sweep cut short keeps the alphas completed.
    const auto exact_ratios_to = [&](const EnvMap& env, const Technique& technique, std::vector<double>& out) {
        try {
            out = exact_variances(env, technique, options.allocation, options.bsdfs, points, 1, control.stop);
            return true;
        } catch (const Interrupted&) {
            sweep.interrupted = true;
            return false;
        }
    };
    std::vector<double> baseline;
    if (exact && !exact_ratios_to(inputs.plain, kBalance, baseline)) return sweep;
    for (size_t i = 0; i < alphas.size(); ++i) {
        const CompensatedMaps compensated =
            compensated_maps(inputs.plain, std::vector<float>(options.bsdfs.size(), alphas[i]));
        // The bins at the same fixed alpha, in the layout of the study's own.
        std::optional<BinnedEnvMap> binned;
        if (uses_bins(options.techniques)) {
            BinnedOptions bins;
            if (inputs.binned) {
                bins.bins_per_side = inputs.binned->layout().bins_per_side;
                bins.diffuse_bins_per_side = inputs.binned->layout().diffuse_bins_per_side;
            }
            bins.auto_alpha = false;
            bins.alpha = alphas[i];
            binned.emplace(build_bins(EnvMap(inputs.plain), bins));
        }
        Comparison c = compare({inputs.plain, compensated, points, sweep_options(options), binned ? &*binned : nullptr},
                               run_control(control, i, alphas.size(), points.size()));
        if (c.points_done < points.size() || control.stopped()) {
            sweep.interrupted = true;
            break;
        }
        if (std::vector<double> variances; exact) {
            if (!exact_ratios_to(compensated.maps.front(), kBalanceComp, variances)) break;
            sweep.exact.push_back(geometric_mean_ratios(variances, baseline, options.bsdfs.size()));
        }
        sweep.alphas.push_back(alphas[i]);
        sweep.comparisons.push_back(std::move(c));
    }
    return sweep;
}

size_t AllocationSweep::best(size_t bsdf, size_t technique) const {
    size_t best = 0;
    for (size_t i = 1; i < allocations.size(); ++i)
        if (comparisons[i].bsdfs[bsdf].techniques[technique].efficiency >
            comparisons[best].bsdfs[bsdf].techniques[technique].efficiency)
            best = i;
    return best;
}

std::vector<Technique> allocation_sweep_techniques(std::span<const Technique> requested) {
    if (requested.empty()) return {kBalance, kBalanceComp};
    std::vector<Technique> list;
    for (const Technique& t : requested)
        if (t.strategy == Strategy::mis || t.strategy == Strategy::one_sample) add_unique(list, t);
    if (list.empty())
        throw std::runtime_error(
            "--allocation-sweep: none of --techniques combines environment and BSDF samples (mis-*, one-sample*)");
    return list;
}

AllocationSweep run_allocation_sweep(const StudyInputs& inputs, uint32_t total, const RunControl& control) {
    AllocationSweep sweep;
    StudyInputs run{inputs.plain, inputs.compensated, inputs.points, sweep_options(inputs.options), inputs.binned};
    for (uint32_t k = 1; k < total; ++k) {
        run.options.allocation = {k, total - k};
        Comparison c = compare(run, run_control(control, k - 1, total - 1, inputs.points.size()));
        if (c.points_done < inputs.points.size() || control.stopped()) {
            sweep.interrupted = true;
            break;
        }
        sweep.allocations.push_back(run.options.allocation);
        sweep.comparisons.push_back(std::move(c));
    }
    return sweep;
}

std::vector<SweepRow> sweep_rows(const AlphaSweep& sweep) {
    std::vector<SweepRow> rows;
    for (size_t i = 0; i < sweep.alphas.size(); ++i)
        for (size_t b = 0; b < sweep.comparisons[i].bsdfs.size(); ++b) {
            const BsdfComparison& bc = sweep.comparisons[i].bsdfs[b];
            for (const TechniqueStats& t : bc.techniques) {
                const bool comp = t.technique == kBalanceComp;
                rows.push_back({"alpha", sweep.alphas[i], sweep.allocation, &bc.bsdf, &t,
                                comp && !sweep.exact.empty() ? sweep.exact[i][b] : kNaN, comp && sweep.best(b) == i});
            }
        }
    return rows;
}

std::vector<SweepRow> sweep_rows(const AllocationSweep& sweep, const CompensatedMaps& compensated) {
    std::vector<SweepRow> rows;
    for (size_t i = 0; i < sweep.allocations.size(); ++i)
        for (size_t b = 0; b < sweep.comparisons[i].bsdfs.size(); ++b) {
            const BsdfComparison& bc = sweep.comparisons[i].bsdfs[b];
            for (size_t t = 0; t < bc.techniques.size(); ++t)
                rows.push_back({"allocation", compensated.alpha_of(b), sweep.allocations[i], &bc.bsdf,
                                &bc.techniques[t], kNaN, sweep.best(b, t) == i});
        }
    return rows;
}

}  // namespace envmis
