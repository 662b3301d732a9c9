// envmis.compare: the variance study of `envmis compare`, set up as the command sets it
// up (plain map, compensation strength fixed or chosen per BSDF, one compensated map per
// BSDF, normal bins for the -bins techniques, shading points), so that the same
// arguments and seed give the same records as `envmis compare --json`.
#pragma once

#include <pybind11/pybind11.h>

#include "envmis/sampling/envmap.h"
#include "envmis/study/comparison/comparison.h"

namespace envmis::python {

namespace py = pybind11;

// compare()'s keyword arguments as Python gave them (checked by run_compare).
struct CompareArguments {
    py::object bsdfs, techniques, spp, points, normals, views, seed, threads, alpha, env_samples, bsdf_samples, bins;
    double view_angle = 0;  // degrees, sphere_points
    float bin_cost = 0;     // BinnedOptions::cost
    bool exact = false;
    bool from_table = false;  // the map was read from a table file (EnvMap.from_table)
    std::string name;
    py::object progress;
};

// What envmis.compare returns: the records of `compare --json`'s "results" and
// "inputs" as Python objects, its "exact" with exact=True, and the study itself for the
// per-point arrays.
struct ComparisonResult {
    Comparison comparison;
    py::list records;
    py::dict inputs;
    py::object exact;  // None without exact=True
};

// Runs the study on `map` (its radiance; its own compensation only gives the default
// alpha) with the GIL released; Ctrl-C or an exception from the progress callback stops
// it and is raised (watch.h). Throws ValueError with the command's messages.
ComparisonResult run_compare(const EnvMap& map, const CompareArguments& args);

// Binds envmis.compare and envmis.Comparison.
void bind_compare(py::module_& m);

}  // namespace envmis::python
