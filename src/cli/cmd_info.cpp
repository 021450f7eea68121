// topopt info: check the inputs and print their topology and classification.
#include <iostream>

#include "brep/report.h"
#include "brep/shape_io.h"
#include "cli/commands.h"

namespace topopt::cli {

int cmd_info(const Args& args) {
  ArgReader a(args,
              "usage: topopt info --part PART [--non-design ND] [--json] [--tolerance T] [--time-budget S]\n"
              "  PART, ND: STEP, IGES or BREP files; ND holds the non-design solids (a compound).\n"
              "  Checks both, reports topology (FreeCAD numbering), where each non-design\n"
              "  vertex, edge and face lies on the part, and contacts among non-design solids.\n"
              "  --json       print the full report as JSON\n"
              "  --tolerance  coincidence tolerance in mm (default 1e-6 x part size)\n"
              "  --time-budget S  seconds allowed for reading, or checking and healing, each input\n"
              "               (default: 30 s + 15 s per MB of file)");
  if (a.print_help()) return 0;
  std::string part = a.option("part"), nondesign = a.option("non-design");
  bool json = a.flag("json");
  brep::ClassifyParams params;
  params.tolerance = a.number("tolerance", -1);
  const brep::ForeignParams budget = a.time_budget();
  if (!a.positionals().empty() || part.empty())
    throw Error(ErrorCode::InvalidParameter, "give the part with --part FILE\n" + a.usage());
  TopoDS_Shape part_shape = brep::read_shape_file(part, "part", budget);
  TopoDS_Shape nondesign_shape = nondesign.empty() ? TopoDS_Shape() : brep::read_shape_file(nondesign, "non-design input", budget);
  brep::TwoBReps m = brep::load_two_breps(part_shape, nondesign_shape, params, {}, budget);
  if (json)
    std::cout << brep::two_breps_report(m).dump(2) << "\n";
  else
    std::cout << brep::two_breps_summary(m);
  return 0;
}

}  // namespace topopt::cli
