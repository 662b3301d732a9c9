// The output of `envmis compare`'s studies beyond one comparison (sweeps.h in
// envmis::study runs them): --alpha auto's choice, the alpha and allocation sweeps, as
// tables, JSON, CSV rows and plots.
#pragma once

#include <ostream>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "envmis/pictures/plot.h"
#include "envmis/study/comparison/alpha.h"
#include "envmis/study/comparison/sweeps.h"

namespace envmis::cli {

// The table of --alpha auto's candidates, per BSDF and over all, the choices marked
// (alpha_choice_json in envmis/report/inputs.h is its JSON).
void print_alpha_choice(std::ostream& out, const AlphaChoice& choice, std::span<const Bsdf> bsdfs);

// The table, then per BSDF the best alpha and, with `auto_alphas` (per BSDF, each one
// of the sweep's alphas), where --alpha auto's choice stands: its ratio over the
// best's and over alpha = 0's (when 0 was swept).
void print_alpha_sweep(std::ostream& out, const AlphaSweep& sweep, const std::vector<float>* auto_alphas);

// Per BSDF, the summary print_alpha_sweep() prints, as JSON objects.
nlohmann::json alpha_sweep_summary_json(const AlphaSweep& sweep, const std::vector<float>* auto_alphas);

// mis-balance-comp's ratio() against alpha, one series per BSDF, log y.
pictures::LinePlot alpha_sweep_plot(const AlphaSweep& sweep, const std::string& map_name);

// The table, then the best allocation per BSDF and technique.
void print_allocation_sweep(std::ostream& out, const AllocationSweep& sweep);

// Efficiency against n_env, one series per BSDF and technique, log y.
pictures::LinePlot allocation_plot(const AllocationSweep& sweep, const std::string& map_name);

// Every technique's var/mis per BSDF (groups: BSDFs, bars: techniques), log y, a
// reference line at 1.
pictures::BarChart variance_chart(const Comparison& comparison, const std::string& map_name);

// A sweep row as the JSON arrays hold it (the TechniqueStats through envmis/report/results.h).
nlohmann::json sweep_row_json(const SweepRow& row);
// The CSV header (no newline) and one row: `prefix` holds the leading map,spp,seed,points
// fields with their trailing comma.
std::string sweep_csv_header();
void write_sweep_csv_row(std::ostream& out, const std::string& prefix, const SweepRow& row);

}  // namespace envmis::cli
