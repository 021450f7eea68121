#include <Standard_Failure.hxx>

#include "bindings/bindings.h"
#include "common/error.h"

namespace py = pybind11;

PYBIND11_MODULE(_native, m) {
  m.doc() = "TopOpt native core: B-Rep checks, meshing, FEM, SIMP, result surfaces";
  // Every failure of the core reaches Python as topopt._native.TopOptError (a RuntimeError)
  // whose .code names the kind ("NonDesignOutside", ...); nothing may take FreeCAD down.
  static py::exception<topopt::Error> error(m, "TopOptError", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const topopt::Error& e) {
      py::object instance = py::handle(error.ptr())(e.what());
      instance.attr("code") = topopt::error_code_name(e.code());
      PyErr_SetObject(error.ptr(), instance.ptr());
    } catch (const Standard_Failure& e) {
      std::string msg = std::string("geometry kernel error: ") + (e.GetMessageString() ? e.GetMessageString() : "?");
      PyErr_SetString(error.ptr(), msg.c_str());
    }
  });
  topopt::py::bind_brep(m);
  topopt::py::bind_mesh(m);
  topopt::py::bind_fem(m);
  topopt::py::bind_simp(m);
}
