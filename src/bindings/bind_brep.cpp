#include <pybind11/stl.h>

#include "bindings/bindings.h"
#include "brep/report.h"
#include "brep/shape_io.h"

namespace py = pybind11;

namespace topopt::py {
namespace {

/// JSON → Python, through the json module (reports are small).
pybind11::object to_python(const nlohmann::json& j) {
  return pybind11::module_::import("json").attr("loads")(j.dump());
}

TopoDS_Shape shape_from(const std::string& brep, const std::string& what) {
  return brep.empty() ? TopoDS_Shape() : brep::read_brep_string(brep, what);
}

}  // namespace

void bind_brep(pybind11::module_& m) {
  m.def(
      "info",
      [](const std::string& part, const std::string& nondesign, double tolerance) {
        TopoDS_Shape p = shape_from(part, "part"), n = shape_from(nondesign, "non-design input");
        brep::ClassifyParams params;
        params.tolerance = tolerance;
        brep::TwoBReps two;
        {
          pybind11::gil_scoped_release release;
          two = brep::load_two_breps(p, n, params);
        }
        return to_python(brep::two_breps_report(two));
      },
      pybind11::arg("part"), pybind11::arg("nondesign") = "", pybind11::arg("tolerance") = -1.0,
      R"doc(Check the part and the non-design solids and classify one against the other.

part, nondesign: BREP strings (Shape.exportBrepToString()); nondesign may be "" (none) and
is a solid or a compound of solids in input order. Returns the report as a dict (see
`topopt info --json`). Raises TopOptError (.code "InvalidShape", "NonDesignOutside",
"NonDesignOverlap", "Io") with a message that says what to fix.)doc");

  m.def(
      "read_shape_file", [](const std::string& path) { return brep::write_brep_string(brep::read_shape_file(path)); },
      pybind11::arg("path"), "Read a STEP/IGES/BREP file; returns its BREP string.");
}

}  // namespace topopt::py
