// The study's arguments as Python gives them, checked and converted once: BSDFs and
// techniques by name or object, shading points as NumPy arrays or a count, sample
// counts and seeds as Python ints. Every refusal is a ValueError (std::invalid_argument)
// or a TypeError (py::type_error) whose message starts with the function's name.
#pragma once

#include <pybind11/pybind11.h>

#include <cstdint>
#include <string>
#include <vector>

#include "envmis/study/comparison/setup.h"
#include "envmis/study/shading/bsdf.h"
#include "envmis/study/techniques/estimator.h"

namespace envmis::python {

namespace py = pybind11;

// A str of comma-separated names (as `--bsdf lambert,phong:50`), or an iterable of
// names and envmis.Bsdf objects. Bsdf::parse's message for a bad name.
std::vector<Bsdf> bsdf_list(const py::handle& bsdfs, const char* where);
// The same for techniques (Technique::parse); None gives `fallback`.
std::vector<Technique> technique_list(const py::handle& techniques, const char* where,
                                      const std::vector<Technique>& fallback);
// One BSDF or technique, by name or object.
Bsdf bsdf_of(const py::handle& bsdf, const char* where);
Technique technique_of(const py::handle& technique, const char* where);

// An integer argument in [low, high]: "envmis.compare: spp must be 1 to 4294967295; got 0".
uint64_t count_in_range(const py::handle& value, const char* where, const char* name, uint64_t low, uint64_t high);

// The shading points: `count` spread over the sphere (sphere_points) when `normals` is
// None, else one per row of normals (N, 3) float32, viewed from `views` (N, 3) float32
// or head-on. Every row must be a unit vector to within 1e-3 (they are used as given,
// not renormalised, so that sphere_points' own normals give the same estimates here as
// in the command). view_degrees tilts the views of the `count` points (sphere_points);
// with normals it must be 0, as their views say where each is seen from.
std::vector<ShadingPoint> shading_points(const py::handle& count, const py::handle& normals, const py::handle& views,
                                         const char* where, double view_degrees = 0);

// env_samples and bsdf_samples, each 0 to kMaxStudySamples.
Allocation allocation_of(const py::handle& env_samples, const py::handle& bsdf_samples, const char* where);

// worker_threads (setup.h), its note a Python RuntimeWarning.
uint32_t worker_threads(const py::handle& threads, const char* where);

}  // namespace envmis::python
