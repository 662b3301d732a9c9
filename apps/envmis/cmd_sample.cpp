// envmis sample TABLE|HDR -n N [--normal X,Y,Z [--view X,Y,Z] [--lobe BSDF]]: directions
// drawn from a map's sampler (a binned table's: around a shading point), as CSV.
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <random>
#include <stdexcept>

#include "cli.h"
#include "envmis/build/atomic_file.h"
#include "envmis/study/shading/bsdf.h"

namespace envmis::cli {
namespace {

// Shortest text that reads back as exactly the same float.
void put(std::string& line, float v, char separator) {
    char buffer[32];
    const auto end = std::to_chars(buffer, buffer + sizeof buffer, v).ptr;
    line.append(buffer, end);
    line += separator;
}

// `sample(u0, u1, choice)` returns one sample; choice picks a binned table's bin.
template <class Sample>
void write_samples(std::ostream& out, Sample&& sample, uint64_t n, uint64_t seed) {
    // u = 24 random bits per dimension, the float grid [0,1) that renderers use.
    std::mt19937_64 rng(seed);
    auto uniform = [&rng] { return static_cast<float>(rng() >> 40) * 0x1p-24f; };
    Progress progress("sampling", n);
    std::string line;
    out << "u,v,x,y,z,pdf\n";
    for (uint64_t i = 0; i < n; ++i) {
        const float u0 = uniform(), u1 = uniform();
        const EnvSample s = sample(u0, u1, uniform);
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
    BuildRequest map;                            // the map flags
    std::string normal, view, lobe = "lambert";  // a binned table's shading point; normal empty: none
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
    sub.add_option("-o,--output", args.output, "CSV file to write (default: standard output)")->check(non_empty());
    CLI::Option* normal =
        sub.add_option("--normal", args.normal,
                       "A binned table's shading normal (world frame; normalised), required for one: each sample "
                       "picks one of the bins around it (a third random number) and reports that bin's pdf")
            ->type_name("X,Y,Z")
            ->check(direction_validator());
    sub.add_option("--view", args.view,
                   "Towards the viewer, for a glossy --lobe: its class's bins follow the mirror direction "
                   "(default: the normal)")
        ->type_name("X,Y,Z")
        ->check(direction_validator())
        ->needs(normal);
    sub.add_option("--lobe", args.lobe,
                   "The shading point's BSDF, which picks the lobe class: lambert, phong:N or ggx:A")
        ->type_name("BSDF")
        ->capture_default_str()
        ->check(bsdf_validator())
        ->needs(normal);
    add_map_flags(sub, args.map);
}

// Writes the samples of the map, or of a binned table's bins around the shading point.
void write_map_samples(std::ostream& out, const SampleArgs& args, const LoadedMap& loaded, const BinnedEnvMap* binned) {
    if (!binned) {
        const EnvMapView view = loaded.map.view();
        write_samples(
            out,
            [&](float u0, float u1, auto&&) {
                return view.sample({u0, u1});
            },
            args.count, args.seed);
        return;
    }
    const BinnedEnvMapView view = binned->view();
    const Vec3 normal = *parse_direction(args.normal);  // the flags' validators have accepted them
    const Vec3 wo = args.view.empty() ? normal : *parse_direction(args.view);
    const uint32_t lobe = binned->lobe_class(Bsdf::parse(args.lobe).phong_exponent());
    const LobeAxis axis = lobe_axis(lobe, normal, wo);
    write_samples(
        out,
        [&](float u0, float u1, auto&& uniform) {
            return view.sample(axis, lobe, uniform(), {u0, u1});
        },
        args.count, args.seed);
}

void run_sample(const SampleArgs& args) {
    check_outputs({args.input}, {{"-o", args.output}});
    if (!args.output.empty()) prepare_output(args.output);
    const LoadedMap loaded = load_map(args.input, args.map);
    if (loaded.bins && args.normal.empty())
        throw std::runtime_error(args.input +
                                 ": a binned table samples per shading point: give --normal X,Y,Z (and --view, "
                                 "--lobe for a glossy BSDF)");
    if (!loaded.bins && !args.normal.empty())
        throw std::runtime_error(args.input + ": --normal samples a binned table's bins, and this " +
                                 (loaded.from_table ? "table has none" : "is an image") +
                                 " (envmis precompute --bins K makes one)");
    std::optional<BinnedEnvMap> binned;
    if (loaded.bins) binned.emplace(EnvMap(loaded.map), *loaded.bins);
    const BinnedEnvMap* bins = binned ? &*binned : nullptr;
    if (args.output.empty()) {
        write_map_samples(std::cout, args, loaded, bins);  // main checks standard output
    } else {
        write_file_atomically(args.output, [&](std::ostream& out) { write_map_samples(out, args, loaded, bins); });
    }
}

}  // namespace

Subcommand add_sample(CLI::App& app) {
    auto args = std::make_shared<SampleArgs>();
    CLI::App* sub = app.add_subcommand(
        "sample",
        "Draw directions from a map's sampler: CSV u,v,x,y,z,pdf (image point, world direction, solid-angle pdf)");
    add_sample_flags(*sub, *args);
    add_threads_flag(*sub);
    return {sub, [args] { run_sample(*args); }};
}

}  // namespace envmis::cli
