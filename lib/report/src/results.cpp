#include "envmis/report/results.h"

#include <cstdio>
#include <stdexcept>

namespace envmis {
namespace {

struct Figure {
    const char* key;
    double TechniqueStats::*member;
};

constexpr Figure kFigures[] = {{"mean", &TechniqueStats::mean},
                               {"reference", &TechniqueStats::reference},
                               {"variance", &TechniqueStats::variance},
                               {"std_error", &TechniqueStats::std_error},
                               {"rel_mse", &TechniqueStats::rel_mse},
                               {"ns_per_estimate", &TechniqueStats::ns_per_estimate},
                               {"efficiency", &TechniqueStats::efficiency},
                               {"variance_ratio_vs_mis", &TechniqueStats::variance_ratio_vs_mis},
                               {"variance_ratio_worst", &TechniqueStats::variance_ratio_worst},
                               {"efficiency_ratio_vs_mis", &TechniqueStats::efficiency_ratio_vs_mis},
                               {"variance_ratio_log_std_error", &TechniqueStats::variance_ratio_log_std_error}};

// The headline first (per-point ratios to mis-balance: variance, its worst point, equal
// time), then the estimates against the reference, then the cost. compare --help and
// docs/compare.md define each.
constexpr StatsColumn kCompareColumns[] = {{"variance_ratio_vs_mis", "var/mis", 8, "%.3f", true},
                                           {"variance_ratio_worst", "worst", 8, "%.3f", true},
                                           {"efficiency_ratio_vs_mis", "eff/mis", 8, "%.3f", true},
                                           {"mean", "mean", 11, "%.5g"},
                                           {"std_error", "std_error", 10, "%.3g"},
                                           {"reference", "reference", 11, "%.5g"},
                                           {"rel_mse", "rel_mse", 10, "%.4g"},
                                           {"ns_per_estimate", "ns/est", 8, "%.1f", true}};

std::string padded(const std::string& text, int width) {
    return text.size() >= static_cast<size_t>(width) ? text : std::string(width - text.size(), ' ') + text;
}

}  // namespace

double stats_figure(const TechniqueStats& stats, std::string_view key) {
    for (const Figure& f : kFigures)
        if (key == f.key) return stats.*f.member;
    throw std::invalid_argument("no figure '" + std::string(key) + "' in TechniqueStats");
}

std::span<const StatsColumn> compare_columns() { return kCompareColumns; }

std::string cell_text(double value, const StatsColumn& column) {
    if (column.dash && !(value > 0)) return padded("-", column.width);
    char text[64];
    std::snprintf(text, sizeof text, column.format, value);
    return padded(text, column.width);
}

std::string headings_text(std::span<const StatsColumn> columns) {
    std::string line;
    for (const StatsColumn& c : columns) line.append(" ").append(padded(c.heading, c.width));
    return line;
}

std::string cells_text(const TechniqueStats& stats, std::span<const StatsColumn> columns) {
    std::string line;
    for (const StatsColumn& c : columns) line.append(" ").append(cell_text(stats_figure(stats, c.key), c));
    return line;
}

nlohmann::json stats_json(const TechniqueStats& stats, StatsDetail detail) {
    nlohmann::json j = {{"technique", stats.technique.name()}, {"estimates", stats.estimates}};
    if (detail == StatsDetail::sweep) {
        for (const char* key : kSweepFigures) j[key] = stats_figure(stats, key);
        return j;
    }
    for (const Figure& f : kFigures) j[f.key] = stats.*f.member;
    j["ill_conditioned_points"] = stats.ill_conditioned_points;
    j["point_variances"] = stats.point_variances;
    j["point_variance_rel_se"] = stats.point_variance_rel_se;
    return j;
}

std::string csv_header(std::span<const char* const> keys) {
    std::string header;
    for (const char* key : keys) {
        if (!header.empty()) header += ',';
        header += key;
    }
    return header;
}

std::string csv_header(std::initializer_list<const char*> keys) {
    return csv_header(std::span<const char* const>(keys.begin(), keys.size()));
}

void write_csv_fields(std::ostream& out, const TechniqueStats& stats, std::span<const char* const> keys) {
    for (size_t i = 0; i < keys.size(); ++i) out << (i ? "," : "") << stats_figure(stats, keys[i]);
}

void print_stats_table(std::ostream& out, const Comparison& comparison) {
    char line[64];
    std::snprintf(line, sizeof line, "%-10s %-17s", "bsdf", "technique");
    out << line << headings_text(compare_columns()) << "\n";
    for (const BsdfComparison& b : comparison.bsdfs)
        for (const TechniqueStats& t : b.techniques) {
            std::snprintf(line, sizeof line, "%-10s %-17s", b.bsdf.name().c_str(), t.technique.name().c_str());
            out << line << cells_text(t, compare_columns()) << "\n";
        }
}

void write_stats_csv(std::ostream& out, const Comparison& comparison, const std::string& map, uint32_t spp,
                     uint64_t seed, const std::function<float(const Bsdf&)>& alpha_of) {
    out << csv_header({"map", "alpha", "spp", "seed", "points", "bsdf", "technique"}) << ','
        << csv_header(kCompareFigures) << '\n';
    for (const BsdfComparison& b : comparison.bsdfs)
        for (const TechniqueStats& t : b.techniques) {
            out << map << ',' << alpha_of(b.bsdf) << ',' << spp << ',' << seed << ',' << comparison.points_done << ','
                << b.bsdf.name() << ',' << t.technique.name() << ',';
            write_csv_fields(out, t, kCompareFigures);
            out << '\n';
        }
}

nlohmann::json stats_results_json(const Comparison& comparison, const std::function<float(const Bsdf&)>& alpha_of) {
    nlohmann::json results = nlohmann::json::array();
    for (const BsdfComparison& b : comparison.bsdfs)
        for (const TechniqueStats& t : b.techniques) {
            nlohmann::json j = stats_json(t, StatsDetail::full);
            j["bsdf"] = b.bsdf.name();
            j["alpha"] = alpha_of(b.bsdf);
            results.push_back(std::move(j));
        }
    return results;
}

}  // namespace envmis
