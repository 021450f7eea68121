// Python bindings of the simp stage (filled in by the issue that brings the stage).
#include "bindings/bindings.h"

namespace topopt::py {
void bind_simp(pybind11::module_&) {}
}  // namespace topopt::py
