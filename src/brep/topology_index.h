// Flat tables of a shape's topology, numbered exactly as FreeCAD numbers sub-shapes
// (TopExp::MapShapes order: FreeCAD's Face7 is faces index 6 here; all arrays are 0-based).
#pragma once
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS_Shape.hxx>
#include <string>
#include <vector>

#include "common/adjacency.h"
#include "common/types.h"

namespace topopt::brep {

/// The topology of one shape. Maps hold the OCCT sub-shapes (1-based, OCCT convention); every
/// other array is 0-based with row k describing map entry k+1.
struct TopologyIndex {
  TopoDS_Shape shape;
  TopTools_IndexedMapOfShape vertices, edges, faces, shells, solids;

  MatX3d vertex_point;                    ///< #V by 3
  VecXd vertex_tolerance;                 ///< #V
  MatX2i edge_vertices;                   ///< #E by 2: first, last vertex (-1 if the edge has none)
  std::vector<bool> edge_degenerate;      ///< #E: collapsed edge (cone apex, sphere pole)
  VecXd edge_length;                      ///< #E
  VecXd edge_tolerance;                   ///< #E
  Adjacency face_edges;                   ///< per face: its edges (a seam edge appears twice)
  Adjacency face_wires;                   ///< per face: the number of edges of each wire, outer first
  VecXd face_area;                        ///< #F
  MatX3d face_centre;                     ///< #F by 3: centre of area (may lie off a curved face)
  std::vector<std::string> face_surface;  ///< #F: "Plane", "Cylinder", "BSpline", ...
  VecXd face_tolerance;                   ///< #F
  Adjacency shell_faces;                  ///< per shell: its faces
  Adjacency solid_shells;                 ///< per solid: its shells, outer first
  Adjacency solid_faces;                  ///< per solid: all its faces
  VecXi face_solid;                       ///< #F: the first solid that holds the face (-1: none)
  VecXd solid_volume;                     ///< #S (signed: negative means reversed)
  double bbox_min[3]{0, 0, 0}, bbox_max[3]{0, 0, 0};

  int num_vertices() const { return vertices.Extent(); }
  int num_edges() const { return edges.Extent(); }
  int num_faces() const { return faces.Extent(); }
  int num_shells() const { return shells.Extent(); }
  int num_solids() const { return solids.Extent(); }
  /// Length of the bounding box diagonal (the model's size).
  double diagonal() const;
};

/// Builds the index of `shape`. Geometry summaries (areas, volumes, lengths) come from
/// BRepGProp; nothing in the shape is modified.
TopologyIndex index_topology(const TopoDS_Shape& shape);

/// Name of the surface type of a face ("Plane", "Cylinder", "Cone", "Sphere", "Torus",
/// "BSpline", "Bezier", "Revolution", "Extrusion", "Offset", "Other").
std::string surface_type_name(const TopoDS_Shape& face);

}  // namespace topopt::brep
