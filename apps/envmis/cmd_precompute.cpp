// envmis precompute IN -o OUT.envmis: build a map's sampler and save it as a table.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>

#include "cli.h"

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
    const std::vector<float> p = map.density(), q = EnvMap(rounded, map.options()).density();
    double sum_p = 0, sum_q = 0, distance = 0;
    for (size_t i = 0; i < p.size(); ++i) sum_p += p[i], sum_q += q[i];
    for (size_t i = 0; i < p.size(); ++i) distance += std::abs(p[i] / sum_p - q[i] / sum_q);
    out << std::setprecision(3) << "  compact       RGBE radiance, 4 bytes/texel on disk (full: 16): luminance within "
        << 100 * worst << "%, sampling density total variation " << 0.5 * distance << "\n";
}

// The arguments of `envmis precompute`.
struct PrecomputeArgs {
    std::string input, output;
    MapFlags map;
    bool compact = false;
};

void add_precompute_flags(CLI::App& sub, PrecomputeArgs& args) {
    sub.add_option("input", args.input, "HDR image (EXR, .hdr, .pfm, TIFF, ...)")->required();
    sub.add_option("-o,--output", args.output, "Table file to write (.envmis)")->required();
    sub.add_flag("--compact", args.compact,
                 "Store the radiance in RGBE (4 bytes/texel instead of 16; density rebuilt on load); prints the error");
    add_map_flags(sub, args.map);
}

void print_precompute(const PrecomputeArgs& args, const LoadedMap& loaded, double write_ms) {
    std::cout << "envmis precompute: " << args.input << " -> " << args.output << "\n";
    print_summary(std::cout, loaded);
    if (args.compact) print_compact_error(std::cout, loaded.map);
    std::cout << std::fixed << std::setprecision(1) << "  time          load " << loaded.load_ms << " ms, build "
              << loaded.build_ms << " ms, write " << write_ms << " ms\n";
}

void run_precompute(const PrecomputeArgs& args) {
    const LoadedMap loaded = load_map(args.input, args.map);
    if (loaded.from_table) throw std::runtime_error(args.input + ": is already a table; give an image");
    const auto start = std::chrono::steady_clock::now();
    write_table(args.output, loaded.map, loaded.source, args.compact ? TableEncoding::compact : TableEncoding::full);
    print_precompute(args, loaded, milliseconds_since(start));
}

}  // namespace

Subcommand add_precompute(CLI::App& app) {
    auto args = std::make_shared<PrecomputeArgs>();
    CLI::App* sub = app.add_subcommand("precompute", "Build the sampling table of an HDR map and save it");
    add_precompute_flags(*sub, *args);
    return {sub, [args] { run_precompute(*args); }};
}

}  // namespace envmis::cli
