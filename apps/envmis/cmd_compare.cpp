// envmis compare IN: the variance study. Estimates direct lighting on analytic BSDFs with
// every technique at equal sample count and reports how much MIS compensation gains.
// With several inputs or a folder and --out-dir, every map's study, in parallel (library.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli.h"
#include "envmis/build/atomic_file.h"
#include "envmis/build/env_map.h"
#include "envmis/cpu.h"
#include "envmis/io/image_io.h"
#include "envmis/report/inputs.h"
#include "envmis/report/results.h"
#include "envmis/study/comparison/setup.h"
#include "envmis/study/comparison/sweeps.h"
#include "library.h"
#include "render.h"
#include "sweeps.h"

namespace envmis::cli {
namespace {

// The flags of `envmis compare`, as CLI11 fills them.
struct CompareArgs {
    std::vector<std::string> inputs;  // library mode with several, or a folder
    std::string out_dir, summary;
    uint32_t jobs = 1;
    bool force = false, recursive = false;
    bool show_progress = true;         // library mode shows one bar for all maps instead
    std::ostream* notes = &std::cerr;  // the map loader's notices (library mode: the map's own)
    const CLI::Option* threads_flag = nullptr;
    std::string input, bsdfs = "lambert,phong:50,ggx:0.1", techniques, normal, view, json, csv, images, plots,
                       alpha_sweep;
    RenderOptions render;
    uint32_t spp = 1024, points = 16, threads = 0, env_samples = 1, bsdf_samples = 1, allocation_sweep = 0;
    double view_angle = 0;  // degrees between each --points normal and its view
    uint32_t bins = 0;      // --bins; 0: kDefaultStudyBins where a -bins technique runs
    float bin_cost = BinnedOptions{}.cost;
    uint32_t cell_columns = 0;
    uint64_t seed = 1;
    bool exact = false;
    // Library mode: hash_text of the file given, the key results_up_to_date checks (for a
    // table, its own bytes: a table rebuilt with other options must run again). Empty: the
    // loaded map's source hash (for a table, the image it was built from).
    std::string source_hash;
    BuildRequest map;  // the map flags
};

// The limits of the count flags, checked by in_range (cli.h), which refuses a negative value
// instead of wrapping it; the study's own (setup.h) are Python's too.
constexpr uint32_t kMaxSpp = std::numeric_limits<uint32_t>::max();
constexpr uint32_t kMaxImageSpp = 65536, kMaxReferenceSpp = 1 << 20;

// Everything a run is set up with: the study's set-up, the map's name and hash, the
// sweeps' techniques and alphas.
struct Setup : CompareSetup {
    std::string map_name;
    std::string source_hash;  // inputs.source_hash of the JSON (CompareArgs::source_hash)
    std::vector<Technique> alpha_techniques, allocation_techniques;  // of the sweeps asked for
    std::vector<float> swept;                                        // --alpha-sweep
};

// What the run measured: the comparison, or the sweeps.
struct Outcome {
    std::optional<Comparison> comparison;
    std::optional<AlphaSweep> alpha;
    std::optional<AllocationSweep> allocation;
    size_t alphas_swept = 0;  // --alpha-sweep's values with auto's choices and 0
};

void add_study_flags(CLI::App& sub, CompareArgs& args) {
    sub.add_option("input", args.inputs,
                   "HDR image or table; several, or folders of them, with --out-dir (library mode)")
        ->required();
    sub.add_option("--bsdf", args.bsdfs,
                   "BSDFs: lambert[:ALBEDO], phong:N[:ALBEDO], ggx:ALPHA[:F0], comma-separated; ALBEDO and F0 grey, "
                   "0 to 1 (default 0.8; GGX's F0 0.95/0.64/0.54)")
        ->capture_default_str();
    sub.add_option(
        "--techniques", args.techniques,
        "Techniques, comma-separated (default: env,bsdf,mis-balance,mis-power,mis-balance-comp,mis-power-comp,"
        "mis-optimal-comp,mis-optimal-all,mis-{balance,power,optimal}-bins; all: env,bsdf,"
        "mis-{balance,power,optimal,var}[-comp],mis-{balance,optimal}-all,mis-{balance,power,optimal}-bins,"
        "one-sample[-comp])");
    sub.add_option("--bins", args.bins,
                   "Normal bins K = g*g (1 to 4096; default 121) of the -bins techniques, which sample the bin of "
                   "each point's normal; alpha per bin by exact variance unless --alpha X fixes it")
        ->type_name("K")
        ->check(bins_validator());
    add_bin_cost_flag(sub, args.bin_cost);
    add_cell_columns_flag(sub, args.cell_columns);
    sub.add_option("--spp", args.spp, "Estimates per shading point, BSDF and technique (1 to 2^32-1)")
        ->capture_default_str()
        ->check(in_range(uint32_t{1}, kMaxSpp));
    sub.add_option("--env-samples", args.env_samples, "Environment samples per MIS estimate (0 to 65536)")
        ->capture_default_str()
        ->check(in_range(uint32_t{0}, kMaxStudySamples));
    sub.add_option("--bsdf-samples", args.bsdf_samples, "BSDF samples per MIS estimate (0 to 65536)")
        ->capture_default_str()
        ->check(in_range(uint32_t{0}, kMaxStudySamples));
    sub.add_option("--seed", args.seed,
                   "Random seed; each (point, technique) draws its own stream from it, so a technique's "
                   "numbers do not depend on which others run")
        ->capture_default_str()
        ->check(any_seed());
    sub.add_option("--threads", args.threads,
                   "Worker threads, 1 to 1024, at most 4 per usable core (more are reduced to that, with a "
                   "note; default: the cores the CPU affinity and cgroup quota allow), the maps' builds' "
                   "loops included; results do not depend on it")
        ->check(in_range(uint32_t{1}, kMaxStudyThreads))
        ->each([](const std::string& threads) { limit_threads(static_cast<uint32_t>(std::stoul(threads))); });
    CLI::Option* normal = sub.add_option("--normal", args.normal, "One shading point with this normal x,y,z")
                              ->check(direction_validator());
    sub.add_option("--view", args.view, "View direction x,y,z for --normal (default: the normal)")
        ->check(direction_validator())
        ->needs(normal);
    sub.add_option("--points", args.points, "Shading points: K normals spread evenly over the sphere (1 to 10^6)")
        ->capture_default_str()
        ->check(in_range(uint32_t{1}, kMaxStudyPoints))
        ->excludes(normal);
    sub.add_option("--view-angle", args.view_angle,
                   "Degrees (0 to 89.9) between each --points normal and its view, towards azimuths that turn by "
                   "the golden angle from point to point (default: 0, seen head-on)")
        ->capture_default_str()
        ->check(CLI::Range(0.0, 89.9))
        ->excludes("--normal");
}

void add_output_flags(CLI::App& sub, CompareArgs& args) {
    sub.add_option("--image", args.render.size,
                   "Size WxH of the rendered row of spheres, one per BSDF (with --images), each side 16 to 8192")
        ->capture_default_str()
        ->check(size_validator(false, kMinImageSide, kMaxImageSide));
    sub.add_option("--image-spp", args.render.spp, "Estimates per pixel for each technique's render (1 to 65536)")
        ->capture_default_str()
        ->check(in_range(uint32_t{1}, kMaxImageSpp));
    sub.add_option("--reference-spp", args.render.reference_spp,
                   "Estimates per pixel of the reference render (mis-power; 1 to 2^20)")
        ->capture_default_str()
        ->check(in_range(uint32_t{1}, kMaxReferenceSpp));
    sub.add_option("--json", args.json, "Write the results as JSON")->check(non_empty());
    sub.add_option("--csv", args.csv, "Write the results as CSV")->check(non_empty());
    sub.add_option("--images", args.images, "Folder for EXR and PNG pictures (renders, errors, montage)")
        ->check(non_empty());
    sub.add_option(
           "--plots", args.plots,
           "Folder for PNG plots: variance_vs_balance.png, or alpha_sweep.png and allocation.png with the sweeps")
        ->check(non_empty());
}

void add_sweep_flags(CLI::App& sub, CompareArgs& args) {
    sub.add_option(
        "--alpha-sweep", args.alpha_sweep,
        "A0:A1:STEP: the study at every alpha A0, A0+STEP, ..., A1 for the techniques that depend on it (default "
        "mis-balance-comp, mis-power-comp, mis-optimal-comp; mis-balance as the baseline), instead of the normal "
        "table");
    sub.add_flag("--exact", args.exact,
                 "Also exact, noise-free variance ratios over mis-balance (quadrature, one subdivision): of every "
                 "technique with fixed weights, or with --alpha-sweep of mis-balance-comp");
    sub.add_option(
           "--allocation-sweep", args.allocation_sweep,
           "N: the MIS techniques (default mis-balance, mis-balance-comp) at every split n_env:n_bsdf = k:(N-k) "
           "of N samples per estimate, with the most efficient marked, instead of the normal table")
        ->check(in_range(uint32_t{2}, uint32_t{1024}));
}

// The plain map as the flags and the file say, and the fixed alpha (--alpha, or the
// table's own).
std::pair<EnvMap, float> load_plain(const CompareArgs& args, std::string& map_name, std::string& source_hash) {
    // The plain density; the compensated ones are built from its radiance, as --alpha
    // says (or as a table was built).
    BuildRequest flags = args.map;
    flags.compensate = false;
    flags.alpha_auto = false;
    LoadedMap loaded = load_map(args.input, flags, *args.notes);
    map_name = loaded.source.name;
    source_hash = args.source_hash.empty() ? hash_text(loaded.source.content_hash) : args.source_hash;
    const float fixed_alpha = !loaded.from_table         ? args.map.alpha.value_or(1.0f)
                              : loaded.map.compensated() ? loaded.map.options().compensation.alpha
                                                         : 0.0f;
    EnvMapOptions plain_options = loaded.map.options();
    plain_options.compensation.enabled = false;
    if (loaded.from_table)
        return {build_env_map(to_image(loaded.map.radiance()), plain_options, &interrupted()), fixed_alpha};
    return {std::move(loaded.map), fixed_alpha};
}

// --threads (0: every usable core), with a note where it is reduced.
uint32_t threads_of(const CompareArgs& args) {
    std::string note;
    const uint32_t threads = worker_threads(args.threads, &note);
    if (!note.empty()) std::cerr << "note: --" << note << "\n";
    return threads;
}

// The techniques --techniques names (empty: the default list). Throws std::invalid_argument
// for an unknown one.
std::vector<Technique> named_techniques(const CompareArgs& args) {
    std::vector<Technique> named;
    for (const std::string& t : split_list(args.techniques)) named.push_back(Technique::parse(t));
    return named;
}

// The study the flags ask for, all but its fixed alpha, which the map may set
// (load_plain); `requested` the techniques named (empty: the default).
CompareRequest compare_request(const CompareArgs& args, std::vector<Technique>& requested) {
    CompareRequest request;
    ComparisonOptions& options = request.options;
    options.spp = args.spp;
    options.seed = args.seed;
    options.bsdfs.clear();
    for (const std::string& b : split_list(args.bsdfs)) options.bsdfs.push_back(Bsdf::parse(b));
    if (options.bsdfs.empty()) throw UsageError("--bsdf '" + args.bsdfs + "': expected at least one BSDF");
    requested = named_techniques(args);
    if (!requested.empty()) options.techniques = requested;
    options.allocation = {args.env_samples, args.bsdf_samples};
    options.threads = threads_of(args);
    try {
        bins_per_side(args.bins, options.techniques);
    } catch (const std::invalid_argument& e) {
        throw std::runtime_error(std::string("--") + e.what());
    }
    if (!args.normal.empty()) {
        const Vec3 n = *parse_direction(args.normal);  // the flags' validators checked both
        request.points = {{n, args.view.empty() ? n : *parse_direction(args.view)}};
    } else {
        request.points = sphere_points(args.points, args.view_angle);
    }
    // --alpha X fixes the bins' alpha; without it, or with auto, each bin chooses its own.
    request.bin_alpha = args.map.alpha;
    request.bins = args.bins;
    request.bin_cost = args.bin_cost;
    request.cell_columns = args.cell_columns;
    return request;
}

Setup prepare(const CompareArgs& args) {
    std::vector<Technique> requested;
    CompareRequest request = compare_request(args, requested);
    Setup s;
    // Each sweep's techniques, checked before any file is touched.
    s.swept = args.alpha_sweep.empty() ? std::vector<float>{} : parse_alpha_sweep(args.alpha_sweep);
    if (!s.swept.empty()) s.alpha_techniques = alpha_sweep_techniques(requested);
    if (args.allocation_sweep) s.allocation_techniques = allocation_sweep_techniques(requested);
    check_outputs({args.input}, {{"--json", args.json}, {"--csv", args.csv}});
    for (const std::string* output : {&args.csv, &args.json})
        if (!output->empty()) prepare_output(*output);
    if (!args.images.empty()) std::filesystem::create_directories(args.images);
    if (!args.plots.empty()) std::filesystem::create_directories(args.plots);
    auto [plain, fixed_alpha] = load_plain(args, s.map_name, s.source_hash);
    if (!args.map.alpha_auto) request.alpha = fixed_alpha;
    static_cast<CompareSetup&>(s) =
        prepare_compare(std::make_shared<const EnvMap>(std::move(plain)), std::move(request), &interrupted());
    return s;
}

// A RunControl that shows `label`'s progress on stderr and stops at Ctrl-C.
RunControl watched(const CompareArgs& args, const char* label) {
    if (!args.show_progress) return {&interrupted(), {}};
    auto bar = std::make_shared<std::optional<Progress>>();
    return {&interrupted(), [label, bar](size_t done, size_t total) {
                if (!*bar) bar->emplace(label, total);
                (*bar)->update(done);
            }};
}

Outcome run_compare(const CompareArgs& args, const Setup& setup) {
    Outcome outcome;
    const bool sweeping = !setup.swept.empty() || args.allocation_sweep;
    if (!sweeping) {
        outcome.comparison = compare(setup.inputs(), watched(args, "compare"));
    }
    if (!setup.swept.empty()) {
        // auto's choices and alpha = 0 are swept too, to say where auto stands.
        std::vector<float> alphas = setup.swept;
        if (setup.choice) {
            alphas.insert(alphas.end(), setup.bsdf_alphas.begin(), setup.bsdf_alphas.end());
            alphas.push_back(0);
        }
        std::sort(alphas.begin(), alphas.end());
        alphas.erase(std::unique(alphas.begin(), alphas.end()), alphas.end());
        StudyInputs inputs = setup.inputs();
        inputs.options.techniques = setup.alpha_techniques;
        outcome.alphas_swept = alphas.size();
        outcome.alpha = run_alpha_sweep(inputs, alphas, args.exact, watched(args, "alpha sweep"));
    }
    if (args.allocation_sweep && !interrupted()) {
        StudyInputs inputs = setup.inputs();
        inputs.options.techniques = setup.allocation_techniques;
        outcome.allocation = run_allocation_sweep(inputs, args.allocation_sweep, watched(args, "allocation sweep"));
    }
    return outcome;
}

// "7.63x lower variance" for a gain of 7.63, "1.25x higher variance" for one of 0.8.
std::string gain_phrase(double gain, const char* better, const char* worse) {
    char text[64];
    std::snprintf(text, sizeof text, "%.2fx %s", gain >= 1 ? gain : 1 / gain, gain >= 1 ? better : worse);
    return text;
}

// What the tables a renderer can load give against balance MIS over the plain map, per
// BSDF, from the table's headline columns: "lambert: against mis-balance, the normal-aware
// table (mis-balance-bins) 7.63x lower variance (worst point 4.17x lower), 3.10x better at
// equal time; the global compensated table (mis-balance-comp) 2.23x lower variance (worst
// point 1.04x higher), 1.58x better at equal time".
std::string verdict(const BsdfComparison& b) {
    if (!b.find("mis-balance")) return b.bsdf.name() + ": no verdict (needs mis-balance)";
    std::string text;
    for (const auto& [technique, table] : {std::pair{"mis-balance-bins", "the normal-aware table"},
                                           {"mis-balance-comp", "the global compensated table"}}) {
        const TechniqueStats* t = b.find(technique);
        if (!t || !(t->variance_ratio_vs_mis > 0)) continue;
        text += std::string(text.empty() ? "" : "; ") + table + " (" + technique + ") " +
                gain_phrase(1 / t->variance_ratio_vs_mis, "lower variance", "higher variance");
        if (t->variance_ratio_worst > 0 && std::isfinite(t->variance_ratio_worst))
            text += " (worst point " + gain_phrase(1 / t->variance_ratio_worst, "lower", "higher") + ")";
        if (t->efficiency_ratio_vs_mis > 0)
            text += ", " + gain_phrase(t->efficiency_ratio_vs_mis, "better", "worse") + " at equal time";
    }
    if (text.empty()) return b.bsdf.name() + ": no verdict (needs mis-balance-bins or mis-balance-comp)";
    return b.bsdf.name() + ": against mis-balance, " + text;
}

// The table, the optimal-MIS warnings and the verdicts.
void print_comparison(std::ostream& out, const Comparison& c) {
    print_stats_table(out, c);
    for (const BsdfComparison& b : c.bsdfs)
        for (const TechniqueStats& t : b.techniques)
            if (t.ill_conditioned_points)
                out << b.bsdf.name() << " " << t.technique.name() << ": the optimal-MIS system was singular at "
                    << t.ill_conditioned_points << " of " << c.points_done << " points, which kept balance weights\n";
    for (const BsdfComparison& b : c.bsdfs) out << verdict(b) << "\n";
}

// A warning for each BSDF whose quadrature reference did not converge to the tolerance.
void print_reference_errors(std::ostream& out, const Comparison& c, double tolerance) {
    for (const BsdfComparison& b : c.bsdfs)
        if (b.reference_error > tolerance)
            out << "warning: " << b.bsdf.name() << ": the quadrature reference did not converge (relative error up to "
                << b.reference_error << ", tolerance " << tolerance
                << "): its lobe is sharper than the subdivided texels resolve; rel_mse and the reference column carry "
                   "that error\n";
}

// "0.8" for one albedo shared by all BSDFs, else "lambert 0.8, ggx:0.1 0.95/0.64/0.54".
std::string albedo_text(std::span<const Bsdf> bsdfs) {
    std::string text;
    const bool shared = std::all_of(bsdfs.begin(), bsdfs.end(),
                                    [&](const Bsdf& b) { return b.albedo_text() == bsdfs.front().albedo_text(); });
    if (shared && !bsdfs.empty()) return bsdfs.front().albedo_text();
    for (const Bsdf& b : bsdfs) text += (text.empty() ? "" : ", ") + b.name() + " " + b.albedo_text();
    return text;
}

// "envmis compare: map.hdr (1024x512), 16 shading points, ..., seed 1, BSDF albedo 0.8".
std::string header_line(const Setup& s, size_t points_done) {
    std::ostringstream alpha;
    if (s.choice) {
        alpha << "auto (";
        for (size_t b = 0; b < s.options.bsdfs.size(); ++b)
            alpha << (b ? ", " : "") << s.options.bsdfs[b].name() << " " << s.bsdf_alphas[b];
        alpha << ")";
    } else {
        alpha << s.map_alpha;
    }
    const ComparisonOptions& o = s.options;
    std::ostringstream header;
    header << "envmis compare: " << printable(s.map_name) << " (" << s.plain->width() << "x" << s.plain->height()
           << "), " << points_done << (points_done < s.points.size() ? " of " + std::to_string(s.points.size()) : "")
           << (s.points.size() == 1 ? " shading point" : " shading points") << ", " << o.spp << " estimates each, "
           << o.allocation.env << " env + " << o.allocation.bsdf << " BSDF samples per estimate ("
           << o.allocation.total() << " for single techniques), alpha " << alpha.str() << ", seed " << o.seed
           << ", BSDF albedo " << albedo_text(o.bsdfs);
    if (s.binned)
        header << ", " << s.binned->bins() << " normal bins (" << s.binned->diffuse_bins() << " diffuse; alpha "
               << (s.bins_auto ? "auto per bin" : "fixed") << ")";
    header << "\n";
    return header.str();
}

// The bins a run builds, not the flag: --bins 0 builds kDefaultStudyBins where a -bins
// technique runs (the flag as given where it is refused: the run reports that).
uint32_t bins_built(const CompareArgs& a) {
    try {
        std::vector<Technique> techniques = named_techniques(a);
        if (techniques.empty()) techniques = ComparisonOptions::default_techniques();
        const uint32_t g = bins_per_side(a.bins, techniques);
        return g * g;
    } catch (const std::invalid_argument&) {
        return a.bins;
    }
}

// Every flag that changes the numbers compare writes, or which files it writes, spelled
// canonically: recorded in the JSON's inputs ("options"), so that library mode can tell
// whether a map's results are what the same flags would give now. --threads, which
// changes only the timings, is left out.
std::string options_text(const CompareArgs& a) {
    std::ostringstream text;
    text << "bsdf=" << a.bsdfs << " techniques=" << a.techniques << " bins=" << bins_built(a) << " spp=" << a.spp
         << " env-samples=" << a.env_samples << " bsdf-samples=" << a.bsdf_samples << " seed=" << a.seed
         << " normal=" << a.normal << " view=" << a.view << " points=" << a.points;
    if (a.view_angle != 0) text << " view-angle=" << a.view_angle;
    if (a.bin_cost != BinnedOptions{}.cost) text << " bin-cost=" << a.bin_cost;
    if (a.cell_columns != 0) text << " cell-columns=" << a.cell_columns;
    char alpha[32];
    std::snprintf(alpha, sizeof alpha, "%.9g", a.map.alpha.value_or(1.0f));
    text << " alpha="
         << (a.map.alpha_auto ? "auto"
             : a.map.alpha    ? alpha
                              : "(default)")
         << " compensate=" << a.map.compensate << " colorspace=" << a.map.colorspace
         << " working-space=" << a.map.working_space << " axes=" << a.map.axes << " mapping=" << a.map.mapping
         << " alpha-sweep=" << a.alpha_sweep << " exact=" << a.exact << " allocation-sweep=" << a.allocation_sweep
         << " csv=" << !a.csv.empty() << " plots=" << !a.plots.empty() << " images=" << !a.images.empty();
    if (!a.images.empty())
        text << " image=" << a.render.size << " image-spp=" << a.render.spp
             << " reference-spp=" << a.render.reference_spp;
    return text.str();
}

nlohmann::json inputs_json(const CompareArgs& args, const Setup& s, size_t points_done) {
    nlohmann::json inputs = envmis::inputs_json({s.map_name, s.plain->width(), s.plain->height(), s.map_alpha,
                                                 s.choice ? &*s.choice : nullptr, &s.options, s.bsdf_alphas,
                                                 s.binned.get(), s.bins_auto, std::span(s.points).first(points_done)});
    inputs["source_hash"] = s.source_hash;
    inputs["options"] = options_text(args);
    return inputs;
}

// What the writers below collect: the JSON, the sweeps' CSV rows and the plots written.
struct Written {
    nlohmann::json json;
    std::vector<SweepRow> rows;  // point into the outcome's sweeps
    std::vector<std::string> plots;
};

// Writes plots/name as a PNG and notes it.
template <class Chart>
void write_plot(const CompareArgs& args, Written& written, const char* name, const Chart& chart) {
    io::write_png(std::filesystem::path(args.plots) / name, pictures::draw(chart));
    written.plots.push_back(name);
}

void write_comparison(std::ostream& out, const CompareArgs& args, const Setup& s, const Comparison& c, Written& w) {
    if (c.points_done < s.points.size()) out << "interrupted: results cover the points done\n";
    print_comparison(out, c);
    print_reference_errors(out, c, s.options.quadrature.tolerance);
    const auto alpha_of = [&s](const Bsdf& b) { return s.alpha_of(b); };
    w.json["results"] = stats_results_json(c, alpha_of);
    for (const BsdfComparison& b : c.bsdfs) w.json["reference_error"][b.bsdf.name()] = b.reference_error;
    for (const BsdfComparison& b : c.bsdfs) w.json["verdicts"].push_back(verdict(b));
    if (!args.csv.empty())
        write_file_atomically(args.csv, [&](std::ostream& out) {
            write_stats_csv(out, c, s.map_name, s.options.spp, s.options.seed, alpha_of);
        });
    if (!args.plots.empty() && !c.bsdfs.empty())
        write_plot(args, w, "variance_vs_balance.png", variance_chart(c, s.map_name));
}

// --exact: per BSDF, each fixed-weight technique's exact variance over mis-balance's,
// the geometric mean over points and the worst point.
void write_exact(std::ostream& out, const CompareArgs& args, const Setup& s, Written& w) {
    std::optional<Progress> progress;
    RunControl control{&interrupted(), {}};
    if (args.show_progress)
        control.progress = [&progress](size_t done, size_t total) {
            if (!progress) progress.emplace("exact variances", total);
            progress->update(done);
        };
    const std::vector<ExactRatio> ratios = exact_ratios(s, control);
    out << "exact var/mis: exact variance / that of mis-balance (quadrature, one subdivision), geometric mean "
           "over points (worst point)\n";
    for (size_t b = 0; b < s.options.bsdfs.size(); ++b) {
        out << "  " << s.options.bsdfs[b].name() << ":";
        for (const ExactRatio& r : ratios) {
            if (r.bsdf != b) continue;
            char text[96];
            if (std::isfinite(r.ratio))
                std::snprintf(text, sizeof text, " %s %.3f (%.3f)", r.technique.name().c_str(), r.ratio, r.worst());
            else
                std::snprintf(text, sizeof text, " %s - (no point with a variance)", r.technique.name().c_str());
            out << text;
            w.json["exact"][s.options.bsdfs[b].name()][r.technique.name()] = {
                {"ratio", r.ratio}, {"worst", r.worst()}, {"points", r.points}};
        }
        out << "\n";
    }
}

void write_alpha_sweep(std::ostream& out, const CompareArgs& args, const Setup& s, const AlphaSweep& sweep,
                       size_t swept, Written& w) {
    const std::vector<float>* auto_alphas = s.choice ? &s.bsdf_alphas : nullptr;
    out << "alpha sweep: " << swept << " values; var/mis: geometric mean over points of "
        << "variance / variance of mis-balance; exact: the same from exact variances (noise-free)\n";
    if (sweep.interrupted) out << "interrupted: the sweep covers the " << sweep.alphas.size() << " alphas done\n";
    print_alpha_sweep(out, sweep, auto_alphas);
    const std::vector<SweepRow> rows = sweep_rows(sweep);
    w.json["sweep"] = nlohmann::json::array();
    for (const SweepRow& row : rows) w.json["sweep"].push_back(sweep_row_json(row));
    w.json["sweep_best"] = alpha_sweep_summary_json(sweep, auto_alphas);
    w.rows.insert(w.rows.end(), rows.begin(), rows.end());
    if (!args.plots.empty() && !sweep.alphas.empty())
        write_plot(args, w, "alpha_sweep.png", alpha_sweep_plot(sweep, s.map_name));
}

void write_allocation_sweep(std::ostream& out, const CompareArgs& args, const Setup& s, const AllocationSweep& sweep,
                            Written& w) {
    out << "allocation sweep: " << args.allocation_sweep << " samples per estimate, split "
        << "n_env:n_bsdf; efficiency = 1 / (variance * seconds per estimate)\n";
    if (sweep.interrupted)
        out << "interrupted: the sweep covers the " << sweep.allocations.size() << " allocations done\n";
    print_allocation_sweep(out, sweep);
    const std::vector<SweepRow> rows = sweep_rows(sweep, s.compensated);
    w.json["allocation"] = nlohmann::json::array();
    for (const SweepRow& row : rows) w.json["allocation"].push_back(sweep_row_json(row));
    w.rows.insert(w.rows.end(), rows.begin(), rows.end());
    if (!args.plots.empty() && !sweep.allocations.empty())
        write_plot(args, w, "allocation.png", allocation_plot(sweep, s.map_name));
}

// The pictures of --images: one compensated map for every sphere (with auto, its
// map-wide choice).
void write_pictures(std::ostream& out, const CompareArgs& args, const Setup& s) {
    std::optional<CompensatedMaps> map_wide;
    if (s.choice) map_wide = compensated_maps(*s.plain, std::vector<float>{s.map_alpha});
    const StudyInputs inputs{*s.plain, map_wide ? *map_wide : s.compensated, s.points, s.options, s.binned.get()};
    const auto montage = render_comparison(inputs, args.render, args.images, s.map_name, {&interrupted(), {}});
    out << "pictures: " << args.images << " (montage: " << montage.string() << ")\n";
}

// Everything compare writes: the header, tables, JSON, CSV, plots and pictures.
void write_compare(std::ostream& out, const CompareArgs& args, const Setup& s, const Outcome& outcome) {
    const size_t points_done = outcome.comparison ? outcome.comparison->points_done : s.points.size();
    out << header_line(s, points_done);
    if (s.choice) print_alpha_choice(out, *s.choice, s.options.bsdfs);
    Written w{{{"inputs", inputs_json(args, s, points_done)}}, {}, {}};
    if (outcome.comparison) write_comparison(out, args, s, *outcome.comparison, w);
    if (outcome.comparison && args.exact && outcome.comparison->points_done == s.points.size())
        write_exact(out, args, s, w);
    if (outcome.alpha) write_alpha_sweep(out, args, s, *outcome.alpha, outcome.alphas_swept, w);
    if (outcome.allocation) write_allocation_sweep(out, args, s, *outcome.allocation, w);
    if ((outcome.alpha || outcome.allocation) && !args.csv.empty()) {
        std::ostringstream prefix;
        prefix << s.map_name << ',' << s.options.spp << ',' << s.options.seed << ',' << s.points.size() << ',';
        write_file_atomically(args.csv, [&](std::ostream& out) {
            out << sweep_csv_header() << '\n';
            for (const SweepRow& row : w.rows) write_sweep_csv_row(out, prefix.str(), row);
        });
    }
    if (!args.json.empty()) write_file_atomically(args.json, [&](std::ostream& out) { out << w.json.dump(2) << "\n"; });
    if (!w.plots.empty()) {
        out << "plots: " << args.plots << " (";
        for (size_t i = 0; i < w.plots.size(); ++i) out << (i ? ", " : "") << w.plots[i];
        out << ")\n";
    }
    if (!args.images.empty()) write_pictures(out, args, s);
}

// A run stopped early prints the tables of what is done (each says it is partial) and
// writes no file: a reader of the JSON, CSV or pictures could not tell them from a
// whole run's. Then it throws Interrupted, saying so.
void write_partial(std::ostream& out, const CompareArgs& args, const Setup& s, const Outcome& outcome) {
    CompareArgs printed = args;
    printed.json.clear();
    printed.csv.clear();
    printed.plots.clear();
    printed.images.clear();
    write_compare(out, printed, s, outcome);
    const bool outputs = !(args.json.empty() && args.csv.empty() && args.plots.empty() && args.images.empty());
    std::string detail = "the results above are partial";
    if (outcome.comparison)
        detail = "the results above cover " + std::to_string(outcome.comparison->points_done) + " of " +
                 std::to_string(s.points.size()) + " points";
    throw Interrupted(detail + (outputs ? "; no file written" : ""));
}

}  // namespace

namespace {

void add_library_flags(CLI::App& sub, CompareArgs& args) {
    sub.add_option("--out-dir", args.out_dir,
                   "Library mode (several inputs or a folder): each map's JSON to DIR/<stem>.json, and "
                   "DIR/summary.json; --csv, --plots and --images then name folders receiving each map's files")
        ->check(non_empty());
    add_jobs_flag(sub, args.jobs);
    sub.add_flag("--force", args.force, "Library mode: run every map, also those whose JSON is up to date");
    sub.add_flag("--recursive", args.recursive, "Library mode: also the maps in subfolders of a folder input");
    sub.add_option("--summary", args.summary,
                   "Library mode: the JSON summary of every map's result (default: DIR/summary.json)")
        ->check(non_empty());
}

// One map's study, start to end; `out` takes what it prints.
void compare_one(const CompareArgs& args, std::ostream& out) {
    const Setup setup = prepare(args);
    const Outcome outcome = run_compare(args, setup);
    if (interrupted())
        write_partial(out, args, setup, outcome);
    else
        write_compare(out, args, setup, outcome);
}

// True where `json` holds results of the source whose bytes hash to `hash`, run with
// `options`. A file that cannot be read or parsed is not up to date.
bool results_up_to_date(const std::filesystem::path& json, uint64_t hash, const std::string& options) {
    std::ifstream in(json);
    if (!in) return false;
    const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
    if (j.is_discarded() || !j.is_object() || !j.contains("inputs") || !j["inputs"].is_object()) return false;
    const nlohmann::json& inputs = j["inputs"];
    return inputs.value("source_hash", "") == hash_text(hash) && inputs.value("options", "") == options;
}

// A map's peak resident memory per texel in compare, above the process's own: about 45
// measured on a 4096x2048 map, from an image or a table (/usr/bin/time -v), rounded up.
constexpr uint64_t kComparePeak = 48;

// Several inputs or a folder: each map's study to DIR/<stem>.json, on the pool of --jobs;
// each map's --threads defaults to its share of the cores.
void run_library_compare(const CompareArgs& args) {
    if (args.out_dir.empty()) {
        std::error_code ec;
        for (const std::string& input : args.inputs)
            if (std::filesystem::is_directory(input, ec))
                throw std::runtime_error(input + ": a directory; a folder of maps needs --out-dir DIR (library mode)");
        throw UsageError("--out-dir: required with several inputs, or with --summary (library mode)");
    }
    if (!args.json.empty())
        throw UsageError("--json: not in library mode; each map's JSON goes to --out-dir/<stem>.json");
    const std::filesystem::path dir = args.out_dir;
    const std::vector<LibraryItem> items = plan_outputs(expand_inputs(args.inputs, args.recursive, true), dir, ".json");
    std::filesystem::create_directories(dir);
    // The maps' CSV files share one folder, made once before any map runs.
    std::error_code ec;
    if (!args.csv.empty() && (std::filesystem::create_directories(args.csv, ec), ec))
        throw std::runtime_error("--csv " + args.csv + ": cannot make the folder: " + ec.message());
    for (const LibraryItem& item : items) prepare_output(item.output);
    CompareArgs shared = args;
    shared.show_progress = false;
    if (!(args.threads_flag && args.threads_flag->count() > 0))
        shared.threads = std::max(1u, usable_cores() / std::min<uint32_t>(args.jobs, uint32_t(items.size())));
    const std::string options = options_text(args);
    const auto matches = [&](const std::filesystem::path& output, uint64_t hash) {
        return results_up_to_date(output, hash, options);
    };
    run_library(
        items,
        {"compare", args.jobs, args.summary.empty() ? dir / "summary.json" : std::filesystem::path(args.summary),
         kComparePeak, matches},
        [&](const LibraryItem& item, uint64_t hash) {
            MapOutcome outcome;
            if (!args.force && results_up_to_date(item.output, hash, options)) {
                outcome.status = "up-to-date";
                outcome.printed = "envmis compare: " + item.output.string() + " is up to date\n";
                return outcome;
            }
            CompareArgs one = shared;
            one.input = item.input.string();
            one.source_hash = hash_text(hash);
            one.json = item.output.string();
            const std::string stem = item.input.stem().string();
            if (!args.csv.empty()) one.csv = (std::filesystem::path(args.csv) / (stem + ".csv")).string();
            if (!args.plots.empty()) one.plots = (std::filesystem::path(args.plots) / stem).string();
            if (!args.images.empty()) one.images = (std::filesystem::path(args.images) / stem).string();
            std::ostringstream out, notes;
            one.notes = &notes;
            compare_one(one, out);
            outcome.status = "written";
            outcome.printed = out.str();
            outcome.notes = notes.str();
            return outcome;
        });
}

}  // namespace

// What compare's table shows (docs/compare.md has the JSON and CSV keys too).
constexpr const char* kColumnsHelp =
    "Table, a row per BSDF and technique; each shading point is its own case, summarised over points:\n"
    "  var/mis    variance of one estimate / that of mis-balance at the same point, geometric mean over points\n"
    "             (the headline: below 1 is better)\n"
    "  worst      the largest of those per-point ratios\n"
    "  eff/mis    the gain at equal time: mis-balance's ns/est / (var/mis x this ns/est); above 1 is better\n"
    "  mean       mean of the estimates (luminance of the reflected radiance, the map's units), over points\n"
    "  std_error  standard error of that mean\n"
    "  reference  the quadrature reference of the mean\n"
    "  rel_mse    relative mean squared error of one estimate, mean of ((estimate - reference) / reference)^2\n"
    "  ns/est     nanoseconds per estimate, timed apart on one core: each technique in turn at up to 8\n"
    "             points, 5 rounds of up to 256 estimates; per point the median, then the mean\n"
    "The lines below it compare the tables a renderer loads against mis-balance over the plain map: the\n"
    "normal-aware one (mis-balance-bins) and the global compensated one (mis-balance-comp).";

Subcommand add_compare(CLI::App& app) {
    auto args = std::make_shared<CompareArgs>();
    CLI::App* sub = app.add_subcommand(
        "compare", "Variance of direct-lighting estimators with and without MIS compensation, at equal sample count");
    add_study_flags(*sub, *args);
    add_output_flags(*sub, *args);
    add_sweep_flags(*sub, *args);
    add_library_flags(*sub, *args);
    add_map_flags(*sub, args->map);
    args->threads_flag = sub->get_option("--threads");
    sub->footer(kColumnsHelp);
    return {sub, [args] {
                std::error_code ec;
                if (args->inputs.size() > 1 || !args->out_dir.empty() || !args->summary.empty() ||
                    std::filesystem::is_directory(args->inputs.front(), ec))
                    return run_library_compare(*args);
                args->input = args->inputs.front();
                compare_one(*args, std::cout);
            }};
}

}  // namespace envmis::cli
