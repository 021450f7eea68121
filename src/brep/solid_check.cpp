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

TopoDS_Shape check_one(TopoDS_Shape item, const std::string& label, std::vector<std::string>& notes) {
  if (item.ShapeType() == TopAbs_SHELL) {
    int free = free_edge_count(item);
    if (free > 0)
      throw Error(ErrorCode::InvalidShape,
                  label + " is an open shell with " + std::to_string(free) +
                      " free edges, not a closed solid: close the gaps (or sew the faces) and make a solid");
    BRepBuilderAPI_MakeSolid maker(TopoDS::Shell(item));
    if (!maker.IsDone())
      throw Error(ErrorCode::InvalidShape, label + " is a closed shell that could not be made into a solid");
    item = maker.Solid();
    notes.push_back(label + ": closed shell turned into a solid");
  }
  if (item.ShapeType() != TopAbs_SOLID)
    throw Error(ErrorCode::InvalidShape,
                label + " is " + type_name(item.ShapeType()) + ", not a solid: give a closed solid");

  for (TopExp_Explorer ex(item, TopAbs_SHELL); ex.More(); ex.Next()) {
    int free = free_edge_count(ex.Current());
    if (free > 0)
      throw Error(ErrorCode::InvalidShape, label + " is not closed: its shell has " + std::to_string(free) +
                                               " free edges; sew or repair it into a closed solid");
  }

  BRepCheck_Analyzer check(item);
  if (!check.IsValid()) {
    ShapeFix_Shape fix(item);
    fix.Perform();
    TopoDS_Shape healed = fix.Shape();
    BRepCheck_Analyzer recheck(healed);
    if (!recheck.IsValid())
      throw Error(ErrorCode::InvalidShape,
                  label +
                      " is not a valid B-Rep and could not be healed: run Part > Check geometry in "
                      "FreeCAD and repair it");
    TopTools_IndexedMapOfShape before, after;
    TopExp::MapShapes(item, TopAbs_FACE, before);
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
    item = healed;
  }

  double volume = signed_volume(item);
  if (volume < 0) {
    item.Reverse();
    volume = -volume;
    notes.push_back(label + ": solid was inside out; turned outwards");
  }
  if (!(volume > 0)) throw Error(ErrorCode::InvalidShape, label + " has zero volume: give a solid with thickness");
  return item;
}

}  // namespace

TopoDS_Shape check_solids(const TopoDS_Shape& shape, const std::string& what, std::vector<std::string>& notes) {
  if (shape.IsNull()) throw Error(ErrorCode::InvalidShape, "the " + what + " is empty");
  std::vector<TopoDS_Shape> items;
  flatten(shape, items);
  if (items.empty()) throw Error(ErrorCode::InvalidShape, "the " + what + " holds no solid");
  std::vector<TopoDS_Shape> solids;
  for (size_t i = 0; i < items.size(); ++i) {
    std::string label = items.size() == 1 ? "the " + what : "item " + std::to_string(i + 1) + " of the " + what;
    solids.push_back(check_one(items[i], label, notes));
  }
  if (solids.size() == 1 && shape.ShapeType() == TopAbs_SOLID) return solids[0];
  TopoDS_Compound compound;
  BRep_Builder builder;
  builder.MakeCompound(compound);
  for (const TopoDS_Shape& s : solids) builder.Add(compound, s);
  return compound;
}

}  // namespace topopt::brep
