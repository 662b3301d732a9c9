#include "envmis/report/markdown.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>

#include "envmis/report/results.h"

namespace envmis {
namespace {

using nlohmann::json;

// The schema of what report reads from a compare run (each field it reads, of the type
// it reads it as): anything else is refused naming the file and the field, before any
// of it is used.
struct Schema {
    const std::string& path;

    void require(bool ok, const std::string& field, const char* expected) const {
        if (!ok) throw std::runtime_error(path + ": " + field + ": expected " + expected);
    }
    // Optional fields that, where present, have the type given.
    void strings(const json& o, const std::string& where, std::initializer_list<const char*> keys) const {
        for (const char* k : keys) require(!o.contains(k) || o[k].is_string(), where + "." + k, "a string");
    }
    // A number, or null: what compare writes for a value that is not finite, read as NaN.
    void numbers(json& o, const std::string& where, std::initializer_list<const char*> keys) const {
        for (const char* k : keys) {
            if (!o.contains(k)) continue;
            if (o[k].is_null()) o[k] = std::numeric_limits<double>::quiet_NaN();
            require(o[k].is_number(), where + "." + k, "a number");
        }
    }
    // Counts and sizes: integers from 0 to 2^32 - 1 (compare's --spp goes that far).
    void integers(const json& o, const std::string& where, std::initializer_list<const char*> keys) const {
        for (const char* k : keys)
            require(!o.contains(k) || (o[k].is_number_integer() && o[k].get<int64_t>() >= 0 &&
                                       o[k].get<int64_t>() <= int64_t{UINT32_MAX}),
                    where + "." + k, "an integer from 0 to 4294967295");
    }
    // Required fields.
    void has(const json& o, const std::string& where, std::initializer_list<const char*> keys) const {
        for (const char* k : keys) require(o.contains(k), where + "." + k, "present");
    }
    // The array at `key` (where present), each element an object; calls check on each.
    template <class Check>
    void objects(json& run, const char* key, Check&& check) const {
        if (!run.contains(key)) return;
        require(run[key].is_array(), key, "an array");
        for (size_t i = 0; i < run[key].size(); ++i) {
            const std::string where = std::string(key) + "[" + std::to_string(i) + "]";
            require(run[key][i].is_object(), where, "an object");
            check(run[key][i], where);
        }
    }
    void number_array(json& o, const std::string& where, const char* key) const {
        if (!o.contains(key)) return;
        json& a = o[key];
        require(a.is_array(), where + "." + key, "an array of numbers");
        for (json& v : a) {
            if (v.is_null()) v = std::numeric_limits<double>::quiet_NaN();
            require(v.is_number(), where + "." + key, "an array of numbers");
        }
    }
};

void check_schema(json& j, const std::string& path) {
    const Schema s{path};
    s.require(j["inputs"].is_object(), "inputs", "an object");
    s.strings(j["inputs"], "inputs", {"map"});
    s.numbers(j["inputs"], "inputs", {"alpha"});
    s.integers(j["inputs"], "inputs", {"width", "height", "points_done", "spp", "env_samples", "bsdf_samples"});
    s.objects(j, "results", [&](json& r, const std::string& where) {
        s.has(r, where, {"bsdf", "technique", "variance_ratio_vs_mis"});
        s.strings(r, where, {"bsdf", "technique"});
        s.has(r, where, {"mean", "reference", "variance", "std_error", "rel_mse", "ns_per_estimate", "efficiency"});
        s.numbers(r, where,
                  {"mean", "reference", "variance", "std_error", "rel_mse", "ns_per_estimate", "efficiency",
                   "variance_ratio_vs_mis"});
        s.number_array(r, where, "point_variances");
        s.number_array(r, where, "point_variance_rel_se");
        s.require(
            r.contains("point_variances") == r.contains("point_variance_rel_se") &&
                (!r.contains("point_variances") || r["point_variances"].size() == r["point_variance_rel_se"].size()),
            where + ".point_variance_rel_se", "one per point of point_variances");
    });
    s.objects(j, "sweep_best", [&](json& b, const std::string& where) {
        s.has(b, where, {"bsdf", "best_alpha", "best_ratio"});
        if (b.contains("auto_alpha")) s.has(b, where, {"auto_vs_best", "auto_vs_alpha0"});
        s.strings(b, where, {"bsdf"});
        s.numbers(b, where, {"best_alpha", "best_ratio", "auto_alpha", "auto_vs_best", "auto_vs_alpha0"});
    });
    s.objects(j, "allocation", [&](json& a, const std::string& where) {
        s.has(a, where, {"bsdf", "technique", "efficiency", "env_samples", "bsdf_samples"});
        s.strings(a, where, {"bsdf", "technique"});
        s.numbers(a, where, {"efficiency"});
        s.integers(a, where, {"env_samples", "bsdf_samples"});
    });
}

}  // namespace

std::optional<json> parse_results(std::string_view text, const std::string& name) {
    json j;
    try {
        j = json::parse(text);
    } catch (const json::exception& e) {
        throw std::runtime_error(name + ": not JSON (" + e.what() + ")");
    }
    if (j.is_object() && j.contains("envmis_summary")) return std::nullopt;
    const bool measured = j.is_object() && ((j.contains("results") && j["results"].is_array()) || j.contains("sweep") ||
                                            j.contains("allocation"));
    if (!measured || !j.contains("inputs"))
        throw std::runtime_error(name + ": not the JSON of envmis compare (no inputs and results)");
    check_schema(j, name);
    return j;
}

namespace {

std::string number(double v, const char* format = "%.4g") {
    char text[32];
    std::snprintf(text, sizeof text, format, v);
    return text;
}

// One (map, BSDF) case: each technique's variance relative to mis-balance, and its
// per-point variances with their relative standard errors.
struct Case {
    std::string map, bsdf;
    std::map<std::string, double> ratio;
    std::set<std::string> exact;  // techniques whose ratio is the exact one (single techniques)
    std::map<std::string, std::pair<std::vector<double>, std::vector<double>>> points;
};

// Geometric mean over points of the variance ratio a / b, and the standard error of its
// logarithm (from the points' relative standard errors); nullopt without per-point data.
std::optional<std::pair<double, double>> paired_ratio(const Case& c, const std::string& a, const std::string& b) {
    const auto pa = c.points.find(a), pb = c.points.find(b);
    if (pa == c.points.end() || pb == c.points.end() || pa->second.first.size() != pb->second.first.size())
        return std::nullopt;
    double log_sum = 0, se2 = 0;
    size_t n = 0;
    for (size_t p = 0; p < pa->second.first.size(); ++p) {
        const double va = pa->second.first[p], vb = pb->second.first[p];
        if (!(va > 0 && vb > 0)) continue;
        log_sum += std::log(va / vb);
        se2 += pa->second.second[p] * pa->second.second[p] + pb->second.second[p] * pb->second.second[p];
        ++n;
    }
    if (n == 0) return std::nullopt;
    return std::pair{std::exp(log_sum / n), std::sqrt(se2) / n};
}

// The name of a run's map without its extension: the folder of its plots.
std::string stem(const json& run) {
    const std::string map = run["inputs"].value("map", "map");
    return map.substr(0, map.rfind('.'));
}

// Compensation strength: for every (map, BSDF), the best alpha of the sweep, the
// automatic choice, and how their variances compare.
void write_strength(std::ostream& out, const std::vector<json>& runs) {
    size_t within = 0, total = 0, never_worse = 0;
    bool header = false;
    for (const json& run : runs) {
        if (!run.contains("sweep_best")) continue;
        if (!header) {
            out << "## Compensation strength: `--alpha auto` against the sweep\n\n"
                << "Variance of mis-balance-comp relative to mis-balance at each alpha of the sweep (exact, by "
                   "quadrature, "
                   "when the sweep ran with `--exact`); auto's choice (exact variances on a 128-wide copy of the map) "
                   "against the sweep's best alpha and against alpha = 0 (no compensation).\n\n"
                << "| map | bsdf | best alpha | best ratio | auto alpha | auto / best | auto / alpha 0 |\n"
                << "|---|---|---:|---:|---:|---:|---:|\n";
            header = true;
        }
        for (const json& b : run["sweep_best"]) {
            if (!b.contains("auto_alpha")) continue;
            const double vs_best = b["auto_vs_best"], vs_zero = b["auto_vs_alpha0"];
            within += vs_best <= 1.05, never_worse += vs_zero <= 1.05, ++total;
            out << "| " << run["inputs"].value("map", "?") << " | " << b["bsdf"].get<std::string>() << " | "
                << number(b["best_alpha"], "%.3g") << " | " << number(b["best_ratio"], "%.3f") << " | "
                << number(b["auto_alpha"], "%.3g") << " | " << number(vs_best, "%.3f") << " | "
                << number(vs_zero, "%.3f") << " |\n";
        }
    }
    if (total)
        out << "\nAuto is within 5% of the best alpha in " << within << " of " << total
            << " cases and at most 5% worse than alpha = 0 in " << never_worse << " of " << total << ".\n\n";
}

// Sample allocation: the most efficient n_env:n_bsdf split per (map, BSDF, technique).
void write_allocation(std::ostream& out, const std::vector<json>& runs, bool no_timing) {
    if (no_timing) return;  // the best split is the one of highest measured efficiency
    bool header = false;
    for (const json& run : runs) {
        if (!run.contains("allocation")) continue;
        if (!header) {
            out << "## Sample allocation\n\n"
                << "For a fixed number of samples per estimate, every split between environment and BSDF samples; "
                   "efficiency = 1 / (variance x time per estimate). The best split, and its efficiency relative to "
                   "the "
                   "even (or nearest to even) split.\n\n"
                << "| map | bsdf | technique | best env:bsdf | efficiency | vs even split "
                   "|\n|---|---|---|---:|---:|---:|\n";
            header = true;
        }
        std::map<std::pair<std::string, std::string>, std::vector<const json*>> groups;
        for (const json& a : run["allocation"]) groups[{a["bsdf"], a["technique"]}].push_back(&a);
        for (const auto& [key, rows] : groups) {
            const json* best = nullptr;
            const json* even = nullptr;
            for (const json* r : rows) {
                if (!best || (*r)["efficiency"].get<double>() > (*best)["efficiency"].get<double>()) best = r;
                const int64_t gap = std::abs((*r)["env_samples"].get<int64_t>() - (*r)["bsdf_samples"].get<int64_t>());
                if (!even ||
                    gap < std::abs((*even)["env_samples"].get<int64_t>() - (*even)["bsdf_samples"].get<int64_t>()))
                    even = r;
            }
            out << "| " << run["inputs"].value("map", "?") << " | " << key.first << " | " << key.second << " | "
                << (*best)["env_samples"].get<int64_t>() << ":" << (*best)["bsdf_samples"].get<int64_t>() << " | "
                << number((*best)["efficiency"]) << " | "
                << number((*best)["efficiency"].get<double>() / (*even)["efficiency"].get<double>(), "%.2f") << "x |\n";
        }
    }
    if (header) out << "\n";
}

// The techniques in the order of the first run that has them (mis-balance, the
// baseline, left out) and the (map, BSDF) cases of all runs.
bool single_technique(const std::string& t) { return !t.starts_with("mis-") && !t.starts_with("one-sample"); }
std::pair<std::vector<std::string>, std::vector<Case>> collect_cases(const std::vector<json>& runs) {
    std::vector<std::string> techniques;
    std::vector<Case> cases;
    for (const json& run : runs) {
        const std::string map = run["inputs"].value("map", "?");
        for (const json& r : run.value("results", json::array())) {
            const std::string bsdf = r["bsdf"], technique = r["technique"];
            if (std::find(techniques.begin(), techniques.end(), technique) == techniques.end())
                techniques.push_back(technique);
            auto it =
                std::find_if(cases.begin(), cases.end(), [&](const Case& c) { return c.map == map && c.bsdf == bsdf; });
            if (it == cases.end()) it = cases.insert(cases.end(), Case{map, bsdf, {}, {}, {}});
            it->ratio[technique] = r["variance_ratio_vs_mis"];
            // A single technique's measured variance misses its rare, bright samples: the
            // exact ratio where the run computed one (compare --exact).
            const json* exact =
                run.contains("exact") && run["exact"].contains(bsdf) && run["exact"][bsdf].contains(technique)
                    ? &run["exact"][bsdf][technique]
                    : nullptr;
            if (single_technique(technique) && exact && exact->contains("ratio") && (*exact)["ratio"].is_number()) {
                it->ratio[technique] = (*exact)["ratio"];
                it->exact.insert(technique);
            }
            if (r.contains("point_variances") && r.contains("point_variance_rel_se"))
                it->points[technique] = {r["point_variances"].get<std::vector<double>>(),
                                         r["point_variance_rel_se"].get<std::vector<double>>()};
        }
    }
    std::erase(techniques, "mis-balance");
    return {techniques, cases};
}

void write_intro(std::ostream& out, const std::vector<json>& runs, const std::string& title,
                 const std::string& command) {
    out << "# " << title << "\n\n";
    if (!command.empty()) out << "Made by `" << command << "`.\n\n";
    const auto with_results =
        std::find_if(runs.begin(), runs.end(), [](const json& r) { return r.contains("results"); });
    const json& first = (with_results != runs.end() ? *with_results : runs.front())["inputs"];
    out << "Every technique spends the same number of samples per estimate (" << first.value("env_samples", int64_t{1})
        << " environment + " << first.value("bsdf_samples", int64_t{1})
        << " BSDF for MIS). Figures are variances of one estimate relative to balance "
        << "MIS over the plain density (`mis-balance`), as the geometric mean over "
        << first.value("points_done", int64_t{0}) << " shading points of the per-point ratios; "
        << first.value("spp", int64_t{0}) << " estimates per point. Below 1 is better than balance MIS.\n\n";
}

// Summary: one row per case, one column per technique, the geometric mean row and the
// MIS technique that gains most. Technique names are code (`bsdf`, BSDF sampling), so
// that none reads as the case's BSDF column.
void write_summary(std::ostream& out, const std::vector<std::string>& techniques, const std::vector<Case>& cases) {
    out << "## Variance relative to balance MIS\n\n| map | BSDF |";
    for (const std::string& t : techniques) out << " `" << t << "` |";
    out << "\n|---|---|";
    for (size_t i = 0; i < techniques.size(); ++i) out << "---:|";
    out << "\n";
    std::map<std::string, std::pair<double, int>> log_sum;
    for (const Case& c : cases) {
        out << "| " << c.map << " | " << c.bsdf << " |";
        for (const std::string& t : techniques) {
            const auto it = c.ratio.find(t);
            const bool valid = it != c.ratio.end() && it->second > 0;
            out << " " << (valid ? number(it->second, "%.3f") : "") << " |";
            if (valid) log_sum[t].first += std::log(it->second), ++log_sum[t].second;
        }
        out << "\n";
    }
    out << "| **geometric mean** | |";
    std::string best;
    double best_ratio = INFINITY;
    for (const std::string& t : techniques) {
        const auto& [sum, n] = log_sum[t];
        const double g = n ? std::exp(sum / n) : NAN;
        out << " **" << (n ? number(g, "%.3f") : "") << "** |";
        // Single techniques are left out of the choice: their rare, bright samples (a sun
        // found by BSDF sampling) are often missing from a finite run, which then
        // understates their variance.
        if (t.starts_with("mis-") && n == static_cast<int>(cases.size()) && g < best_ratio) best_ratio = g, best = t;
    }
    out << "\n\n";
    const bool singles = std::any_of(techniques.begin(), techniques.end(), single_technique);
    const bool exact = std::any_of(cases.begin(), cases.end(), [](const Case& c) { return !c.exact.empty(); });
    if (singles)
        out << "A single technique's variance (" << (exact ? "exact here: `--exact`, quadrature" : "measured here")
            << ") comes from rare, bright samples (a sun that BSDF sampling finds once in thousands of estimates), "
               "which a finite run often lacks: "
            << (exact ? "its measured ratio understates it, often by orders of magnitude. The MIS columns are measured."
                      : "these measured ratios may understate it by orders of magnitude (`envmis compare MAP "
                        "--exact` gives the exact ones).")
            << "\n\n";
    if (!best.empty())
        out << "**Lowest variance of the MIS techniques across the table: `" << best << "`, "
            << number(1 / best_ratio, "%.2f") << "x lower variance than balance MIS (geometric mean over "
            << cases.size() << " cases).**\n\n";
}

// Optimal MIS against balance MIS over the same density, case by case, with the noise
// of the measured variances.
void write_optimal(std::ostream& out, const std::vector<Case>& cases) {
    const std::pair<const char*, const char*> pairs[] = {{"mis-optimal", "mis-balance"},
                                                         {"mis-optimal-comp", "mis-balance-comp"},
                                                         {"mis-optimal-all", "mis-balance-all"}};
    bool header = false;
    size_t cases_within = 0, cases_total = 0;
    for (const Case& c : cases)
        for (const auto& [optimal, balance] : pairs) {
            const auto r = paired_ratio(c, optimal, balance);
            if (!r) continue;
            if (!header) {
                out << "## Optimal weights against balance weights over the same density\n\n"
                    << "Variance of optimal MIS over that of balance MIS sampling the same densities: geometric mean "
                       "over the "
                       "points, with the standard error of its logarithm (from 8 interleaved batches per point). "
                       "Within "
                       "error: at most 2 standard errors above 1.\n\n"
                    << "| map | bsdf | optimal | balance | variance optimal / balance | log std. error | <= 1 within "
                       "error |\n"
                    << "|---|---|---|---|---:|---:|---|\n";
                header = true;
            }
            const bool within = std::log(r->first) <= 2 * r->second;
            cases_within += within, ++cases_total;
            out << "| " << c.map << " | " << c.bsdf << " | " << optimal << " | " << balance << " | "
                << number(r->first, "%.3f") << " | " << number(r->second, "%.3f") << " | "
                << (within ? "yes" : "**no**") << " |\n";
        }
    if (header)
        out << "\nOptimal MIS is at most balance MIS within error in " << cases_within << " of " << cases_total
            << " cases.\n\n";
}

// Links to each map's plots, once per map.
void write_plots(std::ostream& out, const std::vector<json>& runs, const std::string& plots) {
    if (plots.empty()) return;
    out << "## Plots\n\n";
    std::vector<std::string> seen;
    for (const json& run : runs) {
        const std::string name = stem(run);
        if (std::find(seen.begin(), seen.end(), name) != seen.end()) continue;
        seen.push_back(name);
        out << "### " << run["inputs"].value("map", "?") << "\n\n";
        for (const char* plot : {"variance_vs_balance", "alpha_sweep", "allocation"})
            out << "![" << name << " " << plot << "](" << plots << "/" << name << "/" << plot << ".png)\n";
        out << "\n";
    }
}

// The report's full table of a run: compare's figures (results.h), as Markdown.
constexpr StatsColumn kReportColumns[] = {{"mean", "mean", 0, "%.4g"},
                                          {"reference", "reference", 0, "%.4g"},
                                          {"variance", "variance", 0, "%.4g"},
                                          {"std_error", "std_error", 0, "%.3g"},
                                          {"rel_mse", "rel_mse", 0, "%.4g"},
                                          {"ns_per_estimate", "ns/estimate", 0, "%.0f"},
                                          {"efficiency", "efficiency", 0, "%.4g"},
                                          {"variance_ratio_vs_mis", "var/mis", 0, "%.3f"}};

// Each run's full table.
void write_tables(std::ostream& out, const std::vector<json>& runs, bool no_timing) {
    std::vector<StatsColumn> columns;
    for (const StatsColumn& c : kReportColumns)
        if (!no_timing || (std::string_view(c.key) != "ns_per_estimate" && std::string_view(c.key) != "efficiency"))
            columns.push_back(c);
    for (const json& run : runs) {
        if (!run.contains("results")) continue;
        const json& in = run["inputs"];
        out << "## " << in.value("map", "?") << " (" << in.value("width", int64_t{0}) << "x"
            << in.value("height", int64_t{0}) << "), alpha " << number(in.value("alpha", 1.0), "%.3g")
            << "\n\n| bsdf | technique |";
        for (const StatsColumn& c : columns) out << " " << c.heading << " |";
        out << "\n|---|---|";
        for (size_t i = 0; i < columns.size(); ++i) out << "---:|";
        out << "\n";
        for (const json& r : run["results"]) {
            out << "| " << r["bsdf"].get<std::string>() << " | " << r["technique"].get<std::string>() << " |";
            for (const StatsColumn& c : columns) out << " " << cell_text(r[c.key].get<double>(), c) << " |";
            out << "\n";
        }
        out << "\n";
    }
}

}  // namespace

void write_markdown(std::ostream& out, const std::vector<json>& runs, const MarkdownOptions& options) {
    if (runs.empty()) throw std::invalid_argument("write_markdown: no runs");
    const auto [techniques, cases] = collect_cases(runs);
    write_intro(out, runs, options.title, options.command);
    write_summary(out, techniques, cases);
    write_optimal(out, cases);
    write_strength(out, runs);
    write_allocation(out, runs, options.no_timing);
    write_plots(out, runs, options.plots);
    write_tables(out, runs, options.no_timing);
}

}  // namespace envmis
