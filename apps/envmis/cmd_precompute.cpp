// envmis precompute IN -o OUT.envmis: build a map's sampler and save it as a table.
#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>

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
    const std::vector<float> p = map.density(), q = EnvMap(rounded, map.options(), &interrupted()).density();
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
    uint32_t bins = 0;  // K = g^2 normal bins (sampling/binned.h); 0: a single density
    uint32_t cell_columns = 0;
};

void add_precompute_flags(CLI::App& sub, PrecomputeArgs& args) {
    sub.add_option("input", args.input, "HDR image (EXR, .hdr, .pfm, TIFF, ...)")->required();
    sub.add_option("-o,--output", args.output, "Table file to write (.envmis)")->required();
    sub.add_flag("--compact", args.compact,
                 "Store the radiance in RGBE (4 bytes/texel instead of 16; density rebuilt on load); prints the error");
    CLI::Option* bins =
        sub.add_option("--bins", args.bins,
                       "Normal-aware table: K = g x g bins of normals, each with its own compensation (binned.h); "
                       "the texels keep the plain density. --alpha auto (the default with --bins) chooses per bin "
                       "and lobe class, --alpha X fixes it for every bin, --no-compensate makes it 0")
            ->type_name("K")
            ->check(bins_validator());
    sub.add_option("--cell-columns", args.cell_columns, "With --bins: columns of the bins' cell grid (0: width / 32)")
        ->type_name("N")
        ->check(in_range(uint32_t{0}, uint32_t{4096}))
        ->needs(bins);
    add_map_flags(sub, args.map);
}

// `map` is loaded.map, or the plain map of `binned` (which then holds it).
void print_precompute(const PrecomputeArgs& args, const LoadedMap& loaded, const EnvMap& map,
                      const BinnedEnvMap* binned, double bins_ms, double write_ms) {
    std::cout << "envmis precompute: " << args.input << " -> " << args.output << "\n";
    print_summary(std::cout, loaded, map);
    if (binned) print_bins_cost(std::cout, *binned, bins_ms);
    if (args.compact) print_compact_error(std::cout, map);
    std::cout << std::fixed << std::setprecision(1) << "  time          load " << loaded.load_ms << " ms, build "
              << loaded.build_ms << " ms, write " << write_ms << " ms\n";
}

// The bins as the map flags ask: --alpha auto per bin (also without --alpha: the choice
// is what makes bins pay for every BSDF), --alpha X or --no-compensate (0) for every bin.
BinnedOptions binned_options(const PrecomputeArgs& args) {
    BinnedOptions o;
    o.bins_per_side = bins_per_side(args.bins);
    o.cell_columns = args.cell_columns;
    o.auto_alpha = (args.map.alpha_auto || !args.map.alpha_given) && !args.map.no_compensate;
    o.alpha = args.map.no_compensate ? 0.0f : args.map.alpha;
    return o;
}

// With --bins the table's texels hold the plain map, and the compensation the flags ask
// for goes into the bins.
void run_precompute_binned(const PrecomputeArgs& args) {
    MapFlags plain = args.map;
    plain.no_compensate = true;
    plain.alpha_auto = false;
    LoadedMap loaded = load_map(args.input, plain);
    if (loaded.from_table) throw std::runtime_error(args.input + ": is already a table; give an image");
    const auto build_start = std::chrono::steady_clock::now();
    std::optional<Progress> progress(std::in_place, "building bins", 1);
    const BinnedEnvMap binned(std::move(loaded.map), binned_options(args), &interrupted());
    progress.reset();
    const double bins_ms = milliseconds_since(build_start);
    loaded.bins = binned.layout();
    const auto start = std::chrono::steady_clock::now();
    write_table(args.output, binned, loaded.source, args.compact ? TableEncoding::compact : TableEncoding::full,
                &interrupted());
    print_precompute(args, loaded, binned.plain(), &binned, bins_ms, milliseconds_since(start));
}

void run_precompute(const PrecomputeArgs& args) {
    prepare_output(args.output);
    if (args.bins != 0) return run_precompute_binned(args);
    const LoadedMap loaded = load_map(args.input, args.map);
    if (loaded.from_table) throw std::runtime_error(args.input + ": is already a table; give an image");
    const auto start = std::chrono::steady_clock::now();
    write_table(args.output, loaded.map, loaded.source, args.compact ? TableEncoding::compact : TableEncoding::full,
                &interrupted());
    print_precompute(args, loaded, loaded.map, nullptr, 0, milliseconds_since(start));
}

}  // namespace

Subcommand add_precompute(CLI::App& app) {
    auto args = std::make_shared<PrecomputeArgs>();
    CLI::App* sub = app.add_subcommand("precompute", "Build the sampling table of an HDR map and save it");
    add_precompute_flags(*sub, *args);
    return {sub, [args] { run_precompute(*args); }};
}

}  // namespace envmis::cli
