// nlohmann::json as Python objects, so that what Python gets from the study is what
// `envmis compare --json` writes, made by the same writer (envmis/report/results.h).
#pragma once

#include <pybind11/pybind11.h>

#include <cmath>
#include <nlohmann/json.hpp>

namespace envmis::python {

namespace py = pybind11;

// null -> None, booleans, integers (any size), floats, strings, arrays -> list,
// objects -> dict (in the JSON's key order). A non-finite float becomes None, as
// nlohmann::json writes it to a file (null), so that a record equals the file's.
inline py::object to_python(const nlohmann::json& j) {
    switch (j.type()) {
        case nlohmann::json::value_t::boolean: return py::bool_(j.get<bool>());
        case nlohmann::json::value_t::number_integer: return py::int_(j.get<int64_t>());
        case nlohmann::json::value_t::number_unsigned: return py::int_(j.get<uint64_t>());
        case nlohmann::json::value_t::number_float: {
            const double v = j.get<double>();
            return std::isfinite(v) ? py::object(py::float_(v)) : py::object(py::none());
        }
        case nlohmann::json::value_t::string: return py::str(j.get_ref<const std::string&>());
        case nlohmann::json::value_t::array: {
            py::list list;
            for (const nlohmann::json& item : j) list.append(to_python(item));
            return list;
        }
        case nlohmann::json::value_t::object: {
            py::dict dict;
            for (const auto& [key, value] : j.items()) dict[py::str(key)] = to_python(value);
            return dict;
        }
        default: return py::none();
    }
}

}  // namespace envmis::python
