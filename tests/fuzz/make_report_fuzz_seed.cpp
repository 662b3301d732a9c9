// Writes the seeds of report_fuzz into the folder given: the JSON of compare runs with
// every section report reads (results with per-point variances, the alpha sweep's best
// alphas with auto's choice, the allocation sweep), one with null figures, and a library
// run's summary.
#include <filesystem>
#include <fstream>
#include <iostream>

namespace {

constexpr const char* kFull = R"({"inputs": {"map": "sky.exr", "width": 64, "height": 32, "alpha": 1.0,
 "points_done": 2, "spp": 64, "env_samples": 1, "bsdf_samples": 1},
 "results": [
  {"bsdf": "lambert", "technique": "mis-balance", "mean": 1.0, "reference": 1.0, "variance": 0.5, "std_error": 0.01,
   "rel_mse": 0.5, "ns_per_estimate": 80, "efficiency": 0.025, "variance_ratio_vs_mis": 1.0,
   "point_variances": [0.4, 0.6], "point_variance_rel_se": [0.1, 0.1]},
  {"bsdf": "lambert", "technique": "mis-balance-comp", "mean": 1.0, "reference": 1.0, "variance": 0.3,
   "std_error": 0.01, "rel_mse": 0.3, "ns_per_estimate": 85, "efficiency": 0.04, "variance_ratio_vs_mis": 0.6,
   "point_variances": [0.2, 0.4], "point_variance_rel_se": [0.1, 0.1]},
  {"bsdf": "lambert", "technique": "mis-optimal", "mean": 1.0, "reference": 1.0, "variance": 0.45,
   "std_error": 0.01, "rel_mse": 0.45, "ns_per_estimate": 90, "efficiency": 0.02, "variance_ratio_vs_mis": 0.9,
   "point_variances": [0.35, 0.55], "point_variance_rel_se": [0.1, 0.1]}],
 "sweep_best": [{"bsdf": "lambert", "best_alpha": 1.0, "best_ratio": 0.6, "auto_alpha": 0.9,
   "auto_vs_best": 1.01, "auto_vs_alpha0": 0.61}],
 "allocation": [
  {"bsdf": "lambert", "technique": "mis-balance", "efficiency": 0.02, "env_samples": 1, "bsdf_samples": 3},
  {"bsdf": "lambert", "technique": "mis-balance", "efficiency": 0.03, "env_samples": 2, "bsdf_samples": 2}]})";

constexpr const char* kNulls = R"({"inputs": {"map": "dark.hdr"}, "results": [
  {"bsdf": "phong:20", "technique": "bsdf", "mean": null, "reference": 0, "variance": null, "std_error": null,
   "rel_mse": null, "ns_per_estimate": 10, "efficiency": null, "variance_ratio_vs_mis": null}]})";

constexpr const char* kSummary = R"({"envmis_summary": "compare", "maps": 1, "counts": {"written": 1}, "results": []})";

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::cerr << "usage: " << argv[0] << " DIR\n";
        return 2;
    }
    const std::filesystem::path dir = argv[1];
    std::filesystem::create_directories(dir);
    for (const auto& [name, text] : {std::pair{"full.json", kFull}, {"nulls.json", kNulls}, {"summary.json", kSummary}})
        if (!(std::ofstream(dir / name) << text)) {
            std::cerr << "cannot write " << (dir / name).string() << "\n";
            return 1;
        }
    return 0;
}
