// Python bindings of the fem stage (filled in by the issue that brings the stage).
#include "bindings/bindings.h"

namespace topopt::py {
void bind_fem(pybind11::module_&) {}
}  // namespace topopt::py
