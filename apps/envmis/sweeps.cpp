#include "sweeps.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "cli.h"

namespace envmis::cli {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

const Technique kBalance = Technique::parse("mis-balance");
const Technique kBalanceComp = Technique::parse("mis-balance-comp");

void add_unique(std::vector<Technique>& list, const Technique& t) {
    if (std::find(list.begin(), list.end(), t) == list.end()) list.push_back(t);
}

size_t index_of(std::span<const float> values, float value) {
    return static_cast<size_t>(std::find(values.begin(), values.end(), value) - values.begin());
}

// A ratio for a table cell: "-" when there is none.
std::string ratio_text(double ratio) {
    if (!(ratio > 0)) return "-";
    char text[32];
    std::snprintf(text, sizeof text, "%.4f", ratio);
    return text;
}

// The sweeps' options: a one-subdivision reference (see sweeps.h).
ComparisonOptions sweep_options(const ComparisonOptions& options) {
    ComparisonOptions o = options;
    o.quadrature.max_subdivisions = 1;
    return o;
}

std::string allocation_text(Allocation a) { return std::to_string(a.env) + ":" + std::to_string(a.bsdf); }

// Progress over several compare() runs of `points` points each.
std::function<void(size_t, size_t)> run_progress(Progress& progress, size_t run, size_t points) {
    return [&progress, run, points](size_t done, size_t) { progress.update(run * points + done); };
}

}  // namespace

EnvMap compensated_map(const EnvMap& plain, float alpha) {
    EnvMapOptions options = plain.options();
    options.compensation = {true, alpha};
    return EnvMap(to_image(plain.radiance()), options);
}

CompensatedMaps compensated_maps(const EnvMap& plain, std::span<const float> bsdf_alphas) {
    CompensatedMaps result;
    for (float alpha : bsdf_alphas) {
        size_t i = index_of(result.alphas, alpha);
        if (i == result.alphas.size()) {
            result.alphas.push_back(alpha);
            result.maps.push_back(compensated_map(plain, alpha));
        }
        result.of_bsdf.push_back(i);
    }
    return result;
}

Comparison compare_each(const EnvMap& plain, const CompensatedMaps& compensated, std::span<const ShadingPoint> points,
                        const ComparisonOptions& options, const std::atomic<bool>* stop,
                        const std::function<void(size_t, size_t)>& progress) {
    const size_t runs = compensated.maps.size();
    std::vector<std::optional<BsdfComparison>> slots(options.bsdfs.size());
    Comparison merged{{}, points.size(), points.size()};
    for (size_t m = 0; m < runs; ++m) {
        if (stop && stop->load()) {
            merged.points_done = 0;
            break;
        }
        ComparisonOptions run = options;
        run.bsdfs.clear();
        std::vector<size_t> slot;
        for (size_t b = 0; b < options.bsdfs.size(); ++b)
            if (compensated.of_bsdf[b] == m) run.bsdfs.push_back(options.bsdfs[b]), slot.push_back(b);
        const Comparison c = compare(plain, compensated.maps[m], points, run, stop, [&](size_t done, size_t total) {
            if (progress) progress(m * total + done, runs * total);
        });
        merged.points_done = std::min(merged.points_done, c.points_done);
        for (size_t i = 0; i < c.bsdfs.size(); ++i) slots[slot[i]] = c.bsdfs[i];
    }
    for (auto& s : slots)
        if (s) merged.bsdfs.push_back(std::move(*s));
    return merged;
}

void print_alpha_choice(std::ostream& out, const AlphaChoice& choice, std::span<const Bsdf> bsdfs) {
    char line[64];
    out << "alpha auto: exact variance of mis-balance-comp / mis-balance, geometric mean over points, on a "
        << choice.width << "x" << choice.height << " copy (" << static_cast<int>(1e3 * choice.seconds + 0.5)
        << " ms); * marks each BSDF's choice and the map-wide one (all)\n";
    std::snprintf(line, sizeof line, "%8s", "alpha");
    out << line;
    for (const Bsdf& b : bsdfs) {
        std::snprintf(line, sizeof line, " %11s", b.name().c_str());
        out << line;
    }
    out << "         all\n";
    auto cell = [&](double value, bool chosen) {
        std::snprintf(line, sizeof line, " %10.4f%c", value, chosen ? '*' : ' ');
        out << line;
    };
    for (const AlphaCandidate& c : choice.candidates) {
        std::snprintf(line, sizeof line, "%8g", c.alpha);
        out << line;
        for (size_t b = 0; b < bsdfs.size(); ++b) cell(c.per_bsdf[b], c.alpha == choice.bsdf_alphas[b]);
        cell(c.criterion, c.alpha == choice.alpha);
        out << "\n";
    }
}

nlohmann::json alpha_choice_json(const AlphaChoice& choice, std::span<const Bsdf> bsdfs) {
    nlohmann::json j = {{"criterion", "exact variance of mis-balance-comp / mis-balance, geometric mean over points"},
                        {"width", choice.width},
                        {"height", choice.height},
                        {"seconds", choice.seconds},
                        {"map_alpha", choice.alpha},
                        {"candidates", nlohmann::json::array()}};
    for (size_t b = 0; b < bsdfs.size(); ++b) j["bsdf_alpha"][bsdfs[b].name()] = choice.bsdf_alphas[b];
    for (const AlphaCandidate& c : choice.candidates) {
        nlohmann::json per_bsdf;
        for (size_t b = 0; b < bsdfs.size(); ++b) per_bsdf[bsdfs[b].name()] = c.per_bsdf[b];
        j["candidates"].push_back({{"alpha", c.alpha}, {"all", c.criterion}, {"per_bsdf", per_bsdf}});
    }
    return j;
}

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
        if (t.compensated) add_unique(list, t);
    return list;
}

AlphaSweep run_alpha_sweep(const EnvMap& plain, std::span<const float> alphas, std::span<const ShadingPoint> points,
                           const ComparisonOptions& options, bool exact, const std::atomic<bool>* stop) {
    AlphaSweep sweep;
    sweep.allocation = options.allocation;
    Progress progress("alpha sweep", alphas.size() * points.size());
    std::vector<double> baseline;
    if (exact) baseline = exact_variances(plain, kBalance, options.allocation, options.bsdfs, points, 1);
    for (size_t i = 0; i < alphas.size(); ++i) {
        const EnvMap compensated = compensated_map(plain, alphas[i]);
        Comparison c =
            compare(plain, compensated, points, sweep_options(options), stop, run_progress(progress, i, points.size()));
        if (c.points_done < points.size() || (stop && stop->load())) {
            sweep.interrupted = true;
            break;
        }
        if (exact)
            sweep.exact.push_back(geometric_mean_ratios(
                exact_variances(compensated, kBalanceComp, options.allocation, options.bsdfs, points, 1), baseline,
                options.bsdfs.size()));
        sweep.alphas.push_back(alphas[i]);
        sweep.comparisons.push_back(std::move(c));
    }
    return sweep;
}

void print_alpha_sweep(std::ostream& out, const AlphaSweep& sweep, const std::vector<float>* auto_alphas) {
    char line[256];
    std::snprintf(line, sizeof line, "%-8s %-10s %-17s %11s %8s %8s %8s %11s\n", "alpha", "bsdf", "technique",
                  "variance", "var/mis", "exact", "ns/est", "efficiency");
    out << line;
    for (size_t i = 0; i < sweep.alphas.size(); ++i)
        for (size_t b = 0; b < sweep.comparisons[i].bsdfs.size(); ++b) {
            const BsdfComparison& bc = sweep.comparisons[i].bsdfs[b];
            for (const TechniqueStats& t : bc.techniques) {
                const bool exact = !sweep.exact.empty() && t.technique == kBalanceComp;
                std::snprintf(line, sizeof line, "%-8g %-10s %-17s %11.4g %8.4f %8s %8.1f %11.4g\n", sweep.alphas[i],
                              bc.bsdf.name().c_str(), t.technique.name().c_str(), t.variance, t.variance_ratio_vs_mis,
                              exact ? ratio_text(sweep.exact[i][b]).c_str() : "-", t.ns_per_estimate, t.efficiency);
                out << line;
            }
        }
    if (sweep.alphas.empty()) return;
    out << "best alpha per BSDF (lowest " << (sweep.exact.empty() ? "measured" : "exact")
        << " var/mis of mis-balance-comp):\n";
    for (const nlohmann::json& s : alpha_sweep_summary_json(sweep, auto_alphas)) {
        std::snprintf(line, sizeof line, "  %-10s best alpha %-6g (%.4f)", s["bsdf"].get<std::string>().c_str(),
                      s["best_alpha"].get<double>(), s["best_ratio"].get<double>());
        out << line;
        if (s.contains("auto_alpha")) {
            std::snprintf(line, sizeof line, "; auto alpha %g (%.4f): %.4fx the best", s["auto_alpha"].get<double>(),
                          s["auto_ratio"].get<double>(), s["auto_vs_best"].get<double>());
            out << line;
            if (s.contains("auto_vs_alpha0")) {
                std::snprintf(line, sizeof line, ", %.4fx alpha 0", s["auto_vs_alpha0"].get<double>());
                out << line;
            }
        }
        out << "\n";
    }
}

nlohmann::json alpha_sweep_summary_json(const AlphaSweep& sweep, const std::vector<float>* auto_alphas) {
    nlohmann::json summary = nlohmann::json::array();
    if (sweep.alphas.empty()) return summary;
    const size_t zero = index_of(sweep.alphas, 0.0f);
    for (size_t b = 0; b < sweep.comparisons.front().bsdfs.size(); ++b) {
        const size_t best = sweep.best(b);
        nlohmann::json s = {{"bsdf", sweep.comparisons.front().bsdfs[b].bsdf.name()},
                            {"ratio_by", sweep.exact.empty() ? "measured" : "exact"},
                            {"best_alpha", sweep.alphas[best]},
                            {"best_ratio", sweep.ratio(best, b)}};
        const size_t chosen = auto_alphas ? index_of(sweep.alphas, (*auto_alphas)[b]) : sweep.alphas.size();
        if (chosen < sweep.alphas.size()) {
            s["auto_alpha"] = sweep.alphas[chosen];
            s["auto_ratio"] = sweep.ratio(chosen, b);
            s["auto_vs_best"] = sweep.ratio(chosen, b) / sweep.ratio(best, b);
            if (zero < sweep.alphas.size()) s["auto_vs_alpha0"] = sweep.ratio(chosen, b) / sweep.ratio(zero, b);
        }
        summary.push_back(s);
    }
    return summary;
}

pictures::LinePlot alpha_sweep_plot(const AlphaSweep& sweep, const std::string& map_name) {
    pictures::LinePlot plot{
        "Compensation strength: " + map_name,
        "alpha",
        std::string("var(mis-balance-comp) / var(mis-balance), ") + (sweep.exact.empty() ? "measured" : "exact"),
        {},
        true};
    for (size_t b = 0; !sweep.alphas.empty() && b < sweep.comparisons.front().bsdfs.size(); ++b) {
        pictures::Series series{sweep.comparisons.front().bsdfs[b].bsdf.name(), {}, {}};
        for (size_t i = 0; i < sweep.alphas.size(); ++i) {
            series.x.push_back(sweep.alphas[i]);
            series.y.push_back(sweep.ratio(i, b));
        }
        plot.series.push_back(std::move(series));
    }
    return plot;
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

AllocationSweep run_allocation_sweep(const EnvMap& plain, const CompensatedMaps& compensated, uint32_t total,
                                     std::span<const ShadingPoint> points, const ComparisonOptions& options,
                                     const std::atomic<bool>* stop) {
    AllocationSweep sweep;
    Progress progress("allocation sweep", (total - 1) * points.size());
    ComparisonOptions run = sweep_options(options);
    for (uint32_t k = 1; k < total; ++k) {
        run.allocation = {k, total - k};
        Comparison c =
            compare_each(plain, compensated, points, run, stop, run_progress(progress, k - 1, points.size()));
        if (c.points_done < points.size() || (stop && stop->load())) {
            sweep.interrupted = true;
            break;
        }
        sweep.allocations.push_back(run.allocation);
        sweep.comparisons.push_back(std::move(c));
    }
    return sweep;
}

void print_allocation_sweep(std::ostream& out, const AllocationSweep& sweep) {
    char line[256];
    std::snprintf(line, sizeof line, "%-8s %-10s %-17s %11s %8s %8s %11s\n", "env:bsdf", "bsdf", "technique",
                  "variance", "var/mis", "ns/est", "efficiency");
    out << line;
    for (size_t i = 0; i < sweep.allocations.size(); ++i)
        for (const BsdfComparison& b : sweep.comparisons[i].bsdfs)
            for (const TechniqueStats& t : b.techniques) {
                std::snprintf(line, sizeof line, "%-8s %-10s %-17s %11.4g %8s %8.1f %11.4g\n",
                              allocation_text(sweep.allocations[i]).c_str(), b.bsdf.name().c_str(),
                              t.technique.name().c_str(), t.variance, ratio_text(t.variance_ratio_vs_mis).c_str(),
                              t.ns_per_estimate, t.efficiency);
                out << line;
            }
    if (sweep.allocations.empty()) return;
    out << "best allocation per BSDF and technique (highest efficiency = 1 / (variance * seconds per estimate)):\n";
    const Comparison& first = sweep.comparisons.front();
    for (size_t b = 0; b < first.bsdfs.size(); ++b)
        for (size_t t = 0; t < first.bsdfs[b].techniques.size(); ++t) {
            const size_t best = sweep.best(b, t);
            std::snprintf(line, sizeof line, "  %-10s %-17s %s (efficiency %.4g)\n", first.bsdfs[b].bsdf.name().c_str(),
                          first.bsdfs[b].techniques[t].technique.name().c_str(),
                          allocation_text(sweep.allocations[best]).c_str(),
                          sweep.comparisons[best].bsdfs[b].techniques[t].efficiency);
            out << line;
        }
}

pictures::LinePlot allocation_plot(const AllocationSweep& sweep, const std::string& map_name) {
    const uint32_t total = sweep.allocations.empty() ? 0 : sweep.allocations.front().total();
    pictures::LinePlot plot{"Sample allocation (" + std::to_string(total) + " per estimate): " + map_name,
                            "environment samples per estimate",
                            "efficiency, 1 / (variance x seconds per estimate)",
                            {},
                            true};
    if (sweep.allocations.empty()) return plot;
    const Comparison& first = sweep.comparisons.front();
    for (size_t b = 0; b < first.bsdfs.size(); ++b)
        for (size_t t = 0; t < first.bsdfs[b].techniques.size(); ++t) {
            pictures::Series series{
                first.bsdfs[b].bsdf.name() + " " + first.bsdfs[b].techniques[t].technique.name(), {}, {}};
            for (size_t i = 0; i < sweep.allocations.size(); ++i) {
                series.x.push_back(sweep.allocations[i].env);
                series.y.push_back(sweep.comparisons[i].bsdfs[b].techniques[t].efficiency);
            }
            plot.series.push_back(std::move(series));
        }
    return plot;
}

pictures::BarChart variance_chart(const Comparison& comparison, const std::string& map_name) {
    pictures::BarChart chart{"Variance relative to mis-balance: " + map_name,
                             "var / var(mis-balance), geometric mean over points",
                             {},
                             {},
                             {},
                             true,
                             1.0};
    for (const BsdfComparison& b : comparison.bsdfs) {
        chart.groups.push_back(b.bsdf.name());
        std::vector<double> values;
        for (const TechniqueStats& t : b.techniques)
            values.push_back(t.variance_ratio_vs_mis > 0 ? t.variance_ratio_vs_mis : kNaN);
        chart.values.push_back(std::move(values));
    }
    if (!comparison.bsdfs.empty())
        for (const TechniqueStats& t : comparison.bsdfs.front().techniques) chart.bars.push_back(t.technique.name());
    return chart;
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

nlohmann::json sweep_row_json(const SweepRow& row) {
    const TechniqueStats& t = *row.stats;
    nlohmann::json j = {{"alpha", row.alpha},
                        {"env_samples", row.allocation.env},
                        {"bsdf_samples", row.allocation.bsdf},
                        {"bsdf", row.bsdf->name()},
                        {"technique", t.technique.name()},
                        {"variance", t.variance},
                        {"variance_ratio_vs_mis", t.variance_ratio_vs_mis},
                        {"ns_per_estimate", t.ns_per_estimate},
                        {"efficiency", t.efficiency},
                        {"estimates", t.estimates},
                        {"best", row.best}};
    if (!std::isnan(row.exact_ratio)) j["exact_variance_ratio_vs_mis"] = row.exact_ratio;
    return j;
}

const char* const kSweepCsvHeader =
    "map,spp,seed,points,sweep,alpha,env_samples,bsdf_samples,bsdf,technique,variance,variance_ratio_vs_mis,"
    "exact_variance_ratio_vs_mis,ns_per_estimate,efficiency,best";

void write_sweep_csv_row(std::ostream& out, const std::string& prefix, const SweepRow& row) {
    const TechniqueStats& t = *row.stats;
    out << prefix << row.sweep << ',' << row.alpha << ',' << row.allocation.env << ',' << row.allocation.bsdf << ','
        << row.bsdf->name() << ',' << t.technique.name() << ',' << t.variance << ',' << t.variance_ratio_vs_mis << ',';
    if (!std::isnan(row.exact_ratio)) out << row.exact_ratio;
    out << ',' << t.ns_per_estimate << ',' << t.efficiency << ',' << (row.best ? 1 : 0) << '\n';
}

}  // namespace envmis::cli
