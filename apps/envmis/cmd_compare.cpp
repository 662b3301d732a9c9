// envmis compare IN: the variance study. Estimates direct lighting on analytic BSDFs with
// every technique at equal sample count and reports how much MIS compensation gains.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "cli.h"
#include "envmis/io/image_io.h"
#include "envmis/study/comparison/comparison.h"
#include "envmis/table/atomic_file.h"
#include "render.h"
#include "sweeps.h"

namespace envmis::cli {
namespace {

Vec3 parse_vector(const std::string& text, const char* what) {
    float x = 0, y = 0, z = 0;
    char tail = 0;
    if (std::sscanf(text.c_str(), "%f,%f,%f%c", &x, &y, &z, &tail) != 3 || !(x * x + y * y + z * z > 0))
        throw std::runtime_error(std::string(what) + " '" + text + "': expected a non-zero vector x,y,z");
    return normalize(Vec3{x, y, z});
}

std::vector<std::string> split(const std::string& text) {
    std::vector<std::string> items;
    std::stringstream in(text);
    for (std::string item; std::getline(in, item, ',');)
        if (!item.empty()) items.push_back(item);
    return items;
}

// "lambert: compensation 1.7x lower variance, 1.6x higher efficiency".
std::string verdict(const BsdfComparison& b) {
    const TechniqueStats *plain = b.find("mis-balance"), *comp = b.find("mis-balance-comp");
    if (!plain || !comp || !(comp->variance_ratio_vs_mis > 0))
        return b.bsdf.name() + ": no verdict (needs mis-balance and mis-balance-comp)";
    auto phrase = [](double ratio, const char* better, const char* worse) {
        char text[64];
        std::snprintf(text, sizeof text, "%.2fx %s", ratio >= 1 ? ratio : 1 / ratio, ratio >= 1 ? better : worse);
        return std::string(text);
    };
    const double variance_gain = 1 / comp->variance_ratio_vs_mis;
    const double efficiency_gain = variance_gain * plain->ns_per_estimate / comp->ns_per_estimate;
    return b.bsdf.name() + ": compensation " + phrase(variance_gain, "lower variance", "higher variance") + ", " +
           phrase(efficiency_gain, "higher efficiency", "lower efficiency");
}

void print_table(std::ostream& out, const Comparison& c) {
    char line[256];
    std::snprintf(line, sizeof line, "%-10s %-17s %11s %11s %11s %10s %10s %8s %11s %8s\n", "bsdf", "technique", "mean",
                  "reference", "variance", "std_error", "rel_mse", "ns/est", "efficiency", "var/mis");
    out << line;
    for (const BsdfComparison& b : c.bsdfs)
        for (const TechniqueStats& t : b.techniques) {
            std::snprintf(line, sizeof line, "%-10s %-17s %11.5g %11.5g %11.4g %10.3g %10.4g %8.1f %11.4g %8.3f\n",
                          b.bsdf.name().c_str(), t.technique.name().c_str(), t.mean, t.reference, t.variance,
                          t.std_error, t.rel_mse, t.ns_per_estimate, t.efficiency, t.variance_ratio_vs_mis);
            out << line;
        }
    for (const BsdfComparison& b : c.bsdfs)
        for (const TechniqueStats& t : b.techniques)
            if (t.ill_conditioned_points)
                out << b.bsdf.name() << " " << t.technique.name() << ": the optimal-MIS system was singular at "
                    << t.ill_conditioned_points << " of " << c.points_done << " points, which kept balance weights\n";
    for (const BsdfComparison& b : c.bsdfs) out << verdict(b) << "\n";
}

nlohmann::json stats_json(const BsdfComparison& b, const TechniqueStats& t, float alpha) {
    return {{"bsdf", b.bsdf.name()},
            {"technique", t.technique.name()},
            {"alpha", alpha},
            {"mean", t.mean},
            {"reference", t.reference},
            {"variance", t.variance},
            {"std_error", t.std_error},
            {"rel_mse", t.rel_mse},
            {"ns_per_estimate", t.ns_per_estimate},
            {"efficiency", t.efficiency},
            {"variance_ratio_vs_mis", t.variance_ratio_vs_mis},
            {"variance_ratio_log_std_error", t.variance_ratio_log_std_error},
            {"ill_conditioned_points", t.ill_conditioned_points},
            {"point_variances", t.point_variances},
            {"point_variance_rel_se", t.point_variance_rel_se},
            {"estimates", t.estimates}};
}

// Writes plots/name as a PNG.
template <class Chart>
void write_plot(const std::filesystem::path& plots, const char* name, const Chart& chart) {
    io::write_png(plots / name, pictures::draw(chart));
}

}  // namespace

Subcommand add_compare(CLI::App& app) {
    struct Args {
        std::string input, bsdfs = "lambert,phong:50,ggx:0.1", techniques, normal, view, json, csv, images, plots,
                           alpha_sweep;
        RenderOptions render;
        uint32_t points = 16, threads = 0, env_samples = 1, bsdf_samples = 1, allocation_sweep = 0;
        bool exact = false;
        ComparisonOptions options;
        MapFlags map;
    };
    auto args = std::make_shared<Args>();
    args->options.spp = 1024;
    CLI::App* sub = app.add_subcommand(
        "compare", "Variance of direct-lighting estimators with and without MIS compensation, at equal sample count");
    sub->add_option("input", args->input, "HDR image or table")->required();
    sub->add_option("--bsdf", args->bsdfs, "BSDFs: lambert, phong:N, ggx:ALPHA, comma-separated")
        ->capture_default_str();
    sub->add_option(
        "--techniques", args->techniques,
        "Techniques, comma-separated (default: env,bsdf,mis-balance,mis-power,mis-balance-comp,mis-power-comp,"
        "mis-optimal-comp,mis-optimal-all; all: env,bsdf,mis-{balance,power,optimal,var}[-comp],"
        "mis-{balance,optimal}-all,one-sample[-comp])");
    sub->add_option("--spp", args->options.spp, "Estimates per shading point, BSDF and technique")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    sub->add_option("--env-samples", args->env_samples, "Environment samples per MIS estimate")->capture_default_str();
    sub->add_option("--bsdf-samples", args->bsdf_samples, "BSDF samples per MIS estimate")->capture_default_str();
    sub->add_option("--seed", args->options.seed, "Random seed")->capture_default_str();
    sub->add_option("--threads", args->threads, "Worker threads (default: all cores); results do not depend on it");
    sub->add_option("--normal", args->normal, "One shading point with this normal x,y,z");
    sub->add_option("--view", args->view, "View direction x,y,z for --normal (default: the normal)");
    sub->add_option("--points", args->points, "Shading points: K normals spread evenly over the sphere")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    sub->add_option("--image", args->render.size,
                    "Size WxH of the rendered row of spheres, one per BSDF (with --images)")
        ->capture_default_str();
    sub->add_option("--image-spp", args->render.spp, "Estimates per pixel for each technique's render")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    sub->add_option("--reference-spp", args->render.reference_spp,
                    "Estimates per pixel of the reference render (mis-power)")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    sub->add_option("--json", args->json, "Write the results as JSON");
    sub->add_option("--csv", args->csv, "Write the results as CSV");
    sub->add_option("--images", args->images, "Folder for EXR and PNG pictures (renders, errors, montage)");
    sub->add_option(
        "--plots", args->plots,
        "Folder for PNG plots: variance_vs_balance.png, or alpha_sweep.png and allocation.png with the sweeps");
    CLI::Option* alpha_sweep = sub->add_option(
        "--alpha-sweep", args->alpha_sweep,
        "A0:A1:STEP: the study at every alpha A0, A0+STEP, ..., A1 for the techniques that depend on it (default "
        "mis-balance-comp, mis-power-comp, mis-optimal-comp; mis-balance as the baseline), instead of the normal "
        "table");
    sub->add_flag("--exact", args->exact,
                  "With --alpha-sweep: also the exact, noise-free variance ratio of mis-balance-comp over mis-balance")
        ->needs(alpha_sweep);
    sub->add_option(
           "--allocation-sweep", args->allocation_sweep,
           "N: the MIS techniques (default mis-balance, mis-balance-comp) at every split n_env:n_bsdf = k:(N-k) "
           "of N samples per estimate, with the most efficient marked, instead of the normal table")
        ->check(CLI::Range(2u, 1024u));
    add_map_flags(*sub, args->map);
    return {
        sub, [args] {
            ComparisonOptions& options = args->options;
            options.bsdfs.clear();
            for (const std::string& b : split(args->bsdfs)) options.bsdfs.push_back(Bsdf::parse(b));
            std::vector<Technique> requested;  // empty: each study's default
            for (const std::string& t : split(args->techniques)) requested.push_back(Technique::parse(t));
            if (!requested.empty()) options.techniques = requested;
            options.allocation = {args->env_samples, args->bsdf_samples};
            options.threads = args->threads ? args->threads : std::max(1u, std::thread::hardware_concurrency());
            const std::vector<float> swept =
                args->alpha_sweep.empty() ? std::vector<float>{} : parse_alpha_sweep(args->alpha_sweep);
            const bool sweeping = !swept.empty() || args->allocation_sweep;

            if (!args->images.empty()) std::filesystem::create_directories(args->images);
            if (!args->plots.empty()) std::filesystem::create_directories(args->plots);
            // The plain density; the compensated ones are built from its radiance below, as
            // --alpha says (or as a table was built).
            MapFlags flags = args->map;
            flags.no_compensate = true;
            flags.alpha_auto = false;
            LoadedMap loaded = load_map(args->input, flags);
            const float fixed_alpha = !loaded.from_table         ? args->map.alpha
                                      : loaded.map.compensated() ? loaded.map.options().compensation.alpha
                                                                 : 0.0f;
            EnvMapOptions plain_options = loaded.map.options();
            plain_options.compensation.enabled = false;
            const EnvMap plain =
                loaded.from_table ? EnvMap(to_image(loaded.map.radiance()), plain_options) : std::move(loaded.map);

            std::vector<ShadingPoint> points;
            if (!args->normal.empty()) {
                const Vec3 n = parse_vector(args->normal, "--normal");
                points = {{n, args->view.empty() ? n : parse_vector(args->view, "--view")}};
            } else {
                points = sphere_points(args->points);
            }

            std::optional<AlphaChoice> choice;
            if (args->map.alpha_auto) {
                AlphaOptions search;
                search.bsdfs = options.bsdfs;
                search.points = points;
                search.allocation = options.allocation;
                choice = choose_alpha(plain.radiance(), plain.options(), search);
            }
            const float map_alpha = choice ? choice->alpha : fixed_alpha;
            const std::vector<float> bsdf_alphas =
                choice ? choice->bsdf_alphas : std::vector<float>(options.bsdfs.size(), map_alpha);
            const CompensatedMaps compensated = compensated_maps(plain, bsdf_alphas);
            auto alpha_of = [&](const Bsdf& bsdf) {
                for (size_t b = 0; b < options.bsdfs.size(); ++b)
                    if (options.bsdfs[b].name() == bsdf.name()) return bsdf_alphas[b];
                return map_alpha;
            };

            std::optional<Comparison> result;
            if (!sweeping) {
                Progress progress("compare", points.size() * compensated.maps.size());
                result = compare_each(plain, compensated, points, options, &interrupted(),
                                      [&](size_t done, size_t) { progress.update(done); });
            }
            const size_t points_done = result ? result->points_done : points.size();

            std::ostringstream alpha_text;
            if (choice) {
                alpha_text << "auto (";
                for (size_t b = 0; b < options.bsdfs.size(); ++b)
                    alpha_text << (b ? ", " : "") << options.bsdfs[b].name() << " " << bsdf_alphas[b];
                alpha_text << ")";
            } else {
                alpha_text << map_alpha;
            }
            std::ostringstream header;
            header << "envmis compare: " << loaded.source.name << " (" << plain.width() << "x" << plain.height()
                   << "), " << points_done
                   << (points_done < points.size() ? " of " + std::to_string(points.size()) : "")
                   << (points.size() == 1 ? " shading point" : " shading points") << ", " << options.spp
                   << " estimates each, " << options.allocation.env << " env + " << options.allocation.bsdf
                   << " BSDF samples per estimate (" << options.allocation.total() << " for single techniques), alpha "
                   << alpha_text.str() << ", seed " << options.seed << "\n";
            std::cout << header.str();
            if (choice) print_alpha_choice(std::cout, *choice, options.bsdfs);

            nlohmann::json inputs = {{"map", loaded.source.name},
                                     {"width", plain.width()},
                                     {"height", plain.height()},
                                     {"alpha", map_alpha},
                                     {"alpha_auto", choice.has_value()},
                                     {"spp", options.spp},
                                     {"seed", options.seed},
                                     {"threads", options.threads},
                                     {"env_samples", options.allocation.env},
                                     {"bsdf_samples", options.allocation.bsdf},
                                     {"points_done", points_done}};
            for (size_t b = 0; b < options.bsdfs.size(); ++b)
                inputs["bsdf_alpha"][options.bsdfs[b].name()] = bsdf_alphas[b];
            if (choice) inputs["alpha_choice"] = alpha_choice_json(*choice, options.bsdfs);
            for (size_t i = 0; i < points_done; ++i) {
                const ShadingPoint& p = points[i];
                inputs["points"].push_back(
                    {{"normal", {p.normal.x, p.normal.y, p.normal.z}}, {"view", {p.wo.x, p.wo.y, p.wo.z}}});
            }
            nlohmann::json j = {{"inputs", inputs}};
            std::ostringstream csv_prefix;
            csv_prefix << loaded.source.name << ',' << options.spp << ',' << options.seed << ',' << points.size()
                       << ',';
            std::vector<std::string> plots;

            if (result) {
                if (points_done < points.size()) std::cout << "interrupted: results cover the points done\n";
                print_table(std::cout, *result);
                j["results"] = nlohmann::json::array();
                for (const BsdfComparison& b : result->bsdfs) {
                    for (const TechniqueStats& t : b.techniques)
                        j["results"].push_back(stats_json(b, t, alpha_of(b.bsdf)));
                    j["verdicts"].push_back(verdict(b));
                }
                if (!args->csv.empty()) {
                    write_file_atomically(args->csv, [&](std::ostream& out) {
                        out << "map,alpha,spp,seed,points,bsdf,technique,mean,reference,variance,std_error,rel_mse,"
                               "ns_per_estimate,efficiency,variance_ratio_vs_mis\n";
                        for (const BsdfComparison& b : result->bsdfs)
                            for (const TechniqueStats& t : b.techniques)
                                out << loaded.source.name << ',' << alpha_of(b.bsdf) << ',' << options.spp << ','
                                    << options.seed << ',' << points_done << ',' << b.bsdf.name() << ','
                                    << t.technique.name() << ',' << t.mean << ',' << t.reference << ',' << t.variance
                                    << ',' << t.std_error << ',' << t.rel_mse << ',' << t.ns_per_estimate << ','
                                    << t.efficiency << ',' << t.variance_ratio_vs_mis << '\n';
                    });
                }
                if (!args->plots.empty() && !result->bsdfs.empty()) {
                    write_plot(args->plots, "variance_vs_balance.png", variance_chart(*result, loaded.source.name));
                    plots.push_back("variance_vs_balance.png");
                }
            }

            std::vector<SweepRow> rows;  // point into the sweeps below
            std::optional<AlphaSweep> alpha_study;
            if (!swept.empty()) {
                // auto's choices and alpha = 0 are swept too, to say where auto stands.
                std::vector<float> alphas = swept;
                if (choice) {
                    alphas.insert(alphas.end(), bsdf_alphas.begin(), bsdf_alphas.end());
                    alphas.push_back(0);
                }
                std::sort(alphas.begin(), alphas.end());
                alphas.erase(std::unique(alphas.begin(), alphas.end()), alphas.end());
                ComparisonOptions sweep_options = options;
                sweep_options.techniques = alpha_sweep_techniques(requested);
                alpha_study = run_alpha_sweep(plain, alphas, points, sweep_options, args->exact, &interrupted());
                std::cout << "alpha sweep: " << alphas.size() << " values; var/mis: geometric mean over points of "
                          << "variance / variance of mis-balance; exact: the same from exact variances (noise-free)\n";
                if (alpha_study->interrupted)
                    std::cout << "interrupted: the sweep covers the " << alpha_study->alphas.size() << " alphas done\n";
                print_alpha_sweep(std::cout, *alpha_study, choice ? &bsdf_alphas : nullptr);
                const std::vector<SweepRow> alpha_rows = sweep_rows(*alpha_study);
                j["sweep"] = nlohmann::json::array();
                for (const SweepRow& row : alpha_rows) j["sweep"].push_back(sweep_row_json(row));
                j["sweep_best"] = alpha_sweep_summary_json(*alpha_study, choice ? &bsdf_alphas : nullptr);
                rows.insert(rows.end(), alpha_rows.begin(), alpha_rows.end());
                if (!args->plots.empty() && !alpha_study->alphas.empty()) {
                    write_plot(args->plots, "alpha_sweep.png", alpha_sweep_plot(*alpha_study, loaded.source.name));
                    plots.push_back("alpha_sweep.png");
                }
            }
            std::optional<AllocationSweep> allocation_study;
            if (args->allocation_sweep && !interrupted()) {
                ComparisonOptions sweep_options = options;
                sweep_options.techniques = allocation_sweep_techniques(requested);
                allocation_study = run_allocation_sweep(plain, compensated, args->allocation_sweep, points,
                                                        sweep_options, &interrupted());
                std::cout << "allocation sweep: " << args->allocation_sweep << " samples per estimate, split "
                          << "n_env:n_bsdf; efficiency = 1 / (variance * seconds per estimate)\n";
                if (allocation_study->interrupted)
                    std::cout << "interrupted: the sweep covers the " << allocation_study->allocations.size()
                              << " allocations done\n";
                print_allocation_sweep(std::cout, *allocation_study);
                const std::vector<SweepRow> allocation_rows = sweep_rows(*allocation_study, compensated);
                j["allocation"] = nlohmann::json::array();
                for (const SweepRow& row : allocation_rows) j["allocation"].push_back(sweep_row_json(row));
                rows.insert(rows.end(), allocation_rows.begin(), allocation_rows.end());
                if (!args->plots.empty() && !allocation_study->allocations.empty()) {
                    write_plot(args->plots, "allocation.png", allocation_plot(*allocation_study, loaded.source.name));
                    plots.push_back("allocation.png");
                }
            }
            if (sweeping && !args->csv.empty()) {
                write_file_atomically(args->csv, [&](std::ostream& out) {
                    out << kSweepCsvHeader << '\n';
                    for (const SweepRow& row : rows) write_sweep_csv_row(out, csv_prefix.str(), row);
                });
            }
            if (!args->json.empty())
                write_file_atomically(args->json, [&](std::ostream& out) { out << j.dump(2) << "\n"; });
            if (!plots.empty()) {
                std::cout << "plots: " << args->plots << " (";
                for (size_t i = 0; i < plots.size(); ++i) std::cout << (i ? ", " : "") << plots[i];
                std::cout << ")\n";
            }
            if (!args->images.empty()) {
                // One compensated map for every sphere: with auto, its map-wide choice.
                const std::optional<EnvMap> map_wide =
                    choice ? std::optional<EnvMap>(compensated_map(plain, map_alpha)) : std::nullopt;
                const auto montage = render_comparison(plain, map_wide ? *map_wide : compensated.maps.front(), options,
                                                       args->render, args->images, loaded.source.name, &interrupted());
                std::cout << "pictures: " << args->images << " (montage: " << montage.string() << ")\n";
            }
        }};
}

}  // namespace envmis::cli
