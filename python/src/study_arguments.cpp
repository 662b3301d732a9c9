#include "study_arguments.h"

#include <pybind11/numpy.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "numpy_arrays.h"

namespace envmis::python {
namespace {

std::string type_name(const py::handle& object) { return py::str(py::type::of(object).attr("__name__")); }

// Items of a comma-separated str or of an iterable, each converted by `one`.
template <class T, class One>
std::vector<T> list_of(const py::handle& items, const char* where, const char* name, One one) {
    std::vector<T> result;
    if (py::isinstance<py::str>(items)) {
        for (const std::string& item : split_list(items.cast<std::string>()))
            result.push_back(one(py::str(item), where));
        return result;
    }
    if (!py::isinstance<py::iterable>(items))
        throw py::type_error(std::string(where) + ": " + name + " must be a str or an iterable; got " +
                             type_name(items));
    for (const py::handle item : items) result.push_back(one(item, where));
    return result;
}

// The length of a float32 (N, 3) row, in double so that rounding does not hide a
// non-unit vector.
double length(const float* v) { return std::sqrt(double(v[0]) * v[0] + double(v[1]) * v[1] + double(v[2]) * v[2]); }

std::vector<Vec3> unit_rows(const py::array_t<float, py::array::c_style>& rows, const char* where, const char* name) {
    std::vector<Vec3> result(static_cast<size_t>(rows.shape(0)));
    const float* data = rows.data();
    for (size_t i = 0; i < result.size(); ++i) {
        const float* v = data + 3 * i;
        const double l = length(v);
        if (!(std::abs(l - 1) <= 1e-3))
            throw std::invalid_argument(std::string(where) + ": " + name + "[" + std::to_string(i) +
                                        "] must be a unit vector; got length " + std::to_string(l));
        result[i] = {v[0], v[1], v[2]};
    }
    return result;
}

}  // namespace

Bsdf bsdf_of(const py::handle& bsdf, const char* where) {
    if (py::isinstance<Bsdf>(bsdf)) return bsdf.cast<Bsdf>();
    if (py::isinstance<py::str>(bsdf)) return Bsdf::parse(bsdf.cast<std::string>());
    throw py::type_error(std::string(where) + ": a BSDF must be a name such as 'phong:50' or an envmis.Bsdf; got " +
                         type_name(bsdf));
}

Technique technique_of(const py::handle& technique, const char* where) {
    if (py::isinstance<Technique>(technique)) return technique.cast<Technique>();
    if (py::isinstance<py::str>(technique)) return Technique::parse(technique.cast<std::string>());
    throw py::type_error(std::string(where) +
                         ": a technique must be a name such as 'mis-balance' or an envmis.Technique; got " +
                         type_name(technique));
}

std::vector<Bsdf> bsdf_list(const py::handle& bsdfs, const char* where) {
    return list_of<Bsdf>(bsdfs, where, "bsdfs", bsdf_of);
}

std::vector<Technique> technique_list(const py::handle& techniques, const char* where,
                                      const std::vector<Technique>& fallback) {
    if (techniques.is_none()) return fallback;
    return list_of<Technique>(techniques, where, "techniques", technique_of);
}

uint64_t count_in_range(const py::handle& value, const char* where, const char* name, uint64_t low, uint64_t high) {
    if (!py::isinstance<py::int_>(value) || py::isinstance<py::bool_>(value))
        throw py::type_error(std::string(where) + ": " + name + " must be an int; got " + type_name(value));
    const std::string fail = std::string(where) + ": " + name + " must be " + std::to_string(low) + " to " +
                             std::to_string(high) + "; got " + py::str(value).cast<std::string>();
    if (value.cast<py::int_>() < py::int_(0)) throw std::invalid_argument(fail);
    const unsigned long long v = PyLong_AsUnsignedLongLong(value.ptr());
    if (PyErr_Occurred()) {
        PyErr_Clear();
        throw std::invalid_argument(fail);
    }
    if (v < low || v > high) throw std::invalid_argument(fail);
    return v;
}

std::vector<ShadingPoint> shading_points(const py::handle& count, const py::handle& normals, const py::handle& views,
                                         const char* where, double view_degrees) {
    if (normals.is_none()) {
        if (!views.is_none()) throw std::invalid_argument(std::string(where) + ": views needs normals");
        const auto k = static_cast<uint32_t>(count_in_range(count, where, "points", 1, kMaxStudyPoints));
        try {
            return sphere_points(k, view_degrees);
        } catch (const std::invalid_argument& e) {
            throw std::invalid_argument(std::string(where) + ": view_angle: " + e.what());
        }
    }
    if (view_degrees != 0)
        throw std::invalid_argument(std::string(where) + ": view_angle needs points, not normals (views give theirs)");
    const std::vector<Vec3> n = unit_rows(float_array(normals, where, "normals", {-1, 3}), where, "normals");
    if (n.empty() || n.size() > kMaxStudyPoints)
        throw std::invalid_argument(std::string(where) + ": normals must have 1 to " + std::to_string(kMaxStudyPoints) +
                                    " rows; got " + std::to_string(n.size()));
    std::vector<Vec3> v = n;
    if (!views.is_none()) {
        v = unit_rows(float_array(views, where, "views", {-1, 3}), where, "views");
        if (v.size() != n.size())
            throw std::invalid_argument(std::string(where) + ": views must have as many rows as normals (" +
                                        std::to_string(n.size()) + "); got " + std::to_string(v.size()));
    }
    std::vector<ShadingPoint> points(n.size());
    for (size_t i = 0; i < n.size(); ++i) points[i] = {n[i], v[i]};
    return points;
}

Allocation allocation_of(const py::handle& env_samples, const py::handle& bsdf_samples, const char* where) {
    return {static_cast<uint32_t>(count_in_range(env_samples, where, "env_samples", 0, kMaxStudySamples)),
            static_cast<uint32_t>(count_in_range(bsdf_samples, where, "bsdf_samples", 0, kMaxStudySamples))};
}

uint32_t worker_threads(const py::handle& threads, const char* where) {
    std::string note;
    const uint32_t workers = envmis::worker_threads(
        static_cast<uint32_t>(count_in_range(threads, where, "threads", 0, kMaxStudyThreads)), &note);
    if (!note.empty() && PyErr_WarnEx(PyExc_RuntimeWarning, (std::string(where) + ": " + note).c_str(), 1) != 0)
        throw py::error_already_set();
    return workers;
}

}  // namespace envmis::python
