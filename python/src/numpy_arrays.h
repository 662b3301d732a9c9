// NumPy arrays at the boundary of the bindings: checked on the way in, with one message
// naming the argument, the expected dtype and shape and what was given; made without a
// copy on the way out where the data outlives the call.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <charconv>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace envmis::python {

namespace py = pybind11;

// A C-contiguous float32 array. `shape` lists the expected extents, -1 for any
// ("(N, 3)" is {-1, 3}), named in the message by `symbols` in turn ("HW": "(H, W, 3)"). Throws ValueError
// (std::invalid_argument) otherwise: "envmis.EnvMap.sample: u must be a float32 array of shape (N, 2); got a float64
// array of shape (10, 2)". Arrays of another dtype are never converted silently: a float64 array of directions rounded
// to float32 would give other samples than the caller's values.
inline py::array_t<float, py::array::c_style> float_array(const py::handle& object, const char* where, const char* name,
                                                          std::initializer_list<py::ssize_t> shape,
                                                          std::string_view symbols = "NM") {
    std::string expected = "(";
    size_t symbol = 0;
    for (const py::ssize_t extent : shape) {
        if (expected.size() > 1) expected += ", ";
        expected += extent < 0 ? std::string(1, symbols.at(symbol++)) : std::to_string(extent);
    }
    expected += shape.size() == 1 ? ",)" : ")";
    auto fail = [&](const std::string& given) {
        throw std::invalid_argument(std::string(where) + ": " + name + " must be a float32 array of shape " + expected +
                                    "; got " + given);
    };
    if (!py::isinstance<py::array>(object)) fail(std::string("a ") + py::str(py::type::of(object)).cast<std::string>());
    const auto array = py::reinterpret_borrow<py::array>(object);
    std::string given = "(";
    for (py::ssize_t d = 0; d < array.ndim(); ++d) {
        if (d) given += ", ";
        given += std::to_string(array.shape(d));
    }
    given += array.ndim() == 1 ? ",)" : ")";
    const std::string dtype = py::str(array.dtype()).cast<std::string>();
    bool fits = array.dtype().equal(py::dtype::of<float>()) && array.ndim() == static_cast<py::ssize_t>(shape.size());
    for (size_t d = 0; fits && d < shape.size(); ++d) {
        const py::ssize_t extent = shape.begin()[d];
        fits = extent < 0 || array.shape(static_cast<py::ssize_t>(d)) == extent;
    }
    if (!fits) fail("a " + dtype + " array of shape " + given);
    if (!(array.flags() & py::array::c_style))
        fail("a non-contiguous " + dtype + " array of shape " + given +
             " (np.ascontiguousarray makes a contiguous copy)");
    return py::reinterpret_borrow<py::array_t<float, py::array::c_style>>(array);
}

// Throws ValueError unless every value of `u`, a C-contiguous float32 (N, 2) array, is in
// [0, 1) (NaN is not): the core's samplers assume it (CdfView::invert reads one past
// its table at u = 1, and converts u to an unsigned index). Names the first value that
// is not, as "envmis.EnvMap.sample: u[12, 1] = 1 is outside [0, 1)". One pass over the
// values in blocks without branches (vectorised); the block that holds a bad value is
// searched again (measured: docs/performance-log.md, 'check_unit_points').
inline void check_unit_points(const py::array_t<float, py::array::c_style>& u, const char* where, const char* name) {
    const float* values = u.data();
    const auto count = static_cast<size_t>(u.size());
    constexpr size_t kBlock = 4096;
    for (size_t first = 0; first < count; first += kBlock) {
        const size_t last = std::min(count, first + kBlock);
        // Both comparisons evaluated (&, not &&) and the flags or'ed as integers: GCC
        // vectorises this form, not the short-circuit one.
        uint32_t bad = 0;
        for (size_t i = first; i < last; ++i) {
            const bool inside = (values[i] >= 0.0f) & (values[i] < 1.0f);
            bad |= !inside;
        }
        if (!bad) continue;
        size_t i = first;
        while (values[i] >= 0.0f && values[i] < 1.0f) ++i;
        char text[32];
        const auto written = std::to_chars(text, text + sizeof text, values[i]);
        throw std::invalid_argument(std::string(where) + ": " + name + "[" + std::to_string(i / 2) + ", " +
                                    std::to_string(i % 2) + "] = " + std::string(text, written.ptr) +
                                    " is outside [0, 1)");
    }
}

// An output argument: as float_array, and writeable (a read-only array, a view of a
// map's radiance say, raises ValueError naming it rather than NumPy's unnamed message).
inline py::array_t<float, py::array::c_style> writeable_float_array(const py::handle& object, const char* where,
                                                                    const char* name,
                                                                    std::initializer_list<py::ssize_t> shape) {
    auto array = float_array(object, where, name, shape);
    if (!array.writeable()) throw std::invalid_argument(std::string(where) + ": " + name + " is not writeable");
    return array;
}

// A new float32 array of `shape`, C-contiguous, uninitialised: an output to fill.
inline py::array_t<float> new_float_array(std::initializer_list<py::ssize_t> shape) {
    return py::array_t<float>(std::vector<py::ssize_t>(shape));
}

// A read-only array over `data`, which `owner` keeps alive: a view, never a copy.
inline py::array read_only_view(const float* data, std::initializer_list<py::ssize_t> shape, py::handle owner) {
    std::vector<py::ssize_t> extents(shape), strides(extents.size());
    py::ssize_t stride = sizeof(float);
    for (size_t d = extents.size(); d-- > 0;) strides[d] = stride, stride *= extents[d];
    py::array view(py::dtype::of<float>(), extents, strides, data, owner);
    py::detail::array_proxy(view.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
    return view;
}

}  // namespace envmis::python
