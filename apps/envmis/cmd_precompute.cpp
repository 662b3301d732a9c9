// envmis precompute IN -o OUT.envmis: build a map's sampler and save it as a table.
#include <chrono>
#include <iomanip>
#include <iostream>
#include <memory>

#include "cli.h"

namespace envmis::cli {

Subcommand add_precompute(CLI::App& app) {
    struct Args {
        std::string input, output;
        MapFlags map;
    };
    auto args = std::make_shared<Args>();
    CLI::App* sub = app.add_subcommand("precompute", "Build the sampling table of an HDR map and save it");
    sub->add_option("input", args->input, "HDR image (EXR, .hdr, .pfm, TIFF, ...)")->required();
    sub->add_option("-o,--output", args->output, "Table file to write (.envmis)")->required();
    add_map_flags(*sub, args->map);
    return {sub, [args] {
                const LoadedMap loaded = load_map(args->input, args->map);
                if (loaded.from_table) throw std::runtime_error(args->input + ": is already a table; give an image");
                const auto start = std::chrono::steady_clock::now();
                write_table(args->output, loaded.map, loaded.source);
                const double write_ms = milliseconds_since(start);
                std::cout << "envmis precompute: " << args->input << " -> " << args->output << "\n";
                print_summary(std::cout, loaded);
                std::cout << std::fixed << std::setprecision(1) << "  time          load " << loaded.load_ms
                          << " ms, build " << loaded.build_ms << " ms, write " << write_ms << " ms\n";
            }};
}

}  // namespace envmis::cli
