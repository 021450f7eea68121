#include "brep/two_breps.h"

#include <BRep_Builder.hxx>
#include <TopoDS_Compound.hxx>

#include "brep/occt_guard.h"
#include "brep/solid_check.h"

namespace topopt::brep {

TwoBReps load_two_breps(const TopoDS_Shape& part, const TopoDS_Shape& nondesign, const ClassifyParams& params,
                        const Progress& progress, const ForeignParams& foreign) {
  TwoBReps m;
  progress.say("brep", 0.0, "checking the part");
  const TopoDS_Shape checked_part = check_solids(part, "part", m.notes, foreign, progress);
  m.part = guard_occt("indexing the part", [&] { return index_topology(checked_part); });
  TopoDS_Shape nd;
  if (nondesign.IsNull()) {
    TopoDS_Compound empty;
    BRep_Builder().MakeCompound(empty);
    nd = empty;
  } else {
    progress.say("brep", 0.2, "checking the non-design solids");
    nd = check_solids(nondesign, "non-design input", m.notes, foreign, progress);
  }
  m.nondesign = guard_occt("indexing the non-design solids", [&] { return index_topology(nd); });
  progress.say("brep", 0.4, "checking that the non-design solids lie inside the part");
  m.relations = guard_occt("checking that the non-design solids lie inside the part",
                           [&] { return check_containment(m.part, m.nondesign, params); });
  progress.say("brep", 0.7, "classifying the non-design solids against the part");
  m.nd_on_part = guard_occt("classifying the non-design solids against the part",
                            [&] { return classify(m.part, m.nondesign, params); });
  progress.say("brep", 0.85, "imprinting the part's boundary on the non-design solids");
  m.meshed = guard_occt("imprinting the part's boundary on the non-design solids", [&] {
    return meshed_nondesign(m.part, m.nondesign, m.nd_on_part, m.relations, params, progress);
  });
  progress.say("brep", 1.0, "inputs ready");
  return m;
}

}  // namespace topopt::brep
