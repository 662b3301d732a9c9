// Shared pieces of the `envmis` subcommands: the flags that choose how a map is built,
// loading a map from a table or an image, timing, progress and the summary printout.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <ostream>
#include <string>

#include <CLI/CLI.hpp>

#include "envmis/sampling/envmap.h"
#include "envmis/study/comparison/alpha.h"
#include "envmis/table/table.h"

namespace envmis::cli {

// How to build an EnvMap from an image (ignored for tables, which record their own).
struct MapFlags {
    bool no_compensate = false;
    float alpha = 1.0f;
    bool alpha_auto = false;  // --alpha auto: choose_alpha() (alpha.h) picks it, map-wide
    std::string colorspace;   // input colour space; empty: from the file
    std::string working_space = "lin_rec709";
    std::string axes = "z-up";
    std::string mapping = "equirect";  // or "equal-area" (a square image)
};
void add_map_flags(CLI::App& app, MapFlags& flags);

// A map ready to sample, and where it came from.
struct LoadedMap {
    EnvMap map;
    TableSource source;
    bool from_table = false;
    std::string format;          // "envmis table", "openexr", "hdr", ...
    uint32_t table_version = 0;  // the table file's format version
    bool mapped = false;         // the map borrows its radiance from a mapping of the table file
    uint32_t channels = 3;
    double load_ms = 0, build_ms = 0;
    std::optional<AlphaChoice> alpha_choice = {};  // with --alpha auto, for an image
};

// Reads a table (recognised by its magic) or loads an image and builds its map.
LoadedMap load_map(const std::string& path, const MapFlags& flags);

// The summary that precompute and info print.
void print_summary(std::ostream& out, const LoadedMap& loaded);

double milliseconds_since(std::chrono::steady_clock::time_point start);

// This process's resident memory, now and at its peak, with the share of anonymous
// memory and of mapped files' pages; empty where the system does not say (not Linux).
std::string resident_memory();

// Ctrl-C (SIGINT) and SIGTERM set a flag that long loops check, so that they stop
// cleanly: `compare` reports what is done, writers throw and remove their temporary
// files. A second signal ends the process at once.
void install_interrupt_handler();
const std::atomic<bool>& interrupted();
// Throws std::runtime_error("interrupted") once a signal has arrived.
void throw_if_interrupted();

// Progress on stderr, only when stderr is a terminal: "label  42%".
class Progress {
public:
    Progress(std::string label, uint64_t total);
    ~Progress();
    void update(uint64_t done);

private:
    std::string label_;
    uint64_t total_;
    int shown_ = -1;
    bool enabled_;
};

// Each subcommand adds itself to the app, with the function that runs it once parsed.
struct Subcommand {
    CLI::App* app;
    std::function<void()> run;
};
Subcommand add_precompute(CLI::App& app);
Subcommand add_info(CLI::App& app);
Subcommand add_sample(CLI::App& app);
Subcommand add_visualize(CLI::App& app);
Subcommand add_bench(CLI::App& app);
Subcommand add_convert(CLI::App& app);
Subcommand add_compare(CLI::App& app);
Subcommand add_report(CLI::App& app);

}  // namespace envmis::cli
