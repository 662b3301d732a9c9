// Library mode of `envmis precompute` and `envmis compare`: many maps at once, on a
// bounded pool of jobs, with one progress bar, outputs that are up to date skipped, and
// one summary (JSON) of every map's result or error, so that one bad file does not stop
// the rest.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

namespace envmis::cli {

// The files that inputs name, in order: a file as given (missing ones too: their run
// fails and says so); a folder, each regular file in it whose extension OpenImageIO
// reads (and, with `tables`, each .envmis table), sorted by name, subfolders too with
// `recursive`. Throws naming a folder that cannot be read or that holds no such file.
std::vector<std::filesystem::path> expand_inputs(const std::vector<std::string>& inputs, bool recursive, bool tables);

// An input of a library run and the file its result goes to.
struct LibraryItem {
    std::filesystem::path input, output;
};

// Each input's output, `dir`/<stem><extension>. Throws, before any work, naming both
// inputs where two would write the same file ("a.hdr and b/a.exr: both would write
// out/a.envmis").
std::vector<LibraryItem> plan_outputs(const std::vector<std::filesystem::path>& inputs,
                                      const std::filesystem::path& dir, const std::string& extension);

inline constexpr uint32_t kMaxJobs = 1024;
// --jobs N: maps run at once, 1 to kMaxJobs (default: the core count).
CLI::Option* add_jobs_flag(CLI::App& app, uint32_t& jobs);

// A hash as tables and summaries print it: 16 lower-case hex digits.
std::string hash_text(uint64_t hash);

// What one map's job reports: "written" or "up-to-date", what it would have printed on
// standard output and its notices for standard error ("note: FILE: ..." lines; both
// printed whole as the map finishes, never interleaved with another's or the progress
// bar), and the figures for the summary.
struct MapOutcome {
    std::string status;
    std::string printed;
    std::string notes;
    nlohmann::json details = nlohmann::json::object();
};
// A map's job, given its input's hash (io::hash_file); throws to fail (the message names the file).
using MapJob = std::function<MapOutcome(const LibraryItem&, uint64_t source_hash)>;

struct LibraryRun {
    std::string command;  // "precompute" or "compare": the progress bar's label and the summary's
    uint32_t jobs = 1;
    std::filesystem::path summary;  // the summary to write
    // A map's job's peak memory per texel of its map (the header's width x height): what
    // the memory check below expects each map to take.
    uint64_t bytes_per_texel = 0;
    // True where `output` holds the results of the input whose bytes hash to `hash` with
    // this run's options (what lets a map be skipped as up to date).
    std::function<bool(const std::filesystem::path& output, uint64_t hash)> up_to_date;
};

// Runs `job` over `items` on min(jobs, items) threads, each map once, with one progress
// bar (maps done of the total) on stderr. Maps run at once only while their needs
// (bytes_per_texel x texels) fit together in the memory available (available_memory())
// when none ran; a map that does not fit waits for running ones to finish, and one that
// does not fit alone fails with check_memory's message ("FILE: needs N MB of memory, more
// than the M MB available"). An estimate, from the headers alone: other processes' use
// changes under it, and bytes_per_texel is measured, not a bound. A map that fails is reported at once on stderr
// ("envmis: FILE: problem") and in the summary, and the others go on. An earlier run's
// output for a map that fails is removed, and the message and summary say so, where it
// is shown not to match: the input could not be read, or it hashes to other bytes or the
// options differ (run.up_to_date). An output that matches stays, whatever failed (memory,
// a full disk, a later output of the same map). Writes the summary
// atomically: per map its input and output paths, status ("written", "up-to-date",
// "failed", or "interrupted" and "not started" after Ctrl-C), error, seconds, source hash,
// input bytes and the job's details. Then throws Interrupted once a signal arrived (the
// maps written are whole, the summary says which) or a runtime_error counting the failed
// maps, which main reports with exit status 1.
void run_library(const std::vector<LibraryItem>& items, const LibraryRun& run, const MapJob& job);

}  // namespace envmis::cli
