// envmis precompute IN -o OUT.envmis: build a map's sampler and save it as a table; with
// several inputs or a folder, every map into the folder OUT, in parallel (library.h).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <type_traits>
#include <vector>

#include "cli.h"
#include "envmis/build/env_map.h"
#include "envmis/cpu.h"
#include "library.h"

namespace envmis::cli {
namespace {

// What a compact table changes: the largest relative error of a pixel's luminance,
// and the total variation distance between the two sampling densities (half the
// summed absolute difference of texel probabilities; 0 = identical, 1 = disjoint).
void print_compact_error(std::ostream& out, const EnvMap& map) {
    const RgbImage rounded = rgbe_round(map.radiance());
    double worst = 0;
    for (size_t i = 0; i < rounded.pixels.size(); ++i) {
        const double l = luminance(map.radiance().pixels[i], map.options().luma);
        if (l > 0) worst = std::max(worst, std::abs(luminance(rounded.pixels[i], map.options().luma) - l) / l);
    }
    const std::vector<float> p = map.density(), q = build_env_map(rounded, map.options(), &interrupted()).density();
    double sum_p = 0, sum_q = 0, distance = 0;
    for (size_t i = 0; i < p.size(); ++i) sum_p += p[i], sum_q += q[i];
    for (size_t i = 0; i < p.size(); ++i) distance += std::abs(p[i] / sum_p - q[i] / sum_q);
    out << std::setprecision(3) << "  compact       RGBE radiance, 4 bytes/texel on disk (full: 16): luminance within "
        << 100 * worst << "%, sampling density total variation " << 0.5 * distance << "\n";
}

// The arguments of `envmis precompute`.
struct PrecomputeArgs {
    std::vector<std::string> inputs;
    std::string output, summary;
    BuildRequest map;  // the map flags
    bool compact = false;
    uint32_t bins = 0;  // K = g^2 normal bins (sampling/binned.h); 0: a single density
    uint32_t cell_columns = 0;
    float bin_cost = BinnedOptions{}.cost;
    uint32_t jobs = 1;
    bool force = false, recursive = false;
};

void add_precompute_flags(CLI::App& sub, PrecomputeArgs& args) {
    sub.add_option("input", args.inputs,
                   "HDR images (EXR, .hdr, .pfm, TIFF, ...) or folders of them; one image: OUT is the table, "
                   "several or a folder: OUT is a folder receiving OUT/<stem>.envmis each")
        ->required();
    sub.add_option("-o,--output", args.output, "Table file to write (.envmis), or with several inputs a folder")
        ->required()
        ->check(non_empty());
    sub.add_flag("--compact", args.compact,
                 "Store the radiance in RGBE (4 bytes/texel instead of 16; density rebuilt on load); prints the error");
    CLI::Option* bins =
        sub.add_option("--bins", args.bins,
                       "Normal-aware table: K = g x g bins of normals, each with its own compensation (binned.h); "
                       "the texels keep the plain density. --alpha auto (the default with --bins) chooses per bin "
                       "and lobe class, --alpha X fixes it for every bin, --no-compensate makes it 0")
            ->type_name("K")
            ->check(bins_validator());
    add_cell_columns_flag(sub, args.cell_columns)->needs(bins);
    add_bin_cost_flag(sub, args.bin_cost)->needs(bins);
    add_jobs_flag(sub, args.jobs);
    sub.add_flag("--force", args.force,
                 "Library mode: rebuild every table, also those up to date (same source bytes and options)");
    sub.add_flag("--recursive", args.recursive, "Library mode: also the images in subfolders of a folder input");
    sub.add_option("--summary", args.summary,
                   "Library mode: the JSON summary of every map's result (default: OUT/summary.json)")
        ->check(non_empty());
    add_map_flags(sub, args.map);
}

// The request the flags make (build.h), with --bins, --cell-columns and --compact.
BuildRequest precompute_request(const PrecomputeArgs& args) {
    BuildRequest request = args.map;
    request.bins = args.bins;
    request.cell_columns = args.cell_columns;
    request.bin_cost = args.bin_cost;
    request.compact = args.compact;
    return request;
}

// What a written table's summary entry records of it: its size and options, every
// statistic of the build (visit_stats_fields) and the times.
nlohmann::json table_details(const LoadedMap& loaded, const EnvMap& map, double write_ms) {
    nlohmann::json details = {
        {"width", map.width()},
        {"height", map.height()},
        {"compensated", map.options().compensation.enabled},
        {"alpha", map.options().compensation.alpha},
        {"complete", map.complete()},
        {"bins", loaded.bins ? loaded.bins->bins_per_side * loaded.bins->bins_per_side : 0},
        {"diffuse_bins", loaded.bins ? loaded.bins->diffuse_bins_per_side * loaded.bins->diffuse_bins_per_side : 0},
        {"load_ms", loaded.load_ms},
        {"build_ms", loaded.build_ms},
        {"write_ms", write_ms}};
    visit_stats_fields(map.stats(), [&details](const char* name, const auto& value) {
        using Value = std::decay_t<decltype(value)>;
        if constexpr (std::is_same_v<Value, BadPixels>)
            details[name] = {{"nan", value.nan}, {"infinite", value.infinite}, {"negative", value.negative}};
        else
            details[name] = value;
    });
    return details;
}

// `map` is loaded.map, or the plain map of `binned` (which then holds it).
void print_precompute(std::ostream& out, const PrecomputeArgs& args, const LibraryItem& item, const LoadedMap& loaded,
                      const EnvMap& map, const BinnedEnvMap* binned, double bins_ms, double write_ms) {
    out << "envmis precompute: " << item.input.string() << " -> " << item.output.string() << "\n";
    print_summary(out, loaded, map);
    if (binned) print_bins_cost(out, *binned, bins_ms);
    if (args.compact) print_compact_error(out, map);
    const uint32_t threads = usable_cores();
    out << std::fixed << std::setprecision(1) << "  time          load " << loaded.load_ms << " ms, build "
        << loaded.build_ms << " ms, write " << write_ms << " ms (at most " << threads
        << (threads == 1 ? " thread)\n" : " threads)\n");
}

// A map's peak resident memory per texel in precompute, above the process's own: a
// full table's is kBuildPeak (cli.h); a compact one's about 54 (the source map, the
// rounded one and the error report's), rounded up.
constexpr uint64_t kFullPeak = kBuildPeak, kCompactPeak = 64;

// One map: its table written, what precompute prints on `out` and its notices on
// `notes`, and its summary details. With --bins the table's texels hold the plain map,
// and the compensation the flags ask for goes into the bins.
nlohmann::json precompute_one(const PrecomputeArgs& args, const LibraryItem& item, std::ostream& out,
                              std::ostream& notes, bool show_progress) {
    if (looks_like_table(item.input)) {
        read_table_header(item.input);  // a broken table says what is wrong with it
        throw std::runtime_error(item.input.string() + ": is already a table; give an image");
    }
    check_map_memory(item.input, args.compact ? kCompactPeak : kFullPeak);
    // A line per stage ("reading   0%", then "reading 100%" as the next starts), the
    // table's writing last.
    std::optional<Progress> progress;
    const auto next_stage = [&](std::string_view stage) {
        if (!show_progress) return;
        if (progress) progress->update(1);
        progress.emplace(std::string(stage), 1);
    };
    BuiltMap built = build_map(item.input, precompute_request(args), &interrupted(), next_stage);
    for (const std::string& notice : built.notices) notes << "note: " << printable(notice) << "\n";
    const LoadedMap loaded = loaded_map(built);
    const BinnedEnvMap* binned = built.binned ? &*built.binned : nullptr;
    const EnvMap& map = binned ? binned->radiance_map() : loaded.map;
    const TableEncoding encoding = args.compact ? TableEncoding::compact : TableEncoding::full;
    next_stage("writing");
    const auto start = std::chrono::steady_clock::now();
    if (binned)
        write_table(item.output, *binned, loaded.source, encoding, &interrupted());
    else
        write_table(item.output, map, loaded.source, encoding, &interrupted());
    const double write_ms = milliseconds_since(start);
    if (progress) progress->update(1);
    progress.reset();
    print_precompute(out, args, item, loaded, map, binned, built.bins_ms, write_ms);
    nlohmann::json details = table_details(loaded, map, write_ms);
    if (binned) details["bins_build_ms"] = built.bins_ms;
    return details;
}

// True where `output` is a table of the source whose bytes hash to `hash`, built with
// `options`; only its header is read. A table that cannot be read is not up to date.
bool up_to_date(const std::filesystem::path& output, uint64_t hash, const std::string& options) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(output, ec)) return false;
    try {
        const TableHeader header = read_table_header(output);
        return header.source.content_hash == hash && header.source.build_options == options;
    } catch (const TableError&) {
        return false;
    }
}

// Each map of `items` on the pool of --jobs, skipping those up to date, with a summary.
void precompute_items(const PrecomputeArgs& args, const std::vector<LibraryItem>& items,
                      const std::filesystem::path& summary) {
    for (const LibraryItem& item : items) prepare_output(item.output);
    const std::string options = canonical_options(precompute_request(args));
    const auto matches = [&](const std::filesystem::path& output, uint64_t hash) {
        return up_to_date(output, hash, options);
    };
    run_library(items, {"precompute", args.jobs, summary, args.compact ? kCompactPeak : kFullPeak, matches},
                [&](const LibraryItem& item, uint64_t hash) {
                    MapOutcome outcome;
                    if (!args.force && up_to_date(item.output, hash, options)) {
                        outcome.status = "up-to-date";
                        outcome.printed = "envmis precompute: " + item.output.string() + " is up to date\n";
                        return outcome;
                    }
                    std::ostringstream out, notes;
                    outcome.details = precompute_one(args, item, out, notes, false);
                    outcome.status = "written";
                    outcome.printed = out.str();
                    outcome.notes = notes.str();
                    return outcome;
                });
}

void run_precompute(const PrecomputeArgs& args) {
    std::error_code ec;
    if (args.inputs.size() == 1 && !std::filesystem::is_directory(args.inputs.front(), ec)) {
        const LibraryItem item{args.inputs.front(), args.output};
        if (!args.summary.empty()) return precompute_items(args, {item}, args.summary);
        check_outputs({item.input}, {{"-o", item.output}});
        prepare_output(args.output);
        precompute_one(args, item, std::cout, std::cerr, true);
        return;
    }
    // Several inputs or a folder: each map to OUT/<stem>.envmis.
    const std::filesystem::path dir = args.output;
    const std::vector<LibraryItem> items =
        plan_outputs(expand_inputs(args.inputs, args.recursive, false), dir, ".envmis");
    if (std::filesystem::exists(dir, ec) && !std::filesystem::is_directory(dir, ec))
        throw std::runtime_error(dir.string() + ": exists and is not a folder (with several inputs, -o is a folder)");
    std::filesystem::create_directories(dir);
    precompute_items(args, items, args.summary.empty() ? dir / "summary.json" : std::filesystem::path(args.summary));
}

}  // namespace

Subcommand add_precompute(CLI::App& app) {
    auto args = std::make_shared<PrecomputeArgs>();
    CLI::App* sub = app.add_subcommand("precompute", "Build the sampling table of an HDR map and save it");
    add_precompute_flags(*sub, *args);
    add_threads_flag(*sub);
    return {sub, [args] { run_precompute(*args); }};
}

}  // namespace envmis::cli
