// envmis sample TABLE|HDR -n N: directions drawn from a map's sampler, as CSV.
#include <fstream>
#include <iostream>
#include <memory>
#include <random>

#include "cli.h"
#include "envmis/table/atomic_file.h"

namespace envmis::cli {
namespace {

// Shortest text that reads back as exactly the same float.
void put(std::string& line, float v, char separator) {
    char buffer[32];
    const auto end = std::to_chars(buffer, buffer + sizeof buffer, v).ptr;
    line.append(buffer, end);
    line += separator;
}

void write_samples(std::ostream& out, const EnvMap& map, uint64_t n, uint64_t seed) {
    // u = 24 random bits per dimension, the float grid [0,1) that renderers use.
    std::mt19937_64 rng(seed);
    auto uniform = [&rng] { return static_cast<float>(rng() >> 40) * 0x1p-24f; };
    Progress progress("sampling", n);
    std::string line;
    out << "u,v,x,y,z,pdf\n";
    for (uint64_t i = 0; i < n; ++i) {
        const float u0 = uniform(), u1 = uniform();
        const EnvSample s = map.sample({u0, u1});
        line.clear();
        put(line, s.uv.x, ',');
        put(line, s.uv.y, ',');
        put(line, s.direction.x, ',');
        put(line, s.direction.y, ',');
        put(line, s.direction.z, ',');
        put(line, s.pdf, '\n');
        out << line;
        if ((i & 0xffff) == 0) {
            if (!out) return;  // the caller reports the stream's failure; no point in going on
            progress.update(i);
            throw_if_interrupted();
        }
    }
}

// The arguments of `envmis sample`.
struct SampleArgs {
    std::string input, output;
    uint64_t count = 1000;
    uint64_t seed = 1;
    MapFlags map;
};

// At most 2^40 samples (about 60 TB of CSV): far above any use, far below where a count
// typed wrong (or negative, read as 2^64 - n) would run for ever.
constexpr uint64_t kMaxSamples = uint64_t{1} << 40;

void add_sample_flags(CLI::App& sub, SampleArgs& args) {
    sub.add_option("input", args.input, "Table (.envmis) or HDR image")->required();
    sub.add_option("-n,--count", args.count, "Number of samples")
        ->capture_default_str()
        ->check(in_range(uint64_t{1}, kMaxSamples));
    sub.add_option("--seed", args.seed, "Random seed")->capture_default_str()->check(any_seed());
    sub.add_option("-o,--output", args.output, "CSV file to write (default: standard output)");
    add_map_flags(sub, args.map);
}

void run_sample(const SampleArgs& args) {
    if (!args.output.empty()) prepare_output(args.output);
    const LoadedMap loaded = load_map(args.input, args.map);
    if (args.output.empty()) {
        write_samples(std::cout, loaded.map, args.count, args.seed);  // main checks standard output
    } else {
        write_file_atomically(args.output,
                              [&](std::ostream& out) { write_samples(out, loaded.map, args.count, args.seed); });
    }
}

}  // namespace

Subcommand add_sample(CLI::App& app) {
    auto args = std::make_shared<SampleArgs>();
    CLI::App* sub = app.add_subcommand(
        "sample",
        "Draw directions from a map's sampler: CSV u,v,x,y,z,pdf (image point, world direction, solid-angle pdf)");
    add_sample_flags(*sub, *args);
    return {sub, [args] { run_sample(*args); }};
}

}  // namespace envmis::cli
