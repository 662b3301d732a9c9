// envmis info FILE: describe a table or an HDR image.
#include <iomanip>
#include <iostream>
#include <memory>

#include "cli.h"

namespace envmis::cli {

Subcommand add_info(CLI::App& app) {
    struct Args {
        std::string input;
        MapFlags map;
    };
    auto args = std::make_shared<Args>();
    CLI::App* sub = app.add_subcommand("info", "Describe a table file, or an HDR map and the sampler it would give");
    sub->add_option("input", args->input, "Table (.envmis) or HDR image")->required();
    add_map_flags(*sub, args->map);
    return {sub, [args] {
                const LoadedMap loaded = load_map(args->input, args->map);
                std::cout << args->input << ": ";
                if (loaded.from_table)
                    std::cout << "envmis table, format version " << loaded.table_version
                              << (loaded.mapped ? ", radiance used in place from a mapping of the file" : "") << "\n";
                else
                    std::cout << "image, " << loaded.channels << " channels\n";
                print_summary(std::cout, loaded);
                std::cout << std::fixed << std::setprecision(1) << "  time          load " << loaded.load_ms << " ms"
                          << (loaded.from_table ? " (includes rebuilding the sampler)" : "") << ", build "
                          << loaded.build_ms << " ms\n";
                if (const std::string memory = resident_memory(); !memory.empty())
                    std::cout << "  process       " << memory << "\n";
            }};
}

}  // namespace envmis::cli
