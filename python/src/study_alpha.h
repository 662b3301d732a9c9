// envmis.choose_alpha, envmis.exact_variances and envmis.compensated_map: the
// compensation strength and the exact (quadrature) variances of alpha.h and quadrature.h.
#pragma once

#include <pybind11/pybind11.h>

#include <span>

#include "envmis/study/comparison/alpha.h"

namespace envmis::python {

namespace py = pybind11;

// {"alpha", "bsdf_alphas": {bsdf: alpha}, "candidates": [{"alpha", "criterion",
// "per_bsdf": {bsdf: criterion}}], "width", "height", "seconds"}; `bsdfs` are
// AlphaOptions::bsdfs, in order.
py::dict alpha_choice_dict(const AlphaChoice& choice, std::span<const Bsdf> bsdfs);

void bind_alpha(py::module_& m);

}  // namespace envmis::python
