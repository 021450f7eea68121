#include <Standard_Failure.hxx>

#include <nlohmann/json.hpp>

#include "bindings/bindings.h"
#include "brep/occt_guard.h"
#include "common/error.h"

namespace py = pybind11;

namespace {

/// `error` as an instance of the module's TopOptError with its .code, raised in Python.
void raise_topopt_error(const py::exception<topopt::Error>& type, const topopt::Error& error) {
  py::object instance = py::handle(type.ptr())(error.what());
  instance.attr("code") = topopt::error_code_name(error.code());
  PyErr_SetObject(type.ptr(), instance.ptr());
}

}  // namespace

PYBIND11_MODULE(_native, m) {
  m.doc() = "TopOpt native core: B-Rep checks, meshing, FEM, SIMP, result surfaces";
  // Every failure of the core reaches Python as topopt._native.TopOptError (a RuntimeError)
  // whose .code names the kind ("NonDesignOutside", ...); nothing may take FreeCAD down, and
  // no OCCT or library internals reach the user: OCCT's exceptions and JSON type errors are
  // put in words here, the boundary's last line (the core words its own errors earlier).
  static py::exception<topopt::Error> error(m, "TopOptError", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const topopt::Error& e) {
      raise_topopt_error(error, e);
    } catch (const Standard_Failure& failure) {
      raise_topopt_error(error, topopt::brep::occt_error(failure, "the call"));
    } catch (const nlohmann::json::exception& e) {
      const std::string what = e.what();  // "[json.exception.type_error.302] type must be ..."
      const size_t bracket = what.find("] ");
      raise_topopt_error(error, topopt::Error(topopt::ErrorCode::InvalidParameter,
                                              "job_json holds a value of the wrong kind or misses one (" +
                                                  (bracket == std::string::npos ? what : what.substr(bracket + 2)) +
                                                  "): check it against docs/job-format.md"));
    }
  });
  topopt::py::bind_brep(m);
  topopt::py::bind_mesh(m);
  topopt::py::bind_fem(m);
  topopt::py::bind_simp(m);
}
