#include "brep/two_breps.h"

#include <BRep_Builder.hxx>
#include <TopoDS_Compound.hxx>

#include "brep/solid_check.h"

namespace topopt::brep {

TwoBReps load_two_breps(const TopoDS_Shape& part, const TopoDS_Shape& nondesign, const ClassifyParams& params,
                        const Progress& progress) {
  TwoBReps m;
  progress.say("brep", 0.0, "checking the part");
  m.part = index_topology(check_solids(part, "part", m.notes));
  TopoDS_Shape nd;
  if (nondesign.IsNull()) {
    TopoDS_Compound empty;
    BRep_Builder().MakeCompound(empty);
    nd = empty;
  } else {
    progress.say("brep", 0.2, "checking the non-design solids");
    nd = check_solids(nondesign, "non-design input", m.notes);
  }
  m.nondesign = index_topology(nd);
  progress.say("brep", 0.4, "checking that the non-design solids lie inside the part");
  m.relations = check_containment(m.part, m.nondesign, params);
  progress.say("brep", 0.7, "classifying the non-design solids against the part");
  m.nd_on_part = classify(m.part, m.nondesign, params);
  progress.say("brep", 1.0, "inputs ready");
  return m;
}

}  // namespace topopt::brep
