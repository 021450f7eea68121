#include <pybind11/stl.h>

#include <limits>

#include "bindings/arguments.h"
#include "bindings/bindings.h"
#include "brep/report.h"
#include "brep/shape_io.h"
#include "common/error.h"

namespace py = pybind11;

namespace topopt::py {
namespace {

/// JSON → Python, through the json module (reports are small).
pybind11::object to_python(const nlohmann::json& j) {
  return pybind11::module_::import("json").attr("loads")(j.dump());
}

/// The time budget argument of the readers: 0 (from the input's size) or seconds.
brep::ForeignParams budget_arg(const pybind11::handle& seconds) {
  brep::ForeignParams p;
  p.seconds = number_arg(seconds, "time_budget", 0, std::numeric_limits<double>::max());
  return p;
}

TopoDS_Shape shape_from(const std::string& brep, const std::string& what, const brep::ForeignParams& budget) {
  return brep.empty() ? TopoDS_Shape() : brep::read_brep_string(brep, what, budget);
}

}  // namespace

void bind_brep(pybind11::module_& m) {
  m.def(
      "info",
      [](const pybind11::object& part_arg, const pybind11::object& nondesign_arg, const pybind11::object& tolerance,
         const pybind11::object& time_budget) {
        const std::string part = text_arg(part_arg, "part"), nondesign = text_arg(nondesign_arg, "nondesign");
        brep::ClassifyParams params;
        params.tolerance = number_arg(tolerance, "tolerance", -1, std::numeric_limits<double>::max());
        const brep::ForeignParams budget = budget_arg(time_budget);
        brep::TwoBReps two;
        {
          pybind11::gil_scoped_release release;
          TopoDS_Shape p = shape_from(part, "part", budget), n = shape_from(nondesign, "non-design input", budget);
          two = brep::load_two_breps(p, n, params, {}, budget);
        }
        return to_python(brep::two_breps_report(two));
      },
      pybind11::arg("part"), pybind11::arg("nondesign") = "", pybind11::arg("tolerance") = -1.0,
      pybind11::arg("time_budget") = 0.0,
      R"doc(Check the part and the non-design solids and classify one against the other.

part, nondesign: BREP strings (Shape.exportBrepToString()); nondesign may be "" (none) and
is a solid or a compound of solids in input order. tolerance: coincidence tolerance in mm
(<= 0: 1e-6 x the part's size). time_budget: seconds allowed for reading, or checking and
healing, each input (0: 30 s + 15 s per MB). Returns the report as a dict (see
`topopt info --json`). Raises TopOptError (.code "InvalidShape", "NonDesignOutside",
"NonDesignOverlap", "Io", "Crashed" or "Timeout" for a damaged input) with a message that says
what to fix.)doc");

  m.def(
      "read_shape_file",
      [](const pybind11::object& path_arg, const pybind11::object& time_budget) {
        const std::string path = text_arg(path_arg, "path");
        const brep::ForeignParams budget = budget_arg(time_budget);
        pybind11::gil_scoped_release release;
        return brep::write_brep_string(brep::read_shape_file(path, "", budget));
      },
      pybind11::arg("path"), pybind11::arg("time_budget") = 0.0,
      R"doc(Read a STEP/IGES/BREP file (in a child process, within time_budget seconds; 0: from its
size); returns its BREP string. Raises TopOptError (.code "Io", "Crashed", "Timeout") naming the
file when it is missing or damaged.)doc");
}

}  // namespace topopt::py
