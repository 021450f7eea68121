// The Python module topopt._native, split by stage: each bind_*.cpp adds its stage's
// functions. This is the only code that sees Python.
#pragma once
#include <pybind11/pybind11.h>

namespace topopt::py {
void bind_brep(pybind11::module_& m);
void bind_mesh(pybind11::module_& m);
void bind_fem(pybind11::module_& m);
void bind_simp(pybind11::module_& m);
}  // namespace topopt::py
