// envmis._study: BSDFs, techniques and the variance study (envmis::study), over the maps
// of envmis._maps.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

#include "envmis/study/comparison/comparison.h"
#include "envmis/study/shading/bsdf.h"
#include "envmis/study/techniques/estimator.h"
#include "numpy_arrays.h"
#include "study_alpha.h"
#include "study_arguments.h"
#include "study_compare.h"

namespace py = pybind11;

namespace envmis::python {
namespace {

// Each grey reflectance or parameter a factory takes, in the range parse() accepts.
float checked(double value, double low, double high, const char* where, const char* name) {
    if (!(value >= low && value <= high))
        throw std::invalid_argument(std::string(where) + ": " + name + " must be in [" +
                                    py::str(py::float_(low)).cast<std::string>() + ", " +
                                    py::str(py::float_(high)).cast<std::string>() + "]; got " + std::to_string(value));
    return static_cast<float>(value);
}

Rgb grey_or(const std::optional<double>& albedo, BsdfKind kind, const char* where, const char* name) {
    if (!albedo) return Bsdf::default_reflectance(kind);
    const float a = checked(*albedo, 0, 1, where, name);
    return {a, a, a};
}

const char* kind_name(BsdfKind kind) {
    return kind == BsdfKind::lambert ? "lambert" : kind == BsdfKind::phong ? "phong" : "ggx";
}

Vec3 row3(const float* data, size_t i) { return {data[3 * i], data[3 * i + 1], data[3 * i + 2]}; }

// wo and wi (N, 3) float32 of the same N.
size_t pair_rows(const py::array_t<float, py::array::c_style>& wo, const py::array_t<float, py::array::c_style>& wi,
                 const char* where) {
    if (wo.shape(0) != wi.shape(0))
        throw std::invalid_argument(std::string(where) + ": wo and wi must have as many rows; got " +
                                    std::to_string(wo.shape(0)) + " and " + std::to_string(wi.shape(0)));
    return static_cast<size_t>(wo.shape(0));
}

py::array_t<float> bsdf_eval(const Bsdf& bsdf, const py::handle& wo_in, const py::handle& wi_in) {
    constexpr const char* where = "envmis.Bsdf.eval";
    const auto wo = float_array(wo_in, where, "wo", {-1, 3}), wi = float_array(wi_in, where, "wi", {-1, 3});
    const size_t n = pair_rows(wo, wi, where);
    auto out = new_float_array({static_cast<py::ssize_t>(n), 3});
    float* o = out.mutable_data();
    const float *a = wo.data(), *b = wi.data();
    py::gil_scoped_release release;
    for (size_t i = 0; i < n; ++i) {
        const Rgb v = bsdf.eval(row3(a, i), row3(b, i));
        o[3 * i] = v.r, o[3 * i + 1] = v.g, o[3 * i + 2] = v.b;
    }
    return out;
}

py::array_t<float> bsdf_pdf(const Bsdf& bsdf, const py::handle& wo_in, const py::handle& wi_in) {
    constexpr const char* where = "envmis.Bsdf.pdf";
    const auto wo = float_array(wo_in, where, "wo", {-1, 3}), wi = float_array(wi_in, where, "wi", {-1, 3});
    const size_t n = pair_rows(wo, wi, where);
    auto out = new_float_array({static_cast<py::ssize_t>(n)});
    float* o = out.mutable_data();
    const float *a = wo.data(), *b = wi.data();
    py::gil_scoped_release release;
    for (size_t i = 0; i < n; ++i) o[i] = bsdf.pdf(row3(a, i), row3(b, i));
    return out;
}

py::tuple bsdf_sample(const Bsdf& bsdf, const py::handle& wo_in, const py::handle& u_in) {
    constexpr const char* where = "envmis.Bsdf.sample";
    const auto wo = float_array(wo_in, where, "wo", {-1, 3}), u = float_array(u_in, where, "u", {-1, 2});
    if (wo.shape(0) != u.shape(0))
        throw std::invalid_argument(std::string(where) + ": wo and u must have as many rows; got " +
                                    std::to_string(wo.shape(0)) + " and " + std::to_string(u.shape(0)));
    check_unit_points(u, where, "u");
    const auto n = static_cast<py::ssize_t>(wo.shape(0));
    auto wi = new_float_array({n, 3}), pdf = new_float_array({n}), value = new_float_array({n, 3});
    float *w = wi.mutable_data(), *p = pdf.mutable_data(), *v = value.mutable_data();
    const float *a = wo.data(), *uv = u.data();
    {
        py::gil_scoped_release release;
        for (py::ssize_t i = 0; i < n; ++i) {
            const BsdfSample s = bsdf.sample(row3(a, static_cast<size_t>(i)), {uv[2 * i], uv[2 * i + 1]});
            w[3 * i] = s.wi.x, w[3 * i + 1] = s.wi.y, w[3 * i + 2] = s.wi.z;
            p[i] = s.pdf;
            v[3 * i] = s.value.r, v[3 * i + 1] = s.value.g, v[3 * i + 2] = s.value.b;
        }
    }
    return py::make_tuple(wi, pdf, value);
}

std::vector<std::string> names_of(const std::vector<Technique>& techniques) {
    std::vector<std::string> names;
    for (const Technique& t : techniques) names.push_back(t.name());
    return names;
}

void bind_bsdf(py::module_& m) {
    py::class_<Bsdf>(m, "Bsdf", R"(An analytic reflection BSDF (bsdf.h): Lambert, energy-normalised Phong, GGX.

Directions are unit vectors in the local shading frame (z the normal), pointing away
from the surface (wo towards the viewer, wi towards the light); anything below the
surface reflects nothing. eval returns f(wo, wi) cos(theta_i) (the cosine is included),
pdf the solid-angle density (per steradian) of sample over the whole sphere.)")
        .def_static("parse", &Bsdf::parse, py::arg("text"),
                    "'lambert[:ALBEDO]', 'phong:N[:ALBEDO]' (0 <= N <= 1e5) or 'ggx:A[:F0]' (0.001 <= A <= 1), "
                    "ALBEDO and F0 grey in [0, 1]. ValueError with the command's message otherwise.")
        .def_static(
            "lambert",
            [](std::optional<double> albedo) {
                return Bsdf::lambert(grey_or(albedo, BsdfKind::lambert, "envmis.Bsdf.lambert", "albedo"));
            },
            py::arg("albedo") = py::none(), "Lambertian, grey albedo in [0, 1] (default 0.8).")
        .def_static(
            "phong",
            [](double n, std::optional<double> albedo) {
                constexpr const char* where = "envmis.Bsdf.phong";
                return Bsdf::phong(checked(n, 0, 1e5, where, "n"), grey_or(albedo, BsdfKind::phong, where, "albedo"));
            },
            py::arg("n"), py::arg("albedo") = py::none(),
            "Energy-normalised Phong, exponent n in [0, 1e5], grey specular albedo in [0, 1] (default 0.8).")
        .def_static(
            "ggx",
            [](double alpha, std::optional<double> f0) {
                constexpr const char* where = "envmis.Bsdf.ggx";
                return Bsdf::ggx(checked(alpha, 1e-3, 1, where, "alpha"), grey_or(f0, BsdfKind::ggx, where, "f0"));
            },
            py::arg("alpha"), py::arg("f0") = py::none(),
            "GGX microfacet conductor, roughness alpha in [0.001, 1], grey Schlick F0 in [0, 1] (default "
            "0.95/0.64/0.54, copper-like).")
        .def_property_readonly("name", &Bsdf::name, "The name parse() reads back: 'lambert', 'phong:50', 'ggx:0.1'.")
        .def_property_readonly("kind", [](const Bsdf& b) { return kind_name(b.kind); })
        .def_property_readonly(
            "albedo", [](const Bsdf& b) { return py::make_tuple(b.reflectance.r, b.reflectance.g, b.reflectance.b); },
            "The reflectance (r, g, b): Lambert's albedo, Phong's specular albedo, GGX's F0.")
        .def_property_readonly(
            "exponent", [](const Bsdf& b) { return b.exponent; }, "Phong's n (0 otherwise).")
        .def_property_readonly(
            "alpha", [](const Bsdf& b) { return b.alpha; }, "GGX's roughness (0 otherwise).")
        .def("eval", &bsdf_eval, py::arg("wo"), py::arg("wi"),
             "float32 (N, 3) RGB f(wo, wi) cos(theta_i) for wo, wi float32 (N, 3) local unit vectors. GIL released.")
        .def("pdf", &bsdf_pdf, py::arg("wo"), py::arg("wi"),
             "float32 (N,): the solid-angle density (1/sr) of sample(wo) at wi, over the whole sphere.")
        .def("sample", &bsdf_sample, py::arg("wo"), py::arg("u"),
             "(wi float32 (N, 3), pdf float32 (N,), value float32 (N, 3)) for wo float32 (N, 3) and u float32 (N, 2) "
             "in [0, 1)^2: value is eval(wo, wi), value / pdf the sampling weight; pdf 0 means no sample. A u "
             "outside 0 <= u < 1 (NaN included) raises ValueError naming the first (\"u[3, 0] = 1 is outside "
             "[0, 1)\"), as EnvMap.sample does.")
        .def("__eq__", [](const Bsdf& a, const Bsdf& b) { return a.name() == b.name(); })
        .def("__hash__", [](const Bsdf& b) { return py::hash(py::str(b.name())); })
        .def("__repr__", [](const Bsdf& b) { return "envmis.Bsdf.parse('" + b.name() + "')"; });
}

void bind_technique(py::module_& m) {
    py::class_<Technique>(m, "Technique", R"(An estimator of direct lighting (estimator.h), by name.

'env', 'bsdf', 'mis-balance', 'mis-power', 'mis-optimal', 'mis-var', each MIS name also
with -comp (sampling the compensated density), 'mis-balance-all' and 'mis-optimal-all'
(the mixture), 'mis-balance-bins', 'mis-power-bins', 'mis-optimal-bins',
'one-sample' and 'one-sample-comp'; envmis.techniques() lists them.)")
        .def_static("parse", &Technique::parse, py::arg("name"),
                    "ValueError with the command's message for another name.")
        .def_property_readonly("name", &Technique::name)
        .def_property_readonly("adaptive", &Technique::adaptive,
                               "Learns at each shading point (mis-optimal, mis-var): no exact variance.")
        .def_property_readonly("compensated", [](const Technique& t) { return t.compensated; })
        .def_property_readonly("mixture", [](const Technique& t) { return t.mixture; })
        .def_property_readonly("bins", [](const Technique& t) { return t.bins; })
        .def("__eq__", [](const Technique& a, const Technique& b) { return a == b; })
        .def("__hash__", [](const Technique& t) { return py::hash(py::str(t.name())); })
        .def("__repr__", [](const Technique& t) { return "envmis.Technique.parse('" + t.name() + "')"; });
    m.def(
        "techniques", [] { return names_of(Technique::all()); }, "The names of every technique.");
    m.def(
        "default_techniques", [] { return names_of(ComparisonOptions::default_techniques()); },
        "The techniques compare runs when none are named, in its order.");
}

py::array_t<float> sphere_normals(const py::handle& k) {
    const auto count = static_cast<uint32_t>(count_in_range(k, "envmis.sphere_points", "k", 1, kMaxStudyPoints));
    const std::vector<ShadingPoint> points = sphere_points(count);
    auto out = new_float_array({static_cast<py::ssize_t>(count), 3});
    float* o = out.mutable_data();
    for (size_t i = 0; i < points.size(); ++i)
        o[3 * i] = points[i].normal.x, o[3 * i + 1] = points[i].normal.y, o[3 * i + 2] = points[i].normal.z;
    return out;
}

}  // namespace
}  // namespace envmis::python

PYBIND11_MODULE(_study, m) {
    m.doc() = R"(envmis variance study: BSDFs, techniques, compare, exact variances, choose_alpha.

Units and measures are the C++ headers': directions are unit vectors (world frame for
shading points, local frame for Bsdf methods), pdfs per steradian, radiance linear RGB
in the map's working space, variances those of ONE estimate's luminance (radiance units
squared). Errors are ValueError (or TypeError) with the messages of `envmis compare`.)";
    py::module_::import("envmis._maps");
    using namespace envmis::python;
    bind_bsdf(m);
    bind_technique(m);
    m.def("sphere_points", &sphere_normals, py::arg("k"),
          "float32 (k, 3): k unit normals spread evenly over the sphere (a spherical Fibonacci lattice), world frame; "
          "compare's points=k, each viewed head-on. k 1 to 10^6.");
    bind_compare(m);
    bind_alpha(m);
}
