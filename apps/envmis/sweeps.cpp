#include "sweeps.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "envmis/report/results.h"

namespace envmis::cli {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

const Technique kBalanceComp = Technique::parse("mis-balance-comp");

size_t index_of(std::span<const float> values, float value) {
    return static_cast<size_t>(std::find(values.begin(), values.end(), value) - values.begin());
}

// The sweeps' table columns: variance and var/mis (a "-" where there is no ratio in the
// allocation sweep), the exact ratio, then timing.
constexpr StatsColumn kAlphaFigures[] = {{"variance", "variance", 11, "%.4g"},
                                         {"variance_ratio_vs_mis", "var/mis", 8, "%.4f"}};
constexpr StatsColumn kAllocationFigures[] = {{"variance", "variance", 11, "%.4g"},
                                              {"variance_ratio_vs_mis", "var/mis", 8, "%.4f", true}};
constexpr StatsColumn kExact = {"exact_variance_ratio_vs_mis", "exact", 8, "%.4f", true};
constexpr StatsColumn kTiming[] = {{"ns_per_estimate", "ns/est", 8, "%.1f"}, {"efficiency", "efficiency", 11, "%.4g"}};

std::string cell_text_heading(const StatsColumn& column) { return headings_text({&column, 1}).substr(1); }

std::string allocation_text(Allocation a) { return std::to_string(a.env) + ":" + std::to_string(a.bsdf); }

}  // namespace

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

void print_alpha_sweep(std::ostream& out, const AlphaSweep& sweep, const std::vector<float>* auto_alphas) {
    char line[256];
    std::snprintf(line, sizeof line, "%-8s %-10s %-17s", "alpha", "bsdf", "technique");
    out << line << headings_text(kAlphaFigures) << " " << cell_text_heading(kExact) << headings_text(kTiming) << "\n";
    for (size_t i = 0; i < sweep.alphas.size(); ++i)
        for (size_t b = 0; b < sweep.comparisons[i].bsdfs.size(); ++b) {
            const BsdfComparison& bc = sweep.comparisons[i].bsdfs[b];
            for (const TechniqueStats& t : bc.techniques) {
                const bool exact = !sweep.exact.empty() && t.technique == kBalanceComp;
                std::snprintf(line, sizeof line, "%-8g %-10s %-17s", sweep.alphas[i], bc.bsdf.name().c_str(),
                              t.technique.name().c_str());
                out << line << cells_text(t, kAlphaFigures) << " "
                    << cell_text(exact ? sweep.exact[i][b] : kNaN, kExact) << cells_text(t, kTiming) << "\n";
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
        pictures::Series series{
            sweep.comparisons.front().bsdfs[b].bsdf.name(), {}, {}, static_cast<int>(sweep.best(b))};
        for (size_t i = 0; i < sweep.alphas.size(); ++i) {
            series.x.push_back(sweep.alphas[i]);
            series.y.push_back(sweep.ratio(i, b));
        }
        plot.series.push_back(std::move(series));
    }
    plot.best_label = "best alpha";
    return plot;
}

void print_allocation_sweep(std::ostream& out, const AllocationSweep& sweep) {
    char line[256];
    std::snprintf(line, sizeof line, "%-8s %-10s %-17s", "env:bsdf", "bsdf", "technique");
    out << line << headings_text(kAllocationFigures) << headings_text(kTiming) << "\n";
    for (size_t i = 0; i < sweep.allocations.size(); ++i)
        for (const BsdfComparison& b : sweep.comparisons[i].bsdfs)
            for (const TechniqueStats& t : b.techniques) {
                std::snprintf(line, sizeof line, "%-8s %-10s %-17s", allocation_text(sweep.allocations[i]).c_str(),
                              b.bsdf.name().c_str(), t.technique.name().c_str());
                out << line << cells_text(t, kAllocationFigures) << cells_text(t, kTiming) << "\n";
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
            pictures::Series series{first.bsdfs[b].bsdf.name() + " " + first.bsdfs[b].techniques[t].technique.name(),
                                    {},
                                    {},
                                    static_cast<int>(sweep.best(b, t))};
            for (size_t i = 0; i < sweep.allocations.size(); ++i) {
                series.x.push_back(sweep.allocations[i].env);
                series.y.push_back(sweep.comparisons[i].bsdfs[b].techniques[t].efficiency);
            }
            plot.series.push_back(std::move(series));
        }
    plot.best_label = "best split (highest efficiency)";
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

nlohmann::json sweep_row_json(const SweepRow& row) {
    nlohmann::json j = stats_json(*row.stats, StatsDetail::sweep);
    j["alpha"] = row.alpha;
    j["env_samples"] = row.allocation.env;
    j["bsdf_samples"] = row.allocation.bsdf;
    j["bsdf"] = row.bsdf->name();
    j["best"] = row.best;
    if (!std::isnan(row.exact_ratio)) j["exact_variance_ratio_vs_mis"] = row.exact_ratio;
    return j;
}

// The sweeps' figures around the exact ratio: variance and var/mis before it, timing after.
constexpr std::span<const char*const> kBeforeExact(kSweepFigures, 2), kAfterExact(kSweepFigures + 2, 2);

std::string sweep_csv_header() {
    return csv_header(
               {"map", "spp", "seed", "points", "sweep", "alpha", "env_samples", "bsdf_samples", "bsdf", "technique"}) +
           ',' + csv_header(kBeforeExact) + ",exact_variance_ratio_vs_mis," + csv_header(kAfterExact) + ",best";
}

void write_sweep_csv_row(std::ostream& out, const std::string& prefix, const SweepRow& row) {
    out << prefix << row.sweep << ',' << row.alpha << ',' << row.allocation.env << ',' << row.allocation.bsdf << ','
        << row.bsdf->name() << ',' << row.stats->technique.name() << ',';
    write_csv_fields(out, *row.stats, kBeforeExact);
    out << ',';
    if (!std::isnan(row.exact_ratio)) out << row.exact_ratio;
    out << ',';
    write_csv_fields(out, *row.stats, kAfterExact);
    out << ',' << (row.best ? 1 : 0) << '\n';
}

}  // namespace envmis::cli
