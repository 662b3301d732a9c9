#include "study_alpha.h"

#include <pybind11/numpy.h>

#include <cmath>
#include <memory>
#include <stdexcept>

#include "envmis/study/reference/quadrature.h"
#include "numpy_arrays.h"
#include "study_arguments.h"

namespace envmis::python {
namespace {

constexpr int kMaxSubdivisions = 16;

std::vector<float> candidates_of(const py::handle& candidates, const char* where) {
    if (candidates.is_none()) return AlphaOptions{}.candidates;
    std::vector<float> values;
    for (const py::handle c : candidates) {
        if (!py::isinstance<py::float_>(c) && !py::isinstance<py::int_>(c))
            throw py::type_error(std::string(where) + ": candidates must be numbers; got " +
                                 py::repr(c).cast<std::string>());
        values.push_back(c.cast<float>());
    }
    return values;
}

// A map's radiance and build options, or a float32 (H, W, 3) radiance array with the
// default options (Rec.709 luma, z up, equirect).
struct RadianceInput {
    RgbImageView radiance;
    EnvMapOptions options;
};

RadianceInput radiance_of(const py::handle& source, const char* where) {
    if (py::isinstance<EnvMap>(source)) {
        const EnvMap& map = source.cast<const EnvMap&>();
        return {map.radiance(), map.options()};
    }
    static_assert(sizeof(Rgb) == 3 * sizeof(float));
    const auto array = float_array(source, where, "radiance", {-1, -1, 3});
    const auto width = static_cast<uint32_t>(array.shape(1)), height = static_cast<uint32_t>(array.shape(0));
    const auto* pixels = reinterpret_cast<const Rgb*>(array.data());
    return {{width, height, {pixels, static_cast<size_t>(width) * height}}, {}};
}

py::dict choose(const py::handle& source, const py::handle& bsdfs, const py::handle& points, const py::handle& normals,
                const py::handle& views, const py::handle& candidates, const py::handle& env_samples,
                const py::handle& bsdf_samples, const py::handle& max_width) {
    constexpr const char* where = "envmis.choose_alpha";
    AlphaOptions options;
    options.bsdfs = bsdf_list(bsdfs, where);
    options.points = shading_points(points, normals, views, where);
    options.candidates = candidates_of(candidates, where);
    options.allocation = allocation_of(env_samples, bsdf_samples, where);
    options.max_width = static_cast<uint32_t>(count_in_range(max_width, where, "max_width", 1, 65536));
    const RadianceInput input = radiance_of(source, where);
    AlphaChoice choice;
    {
        py::gil_scoped_release release;
        choice = choose_alpha(input.radiance, input.options, options);
    }
    return alpha_choice_dict(choice, options.bsdfs);
}

py::array_t<double> exact(const py::handle& map, const py::handle& technique, const py::handle& bsdfs,
                          const py::handle& points, const py::handle& normals, const py::handle& views,
                          const py::handle& env_samples, const py::handle& bsdf_samples,
                          const py::handle& subdivisions) {
    constexpr const char* where = "envmis.exact_variances";
    const Technique t = technique_of(technique, where);
    const std::vector<Bsdf> b = bsdf_list(bsdfs, where);
    const std::vector<ShadingPoint> p = shading_points(points, normals, views, where);
    const Allocation allocation = allocation_of(env_samples, bsdf_samples, where);
    const int s = static_cast<int>(count_in_range(subdivisions, where, "subdivisions", 1, kMaxSubdivisions));
    if (b.empty()) throw std::invalid_argument(std::string(where) + ": needs at least one BSDF");
    std::vector<double> variances;
    if (py::isinstance<BinnedEnvMap>(map)) {
        const BinnedEnvMap& binned = map.cast<const BinnedEnvMap&>();
        py::gil_scoped_release release;
        for (const Bsdf& bsdf : b)
            for (const ShadingPoint& point : p)
                variances.push_back(exact_variance(binned, t, allocation, bsdf, point, s));
    } else {
        const EnvMap& env = map.cast<const EnvMap&>();
        py::gil_scoped_release release;
        variances = exact_variances(env, t, allocation, b, p, s);
    }
    py::array_t<double> result({static_cast<py::ssize_t>(b.size()), static_cast<py::ssize_t>(p.size())});
    std::copy(variances.begin(), variances.end(), result.mutable_data());
    return result;
}

}  // namespace

py::dict alpha_choice_dict(const AlphaChoice& choice, std::span<const Bsdf> bsdfs) {
    py::dict bsdf_alphas;
    for (size_t b = 0; b < bsdfs.size(); ++b) bsdf_alphas[py::str(bsdfs[b].name())] = choice.bsdf_alphas[b];
    py::list candidates;
    for (const AlphaCandidate& c : choice.candidates) {
        py::dict per_bsdf;
        for (size_t b = 0; b < bsdfs.size(); ++b) per_bsdf[py::str(bsdfs[b].name())] = c.per_bsdf[b];
        candidates.append(
            py::dict(py::arg("alpha") = c.alpha, py::arg("criterion") = c.criterion, py::arg("per_bsdf") = per_bsdf));
    }
    return py::dict(py::arg("alpha") = choice.alpha, py::arg("bsdf_alphas") = bsdf_alphas,
                    py::arg("candidates") = candidates, py::arg("width") = choice.width,
                    py::arg("height") = choice.height, py::arg("seconds") = choice.seconds);
}

void bind_alpha(py::module_& m) {
    const auto default_bsdfs = py::make_tuple("lambert", "phong:50", "ggx:0.1");
    m.def("choose_alpha", &choose, py::arg("map"), py::kw_only(), py::arg("bsdfs") = default_bsdfs,
          py::arg("points") = 16, py::arg("normals") = py::none(), py::arg("views") = py::none(),
          py::arg("candidates") = py::none(), py::arg("env_samples") = 1, py::arg("bsdf_samples") = 1,
          py::arg("max_width") = 128, R"(The compensation strength alpha for a map, before any sampling (alpha.h).

Criterion, per candidate alpha: the exact variance of ONE mis-balance-comp estimate over
that of ONE mis-balance estimate (quadrature, no noise), the ratio per (BSDF, shading
point) and its geometric mean over points (per_bsdf) and over all pairs (criterion);
< 1 where compensation helps. The lowest wins (the smallest alpha on a tie); alpha = 0,
criterion exactly 1, is always a candidate. Computed on a copy of the map downsampled
to at most max_width texels wide: the same choice as `envmis compare --alpha auto`
(its JSON inputs.alpha_choice) for the same BSDFs, points and samples.

map: an envmis.EnvMap (its radiance, luma and axes; its compensation is ignored) or a
  float32 (H, W, 3) linear radiance array (Rec.709 luma, z up, equirect).
bsdfs, points / normals, views, env_samples, bsdf_samples: as envmis.compare.
candidates: alphas to try, finite and >= 0 (default 0, 0.25, 0.5, 0.75, 1, 1.25, 1.5, 2, 3).

Returns {"alpha": the map-wide choice, "bsdf_alphas": {bsdf: its own choice},
"candidates": [{"alpha", "criterion", "per_bsdf": {bsdf: criterion}}] (ascending
alpha), "width", "height" (of the downsampled copy), "seconds" (wall time)}.
Cost: (candidates + 1) x BSDFs x points quadratures of the small copy, about 0.2 s with
the defaults on two cores. The GIL is released.)");
    m.def("exact_variances", &exact, py::arg("map"), py::arg("technique"), py::arg("bsdfs") = default_bsdfs,
          py::kw_only(), py::arg("points") = 16, py::arg("normals") = py::none(), py::arg("views") = py::none(),
          py::arg("env_samples") = 1, py::arg("bsdf_samples") = 1, py::arg("subdivisions") = 1,
          R"(The exact variance of ONE estimate's luminance by `technique`, per BSDF and point.

A quadrature (quadrature.h), not a measurement: for MIS the sum over its two techniques
of (integral of f^2 w^2 / p - (integral of f w)^2) / n, f the integrand L f cos, in the
map's radiance units squared; midpoint rule with subdivisions^2 cells per texel.
map: the envmis.EnvMap the technique samples and takes radiance from: for a -comp
  technique pass a compensated map (envmis.compensated_map), for a plain one a map
  without compensation; or an envmis.BinnedEnvMap for a -bins technique.
technique: a fixed-weight technique (not mis-optimal, mis-var or -all: ValueError).
bsdfs, points / normals, views, env_samples, bsdf_samples: as envmis.compare.
Returns float64 (len(bsdfs), points): [b, p] for BSDF b at point p, in point order.
Cost: BSDFs x points x O(w h subdivisions^2) BSDF evaluations, parallel over rows. The
GIL is released.)");
    m.def(
        "compensated_map",
        [](const EnvMap& map, float alpha) {
            if (!(std::isfinite(alpha) && alpha >= 0))
                throw std::invalid_argument("envmis.compensated_map: alpha must be a finite number >= 0; got " +
                                            std::to_string(alpha));
            py::gil_scoped_release release;
            return std::make_shared<EnvMap>(compensated_map(map, alpha));
        },
        py::arg("map"), py::arg("alpha"),
        "A new envmis.EnvMap over map's radiance and options, compensated with strength alpha (>= 0): the density "
        "mis-balance-comp samples in compare. Costs a new build (tens of ms for a 1k map); the GIL is released.");
}

}  // namespace envmis::python
