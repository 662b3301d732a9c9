// envmis._study: BSDFs, techniques and the variance study.
#include <pybind11/pybind11.h>

PYBIND11_MODULE(_study, m) {
    m.doc() = "envmis variance study";
    pybind11::module_::import("envmis._maps");
}
