// The one writer of TechniqueStats (comparison.h) for every output of `envmis compare`
// and `envmis report`: its figures by key (the JSON key and CSV column), formatted as
// text-table cells, JSON objects and CSV fields.
#pragma once

#include <functional>
#include <initializer_list>
#include <ostream>
#include <span>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "envmis/study/comparison/comparison.h"

namespace envmis {

// A figure of TechniqueStats by key: mean, reference, variance, std_error, rel_mse,
// ns_per_estimate, efficiency, variance_ratio_vs_mis, variance_ratio_worst,
// efficiency_ratio_vs_mis, variance_ratio_log_std_error.
// Throws std::invalid_argument for another key.
double stats_figure(const TechniqueStats& stats, std::string_view key);

// The figures of compare's table and CSV, and those of the sweeps' tables, JSON and CSV.
inline constexpr const char* kCompareFigures[] = {"mean",
                                                  "reference",
                                                  "variance",
                                                  "std_error",
                                                  "rel_mse",
                                                  "ns_per_estimate",
                                                  "efficiency",
                                                  "variance_ratio_vs_mis",
                                                  "variance_ratio_worst",
                                                  "efficiency_ratio_vs_mis"};
inline constexpr const char* kSweepFigures[] = {"variance", "variance_ratio_vs_mis", "ns_per_estimate", "efficiency"};

// A column of a text table: the figure's key, its heading, its width (0: none) and its
// printf format for one double ("%.4g"); `dash` shows "-" for a value that is not > 0.
struct StatsColumn {
    const char* key;
    const char* heading;
    int width;
    const char* format;
    bool dash = false;
};

// The columns of compare's table: var/mis, worst, eff/mis, mean, std_error, reference,
// rel_mse, ns/est.
std::span<const StatsColumn> compare_columns();

// One value as a cell of `column`: formatted, right-aligned to its width.
std::string cell_text(double value, const StatsColumn& column);
// " heading" per column, each right-aligned to its width.
std::string headings_text(std::span<const StatsColumn> columns);
// " cell" per column, the figures of `stats`.
std::string cells_text(const TechniqueStats& stats, std::span<const StatsColumn> columns);

// How much of a TechniqueStats JSON holds: the sweeps' few figures, or all of it
// (per-point variances included).
enum class StatsDetail { sweep, full };
// {"technique", the figures, "estimates"} and, in full, the other figures,
// "ill_conditioned_points", "point_variances" and "point_variance_rel_se".
nlohmann::json stats_json(const TechniqueStats& stats, StatsDetail detail);

// The CSV header of `keys` ("mean,reference,...") and their fields ("0.5,0.49,...") in
// the stream's default format, no trailing comma.
std::string csv_header(std::initializer_list<const char*> keys);
std::string csv_header(std::span<const char* const> keys);
void write_csv_fields(std::ostream& out, const TechniqueStats& stats, std::span<const char* const> keys);

// compare's whole table (a row per BSDF and technique) and its CSV (header and rows);
// `alpha_of(bsdf)` is a BSDF's compensation strength.
void print_stats_table(std::ostream& out, const Comparison& comparison);
void write_stats_csv(std::ostream& out, const Comparison& comparison, const std::string& map, uint32_t spp,
                     uint64_t seed, const std::function<float(const Bsdf&)>& alpha_of);
// compare's JSON "results": one full object per BSDF and technique, with "bsdf" and "alpha".
nlohmann::json stats_results_json(const Comparison& comparison, const std::function<float(const Bsdf&)>& alpha_of);

}  // namespace envmis
