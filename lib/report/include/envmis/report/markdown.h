// `envmis report`'s reader and writer: the JSON of `envmis compare` runs (one per map) in,
// one Markdown report out: every technique's variance relative to balance MIS per (map,
// BSDF) case and its geometric mean over the cases, the technique that gains most,
// optimal against balance weights, the compensation-strength and allocation sweeps,
// links to the plots, and each run's full table.
//
// The reader checks every field the writer uses for its presence and type before any of
// it is used, so that a file that is not compare's (edited, truncated, another tool's) is
// refused naming the file and the field; the writer then reads nothing unchecked
// (tests/fuzz/report_fuzz.cpp holds the pair to that).
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace envmis {

// The results of one compare run in `text` (its JSON), named `name` in errors; empty for
// the summary of a library run (compare --out-dir DIR writes it beside the maps' JSON, so
// DIR/*.json holds it). Figures compare wrote as null (not finite) read as NaN. Throws
// std::runtime_error "NAME: FIELD: expected TYPE" for a field of the wrong type or
// missing, "NAME: not JSON (...)" and "NAME: not the JSON of envmis compare ...".
std::optional<nlohmann::json> parse_results(std::string_view text, const std::string& name);

struct MarkdownOptions {
    std::string title = "envmis results";
    std::string command;     // the command that made the results, quoted in the report
    std::string plots;       // folder, relative to the report, of each map's plots; empty: none
    bool no_timing = false;  // leave out what measured time decides (ns/estimate, efficiency, allocation)
};

// The report of `runs` (each one parse_results gave; at least one).
void write_markdown(std::ostream& out, const std::vector<nlohmann::json>& runs, const MarkdownOptions& options);

}  // namespace envmis
