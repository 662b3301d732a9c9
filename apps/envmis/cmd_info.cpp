// envmis info FILE: describe a table or an HDR image.
#include <chrono>
#include <iomanip>
#include <iostream>
#include <memory>

#include "cli.h"

namespace envmis::cli {

namespace {

// The arguments of `envmis info`.
struct InfoArgs {
    std::string input;
    BuildRequest map;  // the map flags
};

// Rebuilds a binned table's bins (as a renderer loading it would), to check that they
// fit the map and to say what they cost.
void print_bins_rebuild(const InfoArgs& args, const LoadedMap& loaded) {
    const auto start = std::chrono::steady_clock::now();
    try {
        const BinnedEnvMap binned(loaded.map, *loaded.bins);
        print_bins_cost(std::cout, binned, milliseconds_since(start));
    } catch (const std::invalid_argument& e) {
        throw TableError(args.input + ": bins do not fit the map: " + e.what());
    }
}

void print_info(const InfoArgs& args, const LoadedMap& loaded) {
    std::cout << printable(args.input) << ": ";
    if (loaded.from_table)
        std::cout << "envmis table, format version " << loaded.table_version
                  << (loaded.mapped ? ", radiance used in place from a mapping of the file" : "")
                  << (loaded.compact ? ", compact (RGBE radiance, 4 bytes/texel on disk, decoded into memory)" : "")
                  << "\n";
    else
        std::cout << "image, " << loaded.channels << " channels\n";
    print_summary(std::cout, loaded);
    if (loaded.bins) print_bins_rebuild(args, loaded);
    std::cout << std::fixed << std::setprecision(1) << "  time          load " << loaded.load_ms << " ms"
              << (loaded.from_table ? " (includes rebuilding the sampler)" : "") << ", build " << loaded.build_ms
              << " ms\n";
    if (const std::string memory = resident_memory(); !memory.empty())
        std::cout << "  process       " << memory << "\n";
}

void run_info(const InfoArgs& args) { print_info(args, load_map(args.input, args.map)); }

}  // namespace

Subcommand add_info(CLI::App& app) {
    auto args = std::make_shared<InfoArgs>();
    CLI::App* sub = app.add_subcommand("info", "Describe a table file, or an HDR map and the sampler it would give");
    sub->add_option("input", args->input, "Table (.envmis) or HDR image")->required();
    add_map_flags(*sub, args->map);
    add_threads_flag(*sub);
    return {sub, [args] { run_info(*args); }};
}

}  // namespace envmis::cli
