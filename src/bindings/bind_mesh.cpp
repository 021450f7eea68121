// Python bindings of the mesh stage (filled in by the issue that brings the stage).
#include "bindings/bindings.h"

namespace topopt::py {
void bind_mesh(pybind11::module_&) {}
}  // namespace topopt::py
