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

namespace detail {

// "(N, 3)" for {-1, 3}: each -1 named by the next of `symbols`.
inline std::string shape_text(std::initializer_list<py::ssize_t> shape, std::string_view symbols) {
    std::string text = "(";
    size_t symbol = 0;
    for (const py::ssize_t extent : shape) {
        if (text.size() > 1) text += ", ";
        text += extent < 0 ? std::string(1, symbols.at(symbol++)) : std::to_string(extent);
    }
    return text + (shape.size() == 1 ? ",)" : ")");
}

// "a float64 array of shape (10, 2)", or "a <class 'list'>" for what is not an array.
inline std::string given_text(const py::handle& object) {
    if (!py::isinstance<py::array>(object)) return "a " + py::str(py::type::of(object)).cast<std::string>();
    const auto array = py::reinterpret_borrow<py::array>(object);
    std::string shape = "(";
    for (py::ssize_t d = 0; d < array.ndim(); ++d) shape += (d ? ", " : "") + std::to_string(array.shape(d));
    shape += array.ndim() == 1 ? ",)" : ")";
    return "a " + py::str(array.dtype()).cast<std::string>() + " array of shape " + shape;
}

inline bool has_shape(const py::array& array, std::initializer_list<py::ssize_t> shape) {
    bool fits = array.ndim() == static_cast<py::ssize_t>(shape.size());
    for (size_t d = 0; fits && d < shape.size(); ++d)
        fits = shape.begin()[d] < 0 || array.shape(static_cast<py::ssize_t>(d)) == shape.begin()[d];
    return fits;
}

}  // namespace detail

// An input argument: any array-like of real numbers (a NumPy array of any integer or
// floating dtype and any strides, a list, a tuple: what np.asarray takes) of `shape`,
// whose extents are listed with -1 for any ("(N, 3)" is {-1, 3}, named in messages by
// `symbols` in turn), as a C-contiguous float32 array: the argument itself where it is
// one already, else a converted copy, its values rounded to float32 as the C++ API takes
// them. Where the shape is (N, k), a single vector of k values is one row (N = 1).
// Throws ValueError (std::invalid_argument) otherwise, naming the argument, the expected
// shape and what was given: "envmis.EnvMap.sample: u must be an array of real numbers of
// shape (N, 2); got a float32 array of shape (10, 3)". Booleans, complex numbers and
// strings are refused rather than cast.
inline py::array_t<float, py::array::c_style> float_array(const py::handle& object, const char* where, const char* name,
                                                          std::initializer_list<py::ssize_t> shape,
                                                          std::string_view symbols = "NM") {
    auto fail = [&](const py::handle& given) {
        throw std::invalid_argument(std::string(where) + ": " + name + " must be an array of real numbers of shape " +
                                    detail::shape_text(shape, symbols) + "; got " + detail::given_text(given));
    };
    py::array array =
        py::isinstance<py::array>(object) ? py::reinterpret_borrow<py::array>(object) : py::array::ensure(object);
    if (!array) fail(object);
    if (const char kind = array.dtype().kind(); kind != 'f' && kind != 'i' && kind != 'u')
        fail(py::isinstance<py::array>(object) ? py::handle(array) : object);
    if (shape.size() == 2 && shape.begin()[0] < 0 && array.ndim() == 1 && array.shape(0) == shape.begin()[1])
        array = array.reshape({py::ssize_t{1}, shape.begin()[1]});
    if (!detail::has_shape(array, shape)) fail(array);
    using Converted = py::array_t<float, py::array::c_style | py::array::forcecast>;
    Converted converted = Converted::ensure(array);
    if (!converted)  // NumPy failed (out of memory): pybind11 cleared its error
        throw std::runtime_error(std::string(where) + ": " + name + ": could not be converted to a float32 array");
    return py::reinterpret_steal<py::array_t<float, py::array::c_style>>(converted.release());
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

// An output argument (out=): a C-contiguous float32 array of `shape` exactly, never
// converted (the results must land in the caller's array), and writeable. Throws
// ValueError naming it otherwise ("out.uv must be a float32 array of shape (100, 2); got a
// float32 array of shape (99, 2)"; "... is not writeable" for a view of a map's radiance).
inline py::array_t<float, py::array::c_style> writeable_float_array(const py::handle& object, const char* where,
                                                                    const char* name,
                                                                    std::initializer_list<py::ssize_t> shape) {
    const auto fail = [&](const std::string& why) {
        throw std::invalid_argument(std::string(where) + ": " + name + " must be a float32 array of shape " +
                                    detail::shape_text(shape, "NM") + "; got " + why);
    };
    if (!py::isinstance<py::array>(object)) fail(detail::given_text(object));
    const auto array = py::reinterpret_borrow<py::array>(object);
    if (!array.dtype().equal(py::dtype::of<float>()) || !detail::has_shape(array, shape))
        fail(detail::given_text(array));
    if (!(array.flags() & py::array::c_style)) fail("a non-contiguous " + detail::given_text(array).substr(2));
    if (!array.writeable()) throw std::invalid_argument(std::string(where) + ": " + name + " is not writeable");
    return py::reinterpret_borrow<py::array_t<float, py::array::c_style>>(array);
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
