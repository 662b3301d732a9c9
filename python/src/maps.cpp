// envmis._maps: maps, tables and sampling.
#include <pybind11/pybind11.h>

PYBIND11_MODULE(_maps, m) { m.doc() = "envmis maps, tables and sampling"; }
