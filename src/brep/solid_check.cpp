#include "brep/solid_check.h"

#include <BRepBuilderAPI_MakeSolid.hxx>
#include <BRepCheck_Analyzer.hxx>
#include <BRepGProp.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <GProp_GProps.hxx>
#include <ShapeAnalysis_FreeBounds.hxx>
#include <ShapeFix_Shape.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Iterator.hxx>
#include <TopoDS_Solid.hxx>

#include <nlohmann/json.hpp>

#include "brep/damage_check.h"
#include "brep/occt_guard.h"
#include "common/error.h"

namespace topopt::brep {
namespace {

/// The top-level items of a shape: the members of (nested) compounds, or the shape itself.
void flatten(const TopoDS_Shape& shape, std::vector<TopoDS_Shape>& out) {
  if (shape.ShapeType() == TopAbs_COMPOUND || shape.ShapeType() == TopAbs_COMPSOLID) {
    for (TopoDS_Iterator it(shape); it.More(); it.Next()) flatten(it.Value(), out);
  } else {
    out.push_back(shape);
  }
}

int free_edge_count(const TopoDS_Shape& shell) {
  ShapeAnalysis_FreeBounds bounds(shell);
  TopTools_IndexedMapOfShape edges;
  TopExp::MapShapes(bounds.GetClosedWires(), TopAbs_EDGE, edges);
  TopExp::MapShapes(bounds.GetOpenWires(), TopAbs_EDGE, edges);
  return edges.Extent();
}

double signed_volume(const TopoDS_Shape& s) {
  GProp_GProps props;
  BRepGProp::VolumeProperties(s, props);
  return props.Mass();
}

const char* type_name(TopAbs_ShapeEnum t) {
  switch (t) {
    case TopAbs_SHELL:
      return "a shell";
    case TopAbs_FACE:
      return "a face";
    case TopAbs_WIRE:
      return "a wire";
    case TopAbs_EDGE:
      return "an edge";
    case TopAbs_VERTEX:
      return "a vertex";
    default:
      return "not a solid";
  }
}

const char* kRepairAdvice = "repair it (Part > Check geometry in FreeCAD) or re-export it from your CAD system";

/// `item` as a solid: a closed shell is made one (noted); anything else that is not a solid
/// is refused, an open shell with its count of free edges.
TopoDS_Shape solid_of(const TopoDS_Shape& item, const std::string& label, std::vector<std::string>& notes) {
  if (item.ShapeType() == TopAbs_SHELL) {
    int free = free_edge_count(item);
    if (free > 0)
      throw Error(ErrorCode::InvalidShape,
                  label + " is an open shell with " + std::to_string(free) +
                      " free edges, not a closed solid: close the gaps (or sew the faces) and make a solid");
    BRepBuilderAPI_MakeSolid maker(TopoDS::Shell(item));
    if (!maker.IsDone())
      throw Error(ErrorCode::InvalidShape, label + " is a closed shell that could not be made into a solid");
    notes.push_back(label + ": closed shell turned into a solid");
    return maker.Solid();
  }
  if (item.ShapeType() != TopAbs_SOLID)
    throw Error(ErrorCode::InvalidShape,
                label + " is " + type_name(item.ShapeType()) + ", not a solid: give a closed solid");
  return item;
}

void check_closed(const TopoDS_Shape& solid, const std::string& label) {
  for (TopExp_Explorer ex(solid, TopAbs_SHELL); ex.More(); ex.Next()) {
    int free = free_edge_count(ex.Current());
    if (free > 0)
      throw Error(ErrorCode::InvalidShape, label + " is not closed: its shell has " + std::to_string(free) +
                                               " free edges; sew or repair it into a closed solid");
  }
}

/// `solid` if OCCT's checker finds it valid, else what ShapeFix makes of it (noted, with a
/// changed face count called out), which must be a valid single solid.
TopoDS_Shape healed_if_invalid(const TopoDS_Shape& solid, const std::string& label, std::vector<std::string>& notes) {
  BRepCheck_Analyzer check(solid);
  if (check.IsValid()) return solid;
  ShapeFix_Shape fix(solid);
  fix.Perform();
  TopoDS_Shape healed = fix.Shape();
  BRepCheck_Analyzer recheck(healed);
  if (!recheck.IsValid())
    throw Error(ErrorCode::InvalidShape, label +
                                             " is not a valid B-Rep and could not be healed: run Part > Check "
                                             "geometry in FreeCAD and repair it");
  TopTools_IndexedMapOfShape before, after;
  TopExp::MapShapes(solid, TopAbs_FACE, before);
  TopExp::MapShapes(healed, TopAbs_FACE, after);
  notes.push_back(label + ": invalid B-Rep healed by ShapeFix" +
                  (before.Extent() == after.Extent()
                       ? std::string()
                       : " (face count changed from " + std::to_string(before.Extent()) + " to " +
                             std::to_string(after.Extent()) + ": face numbers refer to the healed solid)"));
  if (healed.ShapeType() != TopAbs_SOLID) {
    std::vector<TopoDS_Shape> parts;
    flatten(healed, parts);
    if (parts.size() != 1 || parts[0].ShapeType() != TopAbs_SOLID)
      throw Error(ErrorCode::InvalidShape, label + " did not heal into a single solid");
    healed = parts[0];
  }
  return healed;
}

/// `solid` with positive volume: turned outwards if inside out (noted); zero volume refused.
TopoDS_Shape turned_outwards(TopoDS_Shape solid, const std::string& label, std::vector<std::string>& notes) {
  double volume = signed_volume(solid);
  if (volume < 0) {
    solid.Reverse();
    volume = -volume;
    notes.push_back(label + ": solid was inside out; turned outwards");
  }
  if (!(volume > 0)) throw Error(ErrorCode::InvalidShape, label + " has zero volume: give a solid with thickness");
  return solid;
}

/// One item of the input made a checked solid: a solid (or closed shell), closed, free of
/// gross damage (before OCCT's checker, which crashes or hangs on it), valid or healed, outwards.
TopoDS_Shape check_one(const TopoDS_Shape& item, const std::string& label, std::vector<std::string>& notes) {
  const TopoDS_Shape solid = solid_of(item, label, notes);
  check_closed(solid, label);
  check_gross_damage(solid, label, kRepairAdvice);
  return turned_outwards(healed_if_invalid(solid, label, notes), label, notes);
}

/// Runs in the child: checks and heals every item. Returns one line of JSON,
/// {"notes": [...], "replaced": [[item, bytes], ...]}, then for each item that changed (made
/// a solid, turned outwards, healed) its shape as handover bytes, in that order.
std::string check_items_here(const std::vector<TopoDS_Shape>& items, const std::string& what,
                             const ForeignInput& input) {
  std::vector<std::string> notes;
  nlohmann::json replaced = nlohmann::json::array();
  std::string shapes;
  for (size_t i = 0; i < items.size(); ++i) {
    std::string label = items.size() == 1 ? "the " + what : "item " + std::to_string(i + 1) + " of the " + what;
    TopoDS_Shape checked = check_one(items[i], label, notes);
    if (checked.IsEqual(items[i])) continue;
    const std::string bytes = handover_bytes(checked, input);
    replaced.push_back({i, bytes.size()});
    shapes += bytes;
  }
  return nlohmann::json{{"notes", notes}, {"replaced", replaced}}.dump() + "\n" + shapes;
}

}  // namespace

TopoDS_Shape check_solids(const TopoDS_Shape& shape, const std::string& what, std::vector<std::string>& notes,
                          const ForeignParams& params, const Progress& progress) {
  if (shape.IsNull()) throw Error(ErrorCode::InvalidShape, "the " + what + " is empty");
  std::vector<TopoDS_Shape> items;
  flatten(shape, items);
  if (items.empty()) throw Error(ErrorCode::InvalidShape, "the " + what + " holds no solid");
  const ForeignInput input{"the " + what, kRepairAdvice, shape_bytes(shape), ErrorCode::InvalidShape};
  const std::string answer = run_foreign(
      input, "checking and healing", params, [&] { return check_items_here(items, what, input); }, progress);
  const size_t line = answer.find('\n');
  const nlohmann::json head = nlohmann::json::parse(answer.substr(0, line));
  for (const auto& note : head["notes"]) notes.push_back(note.get<std::string>());
  size_t at = line + 1;
  for (const auto& r : head["replaced"]) {
    const size_t n = r[1].get<size_t>();
    items[r[0].get<size_t>()] = shape_from_handover(answer.substr(at, n), input);
    at += n;
  }
  if (items.size() == 1 && shape.ShapeType() == TopAbs_SOLID) return items[0];
  TopoDS_Compound compound;
  BRep_Builder builder;
  builder.MakeCompound(compound);
  for (const TopoDS_Shape& s : items) builder.Add(compound, s);
  return compound;
}

}  // namespace topopt::brep
