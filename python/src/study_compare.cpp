#include "study_compare.h"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>

#include "envmis/report/inputs.h"
#include "envmis/report/results.h"
#include "study_arguments.h"
#include "study_json.h"
#include "study_watch.h"

namespace envmis::python {
namespace {

constexpr const char* kWhere = "envmis.compare";

// alpha: None (the command's default: the map's own strength if it is compensated, else
// 0 for a map read from a table, which was built so, and --alpha's 1 for one built from
// an image), "auto" or a finite number >= 0.
std::optional<float> fixed_alpha(const py::object& alpha, const EnvMap& map, bool from_table) {
    if (alpha.is_none()) return map.compensated() ? map.options().compensation.alpha : from_table ? 0.0f : 1.0f;
    if (py::isinstance<py::str>(alpha)) {
        if (alpha.cast<std::string>() == "auto") return std::nullopt;
    } else if (py::isinstance<py::float_>(alpha) || py::isinstance<py::int_>(alpha)) {
        const double a = alpha.cast<double>();
        if (std::isfinite(a) && a >= 0 && a <= std::numeric_limits<float>::max()) return static_cast<float>(a);
    }
    throw std::invalid_argument(std::string(kWhere) + ": alpha must be a finite number >= 0 or 'auto'; got " +
                                py::repr(alpha).cast<std::string>());
}

CompareRequest compare_request(const CompareArguments& args, const EnvMap& map) {
    CompareRequest request;
    ComparisonOptions& options = request.options;
    options.bsdfs = bsdf_list(args.bsdfs, kWhere);
    options.techniques = technique_list(args.techniques, kWhere, ComparisonOptions::default_techniques());
    options.spp = static_cast<uint32_t>(count_in_range(args.spp, kWhere, "spp", 1, UINT32_MAX));
    options.seed = count_in_range(args.seed, kWhere, "seed", 0, UINT64_MAX);
    options.allocation = allocation_of(args.env_samples, args.bsdf_samples, kWhere);
    options.threads = worker_threads(args.threads, kWhere);
    request.bins = static_cast<uint32_t>(count_in_range(args.bins, kWhere, "bins", 0, 4096));
    try {
        bins_per_side(request.bins, options.techniques);
    } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(std::string(kWhere) + ": " + e.what());
    }
    request.points = shading_points(args.points, args.normals, args.views, kWhere, args.view_angle);
    request.alpha = fixed_alpha(args.alpha, map, args.from_table);
    // A number fixes the bins' alpha too; with None or 'auto' each bin chooses its own.
    if (request.alpha && !args.alpha.is_none()) request.bin_alpha = request.alpha;
    if (!(args.bin_cost >= 1 && args.bin_cost <= 100))
        throw std::invalid_argument(std::string(kWhere) + ": bin_cost must be 1 to 100; got " +
                                    std::to_string(args.bin_cost));
    request.bin_cost = args.bin_cost;
    return request;
}

// compare --json's "inputs" (without the command's source_hash and options).
py::dict inputs_dict(const CompareSetup& s, const std::string& name, size_t points_done) {
    const nlohmann::json inputs =
        inputs_json({name, s.plain->width(), s.plain->height(), s.map_alpha, s.choice ? &*s.choice : nullptr,
                     &s.options, s.bsdf_alphas, s.binned.get(), s.bins_auto, std::span(s.points).first(points_done)});
    return to_python(inputs).cast<py::dict>();
}

// compare --exact's figures as its JSON holds them: {bsdf: {technique: {ratio, worst, points}}}.
nlohmann::json exact_json(const CompareSetup& s, const std::atomic<bool>& stop) {
    nlohmann::json exact = nlohmann::json::object();
    for (const ExactRatio& r : exact_ratios(s, {&stop, {}}))
        exact[s.options.bsdfs[r.bsdf].name()][r.technique.name()] = {
            {"ratio", r.ratio}, {"worst", r.worst()}, {"points", r.points}};
    return exact;
}

}  // namespace

ComparisonResult run_compare(const EnvMap& map, const CompareArguments& args) {
    CompareRequest request = compare_request(args, map);
    Watch watch;
    watch.progress = args.progress;
    struct Run {
        CompareSetup setup;
        Comparison comparison;
        std::optional<nlohmann::json> exact;
        nlohmann::json records;
    };
    // The caller's map is borrowed: it outlives the call, and the set-up is dropped with it.
    const std::shared_ptr<const EnvMap> borrowed(std::shared_ptr<const EnvMap>(), &map);
    Run run = run_watched(
        [&] {
            Run r{prepare_compare(borrowed, std::move(request), &watch.stop), {}, std::nullopt, {}};
            const CompareSetup& s = r.setup;
            r.comparison = compare(s.inputs(), watch.control());
            if (args.exact && !watch.stop) r.exact = exact_json(s, watch.stop);
            r.records = stats_results_json(r.comparison, [&s](const Bsdf& b) { return s.alpha_of(b); });
            return r;
        },
        watch);
    ComparisonResult result{std::move(run.comparison), py::list(), py::dict(), py::none()};
    result.records = to_python(run.records).cast<py::list>();
    result.inputs = inputs_dict(run.setup, args.name, result.comparison.points_done);
    if (run.exact) result.exact = to_python(*run.exact);
    return result;
}

}  // namespace envmis::python

namespace envmis::python {
namespace {

const TechniqueStats& stats_of(const ComparisonResult& result, const py::handle& bsdf, const py::handle& technique) {
    constexpr const char* where = "envmis.Comparison";
    const std::string b = bsdf_of(bsdf, where).name(), t = technique_of(technique, where).name();
    std::string names;
    for (const BsdfComparison& bc : result.comparison.bsdfs) {
        if (bc.bsdf.name() != b) {
            names += (names.empty() ? "" : ", ") + bc.bsdf.name();
            continue;
        }
        if (const TechniqueStats* stats = bc.find(t)) return *stats;
        throw py::key_error(std::string(where) + ": no technique " + t + " in this comparison");
    }
    throw py::key_error(std::string(where) + ": no BSDF " + b + " in this comparison (it has " + names + ")");
}

// The map's name in inputs: `name`, or where None the source file's name that
// envmis.load recorded (EnvMap.source["name"]; empty for a map made from an array).
std::string name_of(const py::object& map, const py::object& name) {
    if (!name.is_none()) return name.cast<std::string>();
    if (!py::hasattr(map, "source")) return "";
    const py::object source = map.attr("source");
    return py::isinstance<py::dict>(source) && source.contains("name") ? source["name"].cast<std::string>() : "";
}

// True for a map that envmis.load_table (or load of a table) read: EnvMap.from_table,
// which a map made outside envmis._maps does not have.
bool from_table(const py::object& map) { return py::hasattr(map, "from_table") && map.attr("from_table").cast<bool>(); }

py::array_t<double> copy_of(const std::vector<double>& values) {
    return py::array_t<double>(static_cast<py::ssize_t>(values.size()), values.data());
}

constexpr const char* kCompareDoc = R"(The variance study of `envmis compare`, on one map.

Every technique estimates direct lighting L_o (the luminance of reflected radiance, in
the map's radiance units) on every BSDF at every shading point, spp estimates each,
every technique spending env_samples + bsdf_samples samples per estimate (equal sample
count). Each BSDF samples its own compensated map (alpha). The same arguments and seed
give the same records as `envmis compare MAP --json` (every key but the measured
timings ns_per_estimate, efficiency and efficiency_ratio_vs_mis), whatever the number of
threads.

map: an envmis.EnvMap; its radiance is studied (rebuilt without compensation where it
  has some); its own compensation strength is only the default of alpha.
bsdfs: names ('lambert', 'phong:50', 'ggx:0.1', as --bsdf; also one comma-separated
  str) or envmis.Bsdf objects.
techniques: names or envmis.Technique objects; None: envmis.default_techniques().
spp: estimates per point, BSDF and technique, 1 to 2^32-1.
points: K normals spread evenly over the sphere (1 to 10^6), each viewed head-on;
  or normals: float32 (N, 3) unit vectors, world frame, with views (N, 3) (towards
  the viewer; default the normal).
seed: 0 to 2^64-1. threads: workers (0: every usable core: the CPU affinity and cgroup quota).
alpha: the compensation strength, >= 0; 'auto' chooses it per BSDF (envmis.choose_alpha
  over these BSDFs and points); None: the map's own if compensated, else 0 for a map
  read from a table (map.from_table) and 1 for one built from an image, as the command's
  default. The -bins
  techniques choose theirs per bin unless alpha is a number.
env_samples, bsdf_samples: samples per MIS estimate, 0 to 65536.
bins: normal bins K = g*g (1 <= g <= 64) of the -bins techniques; 0: 121 where one runs.
view_angle: degrees (0 to 89.9) between each of the `points` normals and its view, as
  --view-angle (with normals, 0: their views say it).
bin_cost: the bins' cost (1 to 100), as --bin-cost: a bin keeps compensation only where
  it is predicted that much lower in variance.
exact: also the exact, noise-free variance ratios of compare --exact (.exact).
name: the map's name in .inputs (None: the file name envmis.load recorded). progress: None or a callable (done, total) called on
  this thread as points complete.

Cost: points x BSDFs x techniques x spp estimates (tens of ns each) plus a quadrature
reference per point and BSDF. The GIL is released; Ctrl-C stops the run between points
(or every few thousand estimates) and raises KeyboardInterrupt, as does an exception
from progress. Raises ValueError with the command's messages.)";

}  // namespace

void bind_compare(py::module_& m) {
    py::class_<ComparisonResult>(m, "Comparison", R"(The result of envmis.compare.

records: compare --json's "results": a dict per BSDF and technique (in that order) with
  bsdf, technique, alpha, estimates, mean, reference (luminance of L_o, the map's
  radiance units), variance (of ONE estimate, radiance units squared, mean over
  points), std_error, rel_mse, ns_per_estimate, efficiency, variance_ratio_vs_mis
  (geometric mean over points of variance / that of mis-balance), variance_ratio_worst
  (the largest of those per-point ratios), efficiency_ratio_vs_mis (at equal time, > 1
  better), variance_ratio_log_std_error, ill_conditioned_points, point_variances and
  point_variance_rel_se (per point, in point order). A non-finite value is None, as in
  the JSON file.
inputs: compare --json's "inputs" (map, width, height, alpha, alpha_auto, bsdf_alpha,
  spp, seed, threads, env_samples, bsdf_samples, points_done, albedo, points, bins,
  alpha_choice), written by the command's own code (envmis/report/inputs.h); only its
  source_hash and options are the command's alone.
exact: with exact=True, {bsdf: {technique: {"ratio", "worst"}}}: exact variance over
  that of mis-balance, geometric mean over points and the worst point; else None.)")
        .def_readonly("records", &ComparisonResult::records)
        .def_readonly("inputs", &ComparisonResult::inputs)
        .def_readonly("exact", &ComparisonResult::exact)
        .def_property_readonly("points_done", [](const ComparisonResult& r) { return r.comparison.points_done; })
        .def_property_readonly("points_total", [](const ComparisonResult& r) { return r.comparison.points_total; })
        .def_property_readonly("bsdfs",
                               [](const ComparisonResult& r) {
                                   std::vector<std::string> names;
                                   for (const BsdfComparison& b : r.comparison.bsdfs) names.push_back(b.bsdf.name());
                                   return names;
                               })
        .def(
            "point_variances",
            [](const ComparisonResult& r, const py::handle& bsdf, const py::handle& technique) {
                return copy_of(stats_of(r, bsdf, technique).point_variances);
            },
            py::arg("bsdf"), py::arg("technique"),
            "float64 (points_done,): the variance of ONE estimate at each shading point, in point order (radiance "
            "units squared); a copy. KeyError for a BSDF or technique not in the study.")
        .def(
            "point_variance_rel_se",
            [](const ComparisonResult& r, const py::handle& bsdf, const py::handle& technique) {
                return copy_of(stats_of(r, bsdf, technique).point_variance_rel_se);
            },
            py::arg("bsdf"), py::arg("technique"),
            "float64 (points_done,): the relative standard error of each point's variance estimate; a copy.")
        .def("__repr__", [](const ComparisonResult& r) {
            return "<envmis.Comparison: " + std::to_string(r.comparison.bsdfs.size()) + " BSDFs, " +
                   std::to_string(py::len(r.records)) + " records, " + std::to_string(r.comparison.points_done) +
                   " of " + std::to_string(r.comparison.points_total) + " points>";
        });

    m.def(
        "compare",
        [](const py::object& map, py::object bsdfs, py::object techniques, py::object spp, py::object points,
           py::object normals, py::object views, py::object seed, py::object threads, py::object alpha,
           py::object env_samples, py::object bsdf_samples, py::object bins, double view_angle, float bin_cost,
           bool exact, py::object name, py::object progress) {
            if (!py::isinstance<EnvMap>(map))
                throw py::type_error(std::string(kWhere) + ": map must be an envmis.EnvMap; got " +
                                     py::str(py::type::of(map).attr("__name__")).cast<std::string>());
            return run_compare(
                map.cast<const EnvMap&>(),
                {bsdfs, techniques, spp, points, normals, views, seed, threads, alpha, env_samples, bsdf_samples, bins,
                 view_angle, bin_cost, exact, from_table(map), name_of(map, name), progress});
        },
        py::arg("map"), py::kw_only(), py::arg("bsdfs") = py::make_tuple("lambert", "phong:50", "ggx:0.1"),
        py::arg("techniques") = py::none(), py::arg("spp") = 1024, py::arg("points") = 16,
        py::arg("normals") = py::none(), py::arg("views") = py::none(), py::arg("seed") = 1, py::arg("threads") = 0,
        py::arg("alpha") = py::none(), py::arg("env_samples") = 1, py::arg("bsdf_samples") = 1, py::arg("bins") = 0,
        py::arg("view_angle") = 0.0, py::arg("bin_cost") = BinnedOptions{}.cost, py::arg("exact") = false,
        py::arg("name") = py::none(), py::arg("progress") = py::none(), kCompareDoc);
}

}  // namespace envmis::python
