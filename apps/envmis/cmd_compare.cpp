// envmis compare IN: the variance study. Estimates direct lighting on analytic BSDFs with
// every technique at equal sample count and reports how much MIS compensation gains.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "cli.h"
#include "envmis/atomic_file.h"
#include "envmis/comparison.h"
#include "render.h"

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
    if (!plain || !comp || !(comp->variance_ratio_vs_mis > 0)) return b.bsdf.name() + ": no verdict (needs mis-balance and mis-balance-comp)";
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
                          b.bsdf.name().c_str(), t.technique.name().c_str(), t.mean, t.reference, t.variance, t.std_error,
                          t.rel_mse, t.ns_per_estimate, t.efficiency, t.variance_ratio_vs_mis);
            out << line;
        }
    for (const BsdfComparison& b : c.bsdfs) out << verdict(b) << "\n";
}

nlohmann::json stats_json(const BsdfComparison& b, const TechniqueStats& t) {
    return {{"bsdf", b.bsdf.name()},           {"technique", t.technique.name()}, {"mean", t.mean},
            {"reference", t.reference},        {"variance", t.variance},          {"std_error", t.std_error},
            {"rel_mse", t.rel_mse},            {"ns_per_estimate", t.ns_per_estimate},
            {"efficiency", t.efficiency},      {"variance_ratio_vs_mis", t.variance_ratio_vs_mis},
            {"estimates", t.estimates}};
}

}  // namespace

Subcommand add_compare(CLI::App& app) {
    struct Args {
        std::string input, bsdfs = "lambert,phong:50,ggx:0.1", techniques, normal, view, json, csv, images;
        RenderOptions render;
        uint32_t points = 16, threads = 0, env_samples = 1, bsdf_samples = 1;
        ComparisonOptions options;
        MapFlags map;
    };
    auto args = std::make_shared<Args>();
    args->options.spp = 1024;
    CLI::App* sub = app.add_subcommand(
        "compare", "Variance of direct-lighting estimators with and without MIS compensation, at equal sample count");
    sub->add_option("input", args->input, "HDR image or table")->required();
    sub->add_option("--bsdf", args->bsdfs, "BSDFs: lambert, phong:N, ggx:ALPHA, comma-separated")->capture_default_str();
    sub->add_option("--techniques", args->techniques,
                    "Techniques, comma-separated (default: env,bsdf,mis-balance,mis-power,mis-balance-comp,mis-power-comp)");
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
    sub->add_option("--image", args->render.size, "Size WxH of the rendered row of spheres, one per BSDF (with --images)")
        ->capture_default_str();
    sub->add_option("--image-spp", args->render.spp, "Estimates per pixel for each technique's render")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    sub->add_option("--reference-spp", args->render.reference_spp, "Estimates per pixel of the reference render (mis-power)")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    sub->add_option("--json", args->json, "Write the results as JSON");
    sub->add_option("--csv", args->csv, "Write the results as CSV");
    sub->add_option("--images", args->images, "Folder for EXR and PNG pictures (renders, errors, montage)");
    add_map_flags(*sub, args->map);
    return {sub, [args] {
                ComparisonOptions& options = args->options;
                options.bsdfs.clear();
                for (const std::string& b : split(args->bsdfs)) options.bsdfs.push_back(Bsdf::parse(b));
                if (!args->techniques.empty()) {
                    options.techniques.clear();
                    for (const std::string& t : split(args->techniques)) options.techniques.push_back(Technique::parse(t));
                }
                options.allocation = {args->env_samples, args->bsdf_samples};
                options.threads = args->threads ? args->threads : std::max(1u, std::thread::hardware_concurrency());

                if (!args->images.empty()) std::filesystem::create_directories(args->images);
                MapFlags flags = args->map;
                flags.no_compensate = false;
                const LoadedMap loaded = load_map(args->input, flags);
                EnvMapOptions plain_options = loaded.map.options();
                plain_options.compensation.enabled = false;
                const EnvMap plain(loaded.map.radiance(), plain_options);
                const EnvMap& compensated = loaded.map;

                std::vector<ShadingPoint> points;
                if (!args->normal.empty()) {
                    const Vec3 n = parse_vector(args->normal, "--normal");
                    points = {{n, args->view.empty() ? n : parse_vector(args->view, "--view")}};
                } else {
                    points = sphere_points(args->points);
                }

                Progress progress("compare", points.size());
                const Comparison result = compare(plain, compensated, points, options, &interrupted(),
                                                  [&](size_t done, size_t) { progress.update(done); });

                std::ostringstream header;
                header << "envmis compare: " << loaded.source.name << " (" << plain.width() << "x" << plain.height() << "), "
                       << result.points_done << (result.points_done < result.points_total ? " of " + std::to_string(result.points_total) : "")
                       << (points.size() == 1 ? " shading point" : " shading points") << ", " << options.spp
                       << " estimates each, " << options.allocation.env << " env + " << options.allocation.bsdf
                       << " BSDF samples per estimate (" << options.allocation.total() << " for single techniques), alpha "
                       << compensated.options().compensation.alpha << ", seed " << options.seed << "\n";
                std::cout << header.str();
                if (result.points_done < result.points_total) std::cout << "interrupted: results cover the points done\n";
                print_table(std::cout, result);

                nlohmann::json inputs = {{"map", loaded.source.name},
                                         {"width", plain.width()},
                                         {"height", plain.height()},
                                         {"alpha", compensated.options().compensation.alpha},
                                         {"spp", options.spp},
                                         {"seed", options.seed},
                                         {"threads", options.threads},
                                         {"env_samples", options.allocation.env},
                                         {"bsdf_samples", options.allocation.bsdf},
                                         {"points_done", result.points_done}};
                for (size_t i = 0; i < result.points_done; ++i) {
                    const ShadingPoint& p = points[i];
                    inputs["points"].push_back({{"normal", {p.normal.x, p.normal.y, p.normal.z}}, {"view", {p.wo.x, p.wo.y, p.wo.z}}});
                }
                if (!args->json.empty()) {
                    nlohmann::json j = {{"inputs", inputs}, {"results", nlohmann::json::array()}};
                    for (const BsdfComparison& b : result.bsdfs) {
                        for (const TechniqueStats& t : b.techniques) j["results"].push_back(stats_json(b, t));
                        j["verdicts"].push_back(verdict(b));
                    }
                    write_file_atomically(args->json, [&](std::ostream& out) { out << j.dump(2) << "\n"; });
                }
                if (!args->csv.empty()) {
                    write_file_atomically(args->csv, [&](std::ostream& out) {
                        out << "map,alpha,spp,seed,points,bsdf,technique,mean,reference,variance,std_error,rel_mse,"
                               "ns_per_estimate,efficiency,variance_ratio_vs_mis\n";
                        for (const BsdfComparison& b : result.bsdfs)
                            for (const TechniqueStats& t : b.techniques)
                                out << loaded.source.name << ',' << compensated.options().compensation.alpha << ',' << options.spp
                                    << ',' << options.seed << ',' << result.points_done << ',' << b.bsdf.name() << ','
                                    << t.technique.name() << ',' << t.mean << ',' << t.reference << ',' << t.variance << ','
                                    << t.std_error << ',' << t.rel_mse << ',' << t.ns_per_estimate << ',' << t.efficiency << ','
                                    << t.variance_ratio_vs_mis << '\n';
                    });
                }
                if (!args->images.empty()) {
                    const auto montage = render_comparison(plain, compensated, options, args->render, args->images,
                                                           loaded.source.name, &interrupted());
                    std::cout << "pictures: " << args->images << " (montage: " << montage.string() << ")\n";
                }
            }};
}

}  // namespace envmis::cli
