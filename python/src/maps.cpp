// envmis._maps: maps, tables and sampling, with NumPy arrays in and out.
//
// envmis::EnvMap and envmis::BinnedEnvMap are bound as themselves, each held by a
// std::shared_ptr (py::class_<EnvMap, std::shared_ptr<EnvMap>>), so that envmis._study,
// which imports this module, takes them as arguments (const EnvMap&,
// std::shared_ptr<const BinnedEnvMap>) through pybind11's shared type registry. A binned
// map's `plain` is a map of its own, its distribution rebuilt (BinnedEnvMap::plain_map).
//
// What a C++ map does not hold, where it came from (TableSource), how (the request, or a
// table file) and whether its radiance maps a table file, rides in its shared_ptr's
// deleter (Provenance), so that it follows the map into every Python object of it. A
// binned map's plain map has its own: a table of it records what it is, not the bins.
// The density, which EnvMap does not keep (its buffer became the CDF), is computed on
// first access and kept in the Python object's __dict__.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <optional>
#include <random>
#include <sstream>
#include <string_view>
#include <type_traits>
#include <utility>

#include "envmis/io/image_io.h"
#include "maps_batch.h"
#include "maps_build.h"
#include "maps_docs.h"
#include "numpy_arrays.h"

namespace envmis::python {
namespace {

struct Provenance {
    TableSource source;
    bool mapped = false;
    std::optional<BuildRequest> request;  // what built it; empty for a table
    bool from_table = false;              // read from a table file
    bool compact = false;                 // that table's payload was RGBE (rounded radiance)
};

template <class T>
struct Deleter {
    Provenance provenance;
    void operator()(T* map) const noexcept { delete map; }
};

template <class T>
std::shared_ptr<T> held(T map, Provenance provenance) {
    return std::shared_ptr<T>(new T(std::move(map)), Deleter<T>{std::move(provenance)});
}

// Maps made elsewhere (by envmis._study, say) have none: an empty source.
template <class T>
Provenance provenance_of(const std::shared_ptr<T>& map) {
    if (const auto* d = std::get_deleter<Deleter<EnvMap>>(map)) return d->provenance;
    if (const auto* d = std::get_deleter<Deleter<BinnedEnvMap>>(map)) return d->provenance;
    return {};
}

// A binned map's plain map: for a build, the request of that map alone (precompute
// --no-compensate: with bins the texels keep the plain density); for a table, an
// unknown request (no options recorded, so precompute's library mode rebuilds it).
std::shared_ptr<EnvMap> plain_of(const std::shared_ptr<BinnedEnvMap>& map) {
    Provenance provenance = provenance_of(map);
    if (provenance.request) {
        BuildRequest& r = *provenance.request;
        r.compensate = false, r.alpha.reset(), r.alpha_auto = false, r.bins = 0, r.cell_columns = 0;
        provenance.source.build_options = canonical_options(r);
    } else {
        provenance.source.build_options.clear();
    }
    return held(map->plain_map(), std::move(provenance));
}

py::object to_python(Built built) {
    const py::object warn = py::module_::import("warnings").attr("warn");
    for (const std::string& notice : built.notices) warn(notice, py::arg("stacklevel") = 2);
    Provenance provenance{std::move(built.source), built.mapped, std::move(built.request), built.from_table,
                          built.compact};
    if (built.binned) return py::cast(held(std::move(*built.binned), std::move(provenance)));
    return py::cast(held(std::move(built.map), std::move(provenance)));
}

// alpha: None (not given), a number, or "auto"; the messages are the command line's.
BuildRequest build_request(bool compensate, const py::object& alpha, std::string axes, std::string mapping,
                           const py::object& colorspace, std::string working_space) {
    BuildRequest o;
    o.compensate = compensate;
    if (py::isinstance<py::str>(alpha)) {
        // Among strings only "auto": a number given as a string ("0.5") is refused rather
        // than read, as Python reads no str as a float.
        const auto text = alpha.cast<std::string>();
        if (text != "auto") {
            const std::string problem = alpha_problem(text);
            throw std::invalid_argument(
                "alpha: " +
                (problem.empty() ? "'" + text + "': expected a number >= 0 or auto (a number, not a str)" : problem));
        }
        o.alpha_auto = true;
    } else if (!alpha.is_none()) {
        o.alpha = alpha.cast<float>();
    }
    o.axes = std::move(axes);
    o.mapping = std::move(mapping);
    if (!colorspace.is_none()) o.colorspace = colorspace.cast<std::string>();
    o.working_space = std::move(working_space);
    return o;
}

py::dict source_dict(const TableSource& s) {
    py::dict d;
    d["name"] = s.name, d["content_hash"] = s.content_hash;
    d["input_colorspace"] = s.input_colorspace, d["working_colorspace"] = s.working_colorspace;
    d["build_options"] = s.build_options;
    return d;
}

// The source a table of the map records, its build options describing exactly what is
// saved: for a map built here, the canonical options of its request with the table's
// own encoding, as `envmis precompute` records them; for a map read from a table, that
// table's request with its encoding replaced. A compact (RGBE-rounded) table saved full
// is no build of the source, nor are options in no canonical form (an older table's):
// they record none, so that precompute's library mode rebuilds them.
template <class T>
TableSource saved_source(const std::shared_ptr<T>& map, bool compact) {
    Provenance provenance = provenance_of(map);
    std::string& options = provenance.source.build_options;
    std::optional<BuildRequest> request = provenance.request;
    if (!request && provenance.from_table) request = parse_canonical_options(options);
    if (request && !(provenance.from_table && provenance.compact && !compact)) {
        request->compact = compact;
        options = canonical_options(*request);
    } else if (provenance.from_table) {
        options.clear();
    }
    return provenance.source;
}

py::dict stats_dict(const EnvMapStats& s) {
    py::dict d;
    visit_stats_fields(s, [&d](const char* name, const auto& value) {
        using Value = std::decay_t<decltype(value)>;
        if constexpr (std::is_same_v<Value, BadPixels>) {
            py::dict bad;
            bad["nan"] = value.nan, bad["infinite"] = value.infinite, bad["negative"] = value.negative;
            d[name] = bad;
        } else if constexpr (std::is_same_v<Value, std::string_view>) {
            d[name] = std::string(value);
        } else {
            d[name] = value;
        }
    });
    return d;
}

py::dict options_dict(const EnvMapOptions& o) {
    py::dict d;
    d["compensate"] = o.compensation.enabled, d["alpha"] = o.compensation.alpha;
    d["axes"] = o.axes.to_string(), d["mapping"] = std::string(to_string(o.mapping));
    d["luma"] = py::make_tuple(o.luma.r, o.luma.g, o.luma.b);
    return d;
}

// The density, computed once per Python object (EnvMap::density(): O(w h)).
py::object density_view(const py::object& self) {
    const py::dict cache = self.attr("__dict__");
    if (cache.contains("_density")) return cache["_density"];
    const auto& map = self.cast<const EnvMap&>();
    auto values = std::make_unique<std::vector<float>>();
    {
        py::gil_scoped_release released;
        *values = map.density();
    }
    const float* data = values->data();
    const py::capsule owner(values.release(), [](void* p) { delete static_cast<std::vector<float>*>(p); });
    py::object view = read_only_view(data, {map.height(), map.width()}, owner);
    cache["_density"] = view;
    return view;
}

py::object radiance_view(const py::object& self) {
    const auto& map = self.cast<const EnvMap&>();
    return read_only_view(reinterpret_cast<const float*>(map.radiance().pixels.data()), {map.height(), map.width(), 3},
                          self);
}

std::shared_ptr<EnvMap> from_array(const py::object& radiance, const BuildRequest& options) {
    const auto array = float_array(radiance, "envmis.EnvMap", "radiance", {-1, -1, 3}, "HW");
    if (array.shape(0) > UINT32_MAX || array.shape(1) > UINT32_MAX)
        throw std::invalid_argument("envmis.EnvMap: radiance: more than 2^32 - 1 rows or columns");
    RgbImage image{static_cast<uint32_t>(array.shape(1)), static_cast<uint32_t>(array.shape(0)),
                   RgbPixels(static_cast<size_t>(array.shape(0)) * array.shape(1))};
    std::memcpy(static_cast<void*>(image.pixels.data()), array.data(), image.pixels.size() * sizeof(Rgb));
    Built built;
    {
        py::gil_scoped_release released;
        built = from_pixels(std::move(image), options);
    }
    return held(std::move(built.map), {std::move(built.source), false, std::move(built.request), false, false});
}

// The outputs of sample for n points, as the Samples named tuple: new arrays, or the
// caller's `out` (a Samples of arrays of the right shapes) to write into.
struct SampleOutputs {
    py::array_t<float> direction, pdf, radiance, uv;
    SampleOutputs(py::ssize_t n, const py::object& out, const char* where) {
        if (out.is_none()) {
            direction = new_float_array({n, 3}), pdf = new_float_array({n});
            radiance = new_float_array({n, 3}), uv = new_float_array({n, 2});
            return;
        }
        direction = writeable_float_array(out.attr("direction"), where, "out.direction", {n, 3});
        pdf = writeable_float_array(out.attr("pdf"), where, "out.pdf", {n});
        radiance = writeable_float_array(out.attr("radiance"), where, "out.radiance", {n, 3});
        uv = writeable_float_array(out.attr("uv"), where, "out.uv", {n, 2});
    }
    InterleavedSamples arrays() {
        return {direction.mutable_data(), pdf.mutable_data(), radiance.mutable_data(), uv.mutable_data()};
    }
    py::object to_python() const {
        return py::module_::import("envmis._maps").attr("Samples")(direction, pdf, radiance, uv);
    }
};

py::object sample_plain(const EnvMap& map, const py::object& u_object, const py::object& out_object) {
    const char* where = "envmis.EnvMap.sample";
    const auto u = float_array(u_object, where, "u", {-1, 2});
    check_unit_points(u, where, "u");
    SampleOutputs out(u.shape(0), out_object, where);
    const InterleavedSamples arrays = out.arrays();
    {
        py::gil_scoped_release released;
        sample(map.view(), u.data(), arrays, static_cast<size_t>(u.shape(0)));
    }
    return out.to_python();
}

py::array_t<float> lookup_plain(const EnvMap& map, const py::object& directions_object, bool pdf) {
    const char* where = pdf ? "envmis.EnvMap.pdf" : "envmis.EnvMap.eval";
    const auto directions = float_array(directions_object, where, "directions", {-1, 3});
    const py::ssize_t n = directions.shape(0);
    py::array_t<float> out = pdf ? new_float_array({n}) : new_float_array({n, 3});
    float* data = out.mutable_data();
    {
        py::gil_scoped_release released;
        lookup(map.view(), directions.data(), {pdf ? data : nullptr, pdf ? nullptr : data}, static_cast<size_t>(n));
    }
    return out;
}

// Normals for n points: (n, 3), n the length of the other argument, as float32.
py::array_t<float, py::array::c_style> normals_for(const py::object& normals, const char* where, py::ssize_t n,
                                                   const char* other) {
    auto array = float_array(normals, where, "normals", {-1, 3});
    if (array.shape(0) != n)
        throw std::invalid_argument(
            std::string(where) + ": normals must be an array of shape (N, 3) with N = " + std::to_string(n) +
            ", the length of " + other + "; got " + std::to_string(array.shape(0)) + " normals");
    return array;
}

// Picks among the bins around each normal: float32 (n,) in [0, 1).
// One value per normal (as float32), each in [0, 1) or, with `closed`, [0, 1]; `name` in the messages.
py::array_t<float, py::array::c_style> unit_values(const py::object& values, const char* where, const char* name,
                                                   py::ssize_t n, bool closed) {
    auto array = float_array(values, where, name, {-1});
    if (array.shape(0) != n)
        throw std::invalid_argument(std::string(where) + ": " + name + " must be an array of shape (N,) with N = " +
                                    std::to_string(n) + ", one per normal; got " + std::to_string(array.shape(0)));
    for (py::ssize_t i = 0; i < n; ++i) {
        const float x = array.data()[i];
        if (!(x >= 0.0f && (closed ? x <= 1.0f : x < 1.0f)))
            throw std::invalid_argument(std::string(where) + ": " + name + "[" + std::to_string(i) +
                                        "] = " + std::to_string(x) + " is outside [0, 1" + (closed ? "]" : ")"));
    }
    return array;
}

py::array_t<float, py::array::c_style> choices_for(const py::object& choices, const char* where, py::ssize_t n) {
    return unit_values(choices, where, "choices", n, false);
}

// Each point's view cosine (LobeAxis::view_cos): in [0, 1]; 1 (head-on) where None.
py::array_t<float, py::array::c_style> view_cos_for(const py::object& view_cos, const char* where, py::ssize_t n) {
    if (!view_cos.is_none()) return unit_values(view_cos, where, "view_cos", n, true);
    py::array_t<float, py::array::c_style> ones(n);
    std::fill_n(ones.mutable_data(), n, 1.0f);
    return ones;
}

uint32_t lobe_of(const BinnedEnvMap& map, uint32_t lobe, const char* where) {
    if (lobe >= map.classes())
        throw std::invalid_argument(std::string(where) + ": lobe " + std::to_string(lobe) +
                                    " is not a lobe class of this map (0 to " + std::to_string(map.classes() - 1) +
                                    ")");
    return lobe;
}

py::object sample_binned(const BinnedEnvMap& map, const py::object& u_object, const py::object& normals_object,
                         const py::object& choices_object, uint32_t lobe, const py::object& view_cos_object,
                         const py::object& out_object) {
    const char* where = "envmis.BinnedEnvMap.sample";
    const auto u = float_array(u_object, where, "u", {-1, 2});
    check_unit_points(u, where, "u");
    const auto normals = normals_for(normals_object, where, u.shape(0), "u");
    const auto choices = choices_for(choices_object, where, u.shape(0));
    const auto view_cos = view_cos_for(view_cos_object, where, u.shape(0));
    lobe_of(map, lobe, where);
    SampleOutputs out(u.shape(0), out_object, where);
    const InterleavedSamples arrays = out.arrays();
    {
        py::gil_scoped_release released;
        sample(map.view(), lobe, normals.data(), view_cos.data(), choices.data(), u.data(), arrays,
               static_cast<size_t>(u.shape(0)));
    }
    return out.to_python();
}

py::array_t<float> pdf_binned(const BinnedEnvMap& map, const py::object& directions_object,
                              const py::object& normals_object, const py::object& choices_object, uint32_t lobe,
                              const py::object& view_cos_object) {
    const char* where = "envmis.BinnedEnvMap.pdf";
    const auto directions = float_array(directions_object, where, "directions", {-1, 3});
    const py::ssize_t n = directions.shape(0);
    const auto normals = normals_for(normals_object, where, n, "directions");
    const auto choices = choices_for(choices_object, where, n);
    const auto view_cos = view_cos_for(view_cos_object, where, n);
    lobe_of(map, lobe, where);
    py::array_t<float> out = new_float_array({n});
    float* data = out.mutable_data();
    {
        py::gil_scoped_release released;
        lookup(map.view(), lobe, normals.data(), view_cos.data(), choices.data(), directions.data(), {data, nullptr},
               static_cast<size_t>(n));
    }
    return out;
}

std::string describe(const EnvMap& map, const TableSource& source) {
    std::ostringstream text;
    text << map.width() << "x" << map.height() << " " << to_string(map.options().mapping) << ", ";
    if (map.compensated())
        text << "compensated (alpha " << map.options().compensation.alpha << ")";
    else
        text << "uncompensated";
    if (!source.name.empty()) text << ", from " << source.name;
    return text.str();
}

void bind_envmap(py::module_& m) {
    py::class_<EnvMap, std::shared_ptr<EnvMap>>(m, "EnvMap", py::dynamic_attr(), docs::kEnvMap)
        .def(py::init([](const py::object& radiance, bool compensate, const py::object& alpha, std::string axes,
                         std::string mapping, const py::object& colorspace, std::string working_space) {
                 return from_array(radiance, build_request(compensate, alpha, std::move(axes), std::move(mapping),
                                                           colorspace, std::move(working_space)));
             }),
             py::arg("radiance"), py::kw_only(), py::arg("compensate") = true, py::arg("alpha") = 1.0f,
             py::arg("axes") = "z-up", py::arg("mapping") = "equirect", py::arg("colorspace") = py::none(),
             py::arg("working_space") = "lin_rec709", docs::kEnvMapInit)
        .def_property_readonly("width", &EnvMap::width, "Columns of the image (texels).")
        .def_property_readonly("height", &EnvMap::height, "Rows of the image (texels).")
        .def_property_readonly("compensated", &EnvMap::compensated, docs::kCompensated)
        .def_property_readonly("complete", &EnvMap::complete, docs::kComplete)
        .def_property_readonly(
            "options", [](const EnvMap& map) { return options_dict(map.options()); }, docs::kOptions)
        .def_property_readonly(
            "stats", [](const EnvMap& map) { return stats_dict(map.stats()); }, docs::kStats)
        .def_property_readonly(
            "source", [](const std::shared_ptr<EnvMap>& map) { return source_dict(provenance_of(map).source); },
            docs::kSource)
        .def_property_readonly(
            "mapped", [](const std::shared_ptr<EnvMap>& map) { return provenance_of(map).mapped; }, docs::kMapped)
        .def_property_readonly(
            "from_table", [](const std::shared_ptr<EnvMap>& map) { return provenance_of(map).from_table; },
            docs::kFromTable)
        .def_property_readonly("radiance", &radiance_view, docs::kRadiance)
        .def_property_readonly("density", &density_view, docs::kDensity)
        .def("sample", &sample_plain, py::arg("u"), py::kw_only(), py::arg("out") = py::none(), docs::kSample)
        .def(
            "pdf", [](const EnvMap& map, const py::object& d) { return lookup_plain(map, d, true); },
            py::arg("directions"), docs::kPdf)
        .def(
            "eval", [](const EnvMap& map, const py::object& d) { return lookup_plain(map, d, false); },
            py::arg("directions"), docs::kEval)
        .def(
            "save",
            [](const std::shared_ptr<EnvMap>& map, const std::filesystem::path& path, bool compact) {
                const TableSource source = saved_source(map, compact);
                py::gil_scoped_release released;
                write_table(path, *map, source, compact ? TableEncoding::compact : TableEncoding::full);
            },
            py::arg("path"), py::kw_only(), py::arg("compact") = false, docs::kSave)
        .def("__repr__", [](const std::shared_ptr<EnvMap>& map) {
            return "<envmis.EnvMap " + describe(*map, provenance_of(map).source) + ">";
        });
}

void bind_binned(py::module_& m) {
    py::class_<BinnedEnvMap, std::shared_ptr<BinnedEnvMap>>(m, "BinnedEnvMap", py::dynamic_attr(), docs::kBinned)
        .def_property_readonly("plain", &plain_of, docs::kPlain)
        .def_property_readonly("width", [](const BinnedEnvMap& map) { return map.radiance_map().width(); })
        .def_property_readonly("height", [](const BinnedEnvMap& map) { return map.radiance_map().height(); })
        .def_property_readonly("bins", &BinnedEnvMap::bins,
                               "K = g^2, the bins of normals of each glossy class (a g x g octahedral grid).")
        .def_property_readonly("diffuse_bins", &BinnedEnvMap::diffuse_bins,
                               "The diffuse class's bins of normals (by default (2 g - 1)^2).")
        .def_property_readonly("classes", &BinnedEnvMap::classes, "The lobe classes (lobe arguments 0 to classes - 1).")
        .def_property_readonly(
            "lobe_exponents", [](const BinnedEnvMap& map) { return map.layout().lobe_exponents; }, docs::kExponents)
        .def(
            "lobe_class",
            [](const BinnedEnvMap& map, float exponent) {
                if (!(exponent >= 0 && std::isfinite(exponent)))
                    throw py::value_error("phong_exponent: expected a finite number >= 0, got " +
                                          std::to_string(exponent));
                return map.lobe_class(exponent);
            },
            py::arg("phong_exponent"), docs::kLobeClass)
        .def(
            "complete",
            [](const BinnedEnvMap& map, uint32_t lobe) {
                if (lobe >= map.classes())
                    throw py::value_error("lobe: " + std::to_string(lobe) + " is not a class (0 to " +
                                          std::to_string(map.classes() - 1) + ")");
                return map.complete(lobe);
            },
            py::arg("lobe"), docs::kBinnedComplete)
        .def_property_readonly(
            "source", [](const std::shared_ptr<BinnedEnvMap>& map) { return source_dict(provenance_of(map).source); },
            docs::kSource)
        .def_property_readonly(
            "mapped", [](const std::shared_ptr<BinnedEnvMap>& map) { return provenance_of(map).mapped; }, docs::kMapped)
        .def_property_readonly(
            "from_table", [](const std::shared_ptr<BinnedEnvMap>& map) { return provenance_of(map).from_table; },
            docs::kFromTable)
        .def("sample", &sample_binned, py::arg("u"), py::arg("normals"), py::arg("choices"), py::arg("lobe") = 0,
             py::kw_only(), py::arg("view_cos") = py::none(), py::arg("out") = py::none(), docs::kBinnedSample)
        .def("pdf", &pdf_binned, py::arg("directions"), py::arg("normals"), py::arg("choices"), py::arg("lobe") = 0,
             py::kw_only(), py::arg("view_cos") = py::none(), docs::kBinnedPdf)
        .def(
            "eval",
            [](const BinnedEnvMap& map, const py::object& d) { return lookup_plain(map.radiance_map(), d, false); },
            py::arg("directions"), docs::kEval)
        .def(
            "save",
            [](const std::shared_ptr<BinnedEnvMap>& map, const std::filesystem::path& path, bool compact) {
                const TableSource source = saved_source(map, compact);
                py::gil_scoped_release released;
                write_table(path, *map, source, compact ? TableEncoding::compact : TableEncoding::full);
            },
            py::arg("path"), py::kw_only(), py::arg("compact") = false, docs::kSave)
        .def("__repr__", [](const std::shared_ptr<BinnedEnvMap>& map) {
            return "<envmis.BinnedEnvMap " + std::to_string(map->bins()) + " bins over " +
                   describe(map->radiance_map(), provenance_of(map).source) + ">";
        });
}

// The u that `envmis sample` draws for a seed (cmd_sample.cpp): mt19937_64, 24 bits a
// coordinate, u.x then u.y.
py::array_t<float> uniform_points(py::ssize_t n, uint64_t seed) {
    if (n < 0) throw std::invalid_argument("envmis.uniform_points: n must be >= 0; got " + std::to_string(n));
    py::array_t<float> out = new_float_array({n, 2});
    float* data = out.mutable_data();
    py::gil_scoped_release released;
    std::mt19937_64 rng(seed);
    for (py::ssize_t i = 0; i < 2 * n; ++i) data[i] = static_cast<float>(rng() >> 40) * 0x1p-24f;
    return out;
}

void bind_functions(py::module_& m) {
    m.def(
        "load",
        [](const std::filesystem::path& path, bool compensate, const py::object& alpha, std::string axes,
           std::string mapping, const py::object& colorspace, std::string working_space, uint32_t bins,
           uint32_t cell_columns, float bin_cost) {
            BuildRequest o = build_request(compensate, alpha, std::move(axes), std::move(mapping), colorspace,
                                           std::move(working_space));
            o.bins = bins, o.cell_columns = cell_columns, o.bin_cost = bin_cost;
            Built built;
            {
                py::gil_scoped_release released;
                built = load(path, o);
            }
            return to_python(std::move(built));
        },
        py::arg("path"), py::kw_only(), py::arg("compensate") = true, py::arg("alpha") = py::none(),
        py::arg("axes") = "z-up", py::arg("mapping") = "equirect", py::arg("colorspace") = py::none(),
        py::arg("working_space") = "lin_rec709", py::arg("bins") = 0, py::arg("cell_columns") = 0,
        py::arg("bin_cost") = BinnedOptions{}.cost, docs::kLoad);
    m.def(
        "load_table",
        [](const std::filesystem::path& path, bool mapped) {
            Built built;
            {
                py::gil_scoped_release released;
                built = load_table(path, mapped);
            }
            return to_python(std::move(built));
        },
        py::arg("path"), py::kw_only(), py::arg("mapped") = true, docs::kLoadTable);
    m.def("uniform_points", &uniform_points, py::arg("n"), py::arg("seed"), docs::kUniformPoints);
    m.def(
        "_time_sample_many",
        [](const EnvMap& map, const py::object& u_object, int repeats, bool fresh_outputs) {
            const auto u = float_array(u_object, "envmis._time_sample_many", "u", {-1, 2});
            check_unit_points(u, "envmis._time_sample_many", "u");
            if (repeats < 1) throw std::invalid_argument("envmis._time_sample_many: repeats must be >= 1");
            py::gil_scoped_release released;
            return time_sample_many(map.view(), u.data(), static_cast<size_t>(u.shape(0)), repeats, fresh_outputs);
        },
        py::arg("map"), py::arg("u"), py::arg("repeats"), py::kw_only(), py::arg("fresh_outputs") = false,
        docs::kTimeSampleMany);
}

}  // namespace
}  // namespace envmis::python

PYBIND11_MODULE(_maps, m) {
    using namespace envmis::python;
    m.doc() = docs::kModule;
    py::register_exception<envmis::io::ImageError>(m, "ImageError", PyExc_OSError).doc() = docs::kImageError;
    py::register_exception<envmis::TableError>(m, "TableError", PyExc_OSError).doc() = docs::kTableError;
    const py::object samples = py::module_::import("collections")
                                   .attr("namedtuple")("Samples", py::make_tuple("direction", "pdf", "radiance", "uv"),
                                                       py::arg("module") = "envmis._maps");
    samples.attr("__doc__") = docs::kSamples;
    m.attr("Samples") = samples;
    m.attr("__version__") = ENVMIS_VERSION;
    bind_envmap(m);
    bind_binned(m);
    bind_functions(m);
}
