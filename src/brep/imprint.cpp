#include "brep/imprint.h"

#include <BOPAlgo_Splitter.hxx>
#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_Copy.hxx>
#include <BRep_Builder.hxx>
#include <Bnd_Box.hxx>
#include <Message_ProgressIndicator.hxx>
#include <TopExp.hxx>
#include <TopTools_DataMapOfShapeInteger.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopoDS_Compound.hxx>
#include <cmath>
#include <string>

#include "common/cpu_time.h"
#include "common/error.h"

namespace topopt::brep {
namespace {

/// OCCT's progress indicator for the split: it asks OCCT to stop (UserBreak) once the thread
/// has spent its CPU budget or the caller cancels, and remembers which of the two it was.
class SplitBudget : public Message_ProgressIndicator {
 public:
  SplitBudget(double seconds, const Progress& progress) : end_(thread_cpu_seconds() + seconds), progress_(progress) {}
  Standard_Boolean UserBreak() override {
    if (progress_.cancelled && progress_.cancelled()) cancelled_ = true;
    if (!cancelled_ && thread_cpu_seconds() > end_) expired_ = true;
    return cancelled_ || expired_;
  }
  void Show(const Message_ProgressScope&, const Standard_Boolean) override {}
  bool expired() const { return expired_; }
  bool cancelled() const { return cancelled_; }

 private:
  double end_;
  const Progress& progress_;
  bool expired_ = false, cancelled_ = false;
};

/// Runs the General Fuse of Ω̄'s solids (objects) with Ω (tool) within `seconds` of CPU time;
/// throws when OCCT refuses, when the budget is spent (Timeout) or on a cancel.
void run_splitter(BOPAlgo_Splitter& splitter, const TopologyIndex& part, const TopologyIndex& nondesign, double fuzzy,
                  double seconds, const Progress& progress) {
  TopTools_ListOfShape objects, tools;
  for (int i = 1; i <= nondesign.num_solids(); ++i) objects.Append(nondesign.solids(i));
  tools.Append(part.solids(1));
  splitter.SetArguments(objects);
  splitter.SetTools(tools);
  splitter.SetFuzzyValue(fuzzy);
  splitter.SetNonDestructive(true);
  splitter.SetRunParallel(false);
  Handle(SplitBudget) budget = new SplitBudget(seconds, progress);
  splitter.Perform(budget->Start());
  if (budget->cancelled())
    throw Error(ErrorCode::Cancelled, "cancelled during imprinting the part's boundary on the non-design solids");
  if (budget->expired())
    throw Error(ErrorCode::Timeout,
                "imprinting the part's boundary on the non-design solids did not finish within its budget of " +
                    std::to_string(static_cast<long>(std::ceil(seconds))) +
                    " s of computing: simplify the non-design solids where they reach the part's surface (fewer, "
                    "simpler faces there), or mesh with --mesher gmsh");
  if (splitter.HasErrors())
    throw Error(ErrorCode::InvalidShape,
                "could not imprint the part's boundary on the non-design solids (where they reach the part's "
                "surface): check that the non-design solids and the part are valid solids exported at the same "
                "precision, or mesh with --mesher gmsh");
}

/// The split solid that replaces input solid i (1-based) of `nondesign`.
TopoDS_Shape split_solid(BOPAlgo_Splitter& splitter, const TopologyIndex& nondesign, int i) {
  const TopoDS_Shape& solid = nondesign.solids(i);
  const TopTools_ListOfShape& pieces = splitter.Modified(solid);
  if (pieces.IsEmpty()) return solid;
  if (pieces.Extent() != 1)
    throw Error(ErrorCode::NonDesignOutside, "non-design solid " + std::to_string(i) + " is cut into " +
                                                 std::to_string(pieces.Extent()) +
                                                 " pieces by the part's boundary: trim it to the part");
  return pieces.First();
}

/// Input face of every face of the split solid (0-based input numbers), keyed by the split
/// solid's own face shapes.
TopTools_DataMapOfShapeInteger split_face_origins(BOPAlgo_Splitter& splitter, const TopologyIndex& nondesign, int i) {
  TopTools_DataMapOfShapeInteger origin;
  for (const int* f = nondesign.solid_faces.begin(i - 1); f != nondesign.solid_faces.end(i - 1); ++f) {
    const TopoDS_Shape& face = nondesign.faces(*f + 1);
    const TopTools_ListOfShape& pieces = splitter.Modified(face);
    if (pieces.IsEmpty()) origin.Bind(face, *f);
    for (TopTools_ListOfShape::Iterator it(pieces); it.More(); it.Next()) origin.Bind(it.Value(), *f);
  }
  return origin;
}

int count(const TopoDS_Shape& shape, TopAbs_ShapeEnum kind) {
  TopTools_IndexedMapOfShape map;
  TopExp::MapShapes(shape, kind, map);
  return map.Extent();
}

}  // namespace

TopoDS_Shape split_nondesign(const TopologyIndex& part, const TopologyIndex& nondesign, double fuzzy,
                             std::vector<int>& face_origin, double seconds, const Progress& progress) {
  BOPAlgo_Splitter splitter;
  run_splitter(splitter, part, nondesign, fuzzy, seconds, progress);
  TopoDS_Compound out;
  BRep_Builder builder;
  builder.MakeCompound(out);
  TopTools_DataMapOfShapeInteger origin_of_copy;
  for (int i = 1; i <= nondesign.num_solids(); ++i) {
    const TopoDS_Shape solid = split_solid(splitter, nondesign, i);
    const TopTools_DataMapOfShapeInteger origin = split_face_origins(splitter, nondesign, i);
    // A copy of its own: faces where two solids touch are shared by the split, and each
    // solid must hold its own (the mesher aliases them, DESIGN.md).
    BRepBuilderAPI_Copy copy(solid, true, false);
    TopTools_IndexedMapOfShape faces;
    TopExp::MapShapes(solid, TopAbs_FACE, faces);
    for (int f = 1; f <= faces.Extent(); ++f) {
      int input_face = -1;
      if (!origin.Find(faces(f), input_face))
        throw Error(ErrorCode::InvalidShape, "a face of non-design solid " + std::to_string(i) +
                                                 " has no origin after imprinting the part's boundary on it");
      origin_of_copy.Bind(copy.ModifiedShape(faces(f)), input_face);
    }
    builder.Add(out, copy.Shape());
  }
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(out, TopAbs_FACE, faces);
  face_origin.assign(faces.Extent(), -1);
  for (int f = 1; f <= faces.Extent(); ++f) origin_of_copy.Find(faces(f), face_origin[f - 1]);
  return out;
}

MeshedNonDesign without_imprint(const TopologyIndex& nondesign, const Classification& on_part,
                                const ContainmentReport& relations) {
  MeshedNonDesign m;
  m.topo = nondesign;
  m.on_part = on_part;
  m.relations = relations;
  for (int f = 0; f < nondesign.num_faces(); ++f) m.face_origin.push_back(f);
  return m;
}

MeshedNonDesign meshed_nondesign(const TopologyIndex& part, const TopologyIndex& nondesign,
                                 const Classification& on_part, const ContainmentReport& relations,
                                 const ClassifyParams& params, const Progress& progress) {
  MeshedNonDesign m;
  bool changed = false;
  std::vector<int> origin;
  TopoDS_Shape split;
  if (nondesign.num_solids() > 0) {
    split =
        split_nondesign(part, nondesign, coincidence_tolerance(part, params), origin, params.imprint_seconds, progress);
    TopTools_IndexedMapOfShape solids;
    TopExp::MapShapes(split, TopAbs_SOLID, solids);
    for (int i = 1; i <= nondesign.num_solids() && !changed; ++i)
      changed = count(solids(i), TopAbs_FACE) != count(nondesign.solids(i), TopAbs_FACE) ||
                count(solids(i), TopAbs_EDGE) != count(nondesign.solids(i), TopAbs_EDGE);
  }
  if (!changed) return without_imprint(nondesign, on_part, relations);
  m.imprinted = true;
  m.topo = index_topology(split);
  m.face_origin = std::move(origin);
  m.on_part = classify(part, m.topo, params);
  const double tol = coincidence_tolerance(part, params);
  std::vector<Bnd_Box> boxes(m.topo.num_solids());
  for (int i = 0; i < m.topo.num_solids(); ++i) {
    BRepBndLib::Add(m.topo.solids(i + 1), boxes[i], false);
    boxes[i].Enlarge(tol);
  }
  for (int i = 0; i < m.topo.num_solids(); ++i)
    for (int j = i + 1; j < m.topo.num_solids(); ++j) {
      Contact contact;
      if (!boxes[i].IsOut(boxes[j]) && touching(m.topo, i, j, tol, contact)) m.relations.contacts.push_back(contact);
    }
  m.relations.warnings = relations.warnings;
  return m;
}

}  // namespace topopt::brep
