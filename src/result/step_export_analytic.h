// The input's curved analytic faces in the result's STEP: which triangles of the result surface
// lie on a cylinder, cone, sphere or torus of Ω or of a non-design solid (SourceFaces, a lookup
// from a triangle's tag and place to the input's TopoDS_Face), and one B-Rep face on that
// ORIGINAL surface per connected region of such triangles (analytic_faces), bounded by the
// region's boundary polylines made of the same shared edges the neighbouring faces use, so the
// shell stays closed by construction. Each edge gets a 2D curve on the surface (the straight
// line between its end points' (u, v)) and the tolerance of its largest distance from the
// surface along it (the straight edge is a chord, sampled at 17 points). A region that wraps all the way round the axis
// (a full bore) is split in two halves, each on a copy of the surface turned about its axis so that the half lies clear
// of the parametric seam: no seam edge to build.
#pragma once
#include <Geom_ElementarySurface.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <functional>
#include <gp_Pnt.hxx>
#include <gp_Vec.hxx>
#include <vector>

#include "result/iso_surface.h"

namespace topopt::result {

/// The curved analytic faces (cylinder, cone, sphere, torus) of the part Ω and of the non-design
/// solids, as the result surface's tags name them (iso_surface.h: f > 0 Ω's face f, -k a face
/// of non-design solid k). Planar faces are left out: the export merges coplanar facets already.
class SourceFaces {
 public:
  SourceFaces() = default;
  /// `part`: Ω (its faces numbered as FreeCAD numbers them, TopExp::MapShapes order);
  /// `nondesign`: the compound of the non-design solids Ω1..ΩN in input order (may be null).
  SourceFaces(const TopoDS_Shape& part, const TopoDS_Shape& nondesign);

  /// True when neither shape has a curved analytic face.
  bool empty() const { return faces_.empty(); }

  /// #Q (s.F's rows): per triangle, the index (into face()) of the curved analytic input face
  /// it lies on, or -1 (free-form, planar, or on no such face). A triangle tagged f > 0 is
  /// looked for on Ω's face f, one tagged -k on the faces of non-design solid k; it lies on a
  /// face when its centre is within 0.2 of its longest edge of the surface and its normal
  /// within 45° of the surface's (either way round). Of several, the nearest.
  std::vector<int> classify(const TriSurface& s) const;

  /// For a tet mesh whose boundary triangles carry no face numbers (the workbench's stored
  /// mesh, re-extracted by the threshold slider): per row of `F` (#F by 3 boundary triangles of
  /// nodes `V`, #V by 3, mm, either orientation), the number f (1-based, as classify reads tags)
  /// of the curved analytic face of Ω the triangle lies on, by the same test as classify and
  /// inside that face's bounding box (enlarged by the triangle's longest edge); 0 for any other
  /// triangle (planar faces, non-design solids, none). Returns #F numbers, a TetMesh::face.
  VecXi part_face_numbers(const MatX3d& V, const MatX3i& F) const;

  /// The input face with index `id` (0 <= id < size()).
  const TopoDS_Face& face(int id) const { return faces_[id]; }
  /// Its surface (cylinder, cone, sphere or torus) in the face's place, untrimmed.
  const Handle(Geom_ElementarySurface) & surface(int id) const { return surfaces_[id]; }
  int size() const { return static_cast<int>(faces_.size()); }

 private:
  void add(const TopoDS_Face& face, std::vector<int>& ids);
  std::vector<TopoDS_Face> faces_;                        ///< the curved analytic faces, Ω's first
  std::vector<Handle(Geom_ElementarySurface)> surfaces_;  ///< #faces_: their surfaces
  std::vector<std::vector<int>> part_face_;               ///< Ω face number f (1-based) -> ids (0 or 1)
  std::vector<std::vector<int>> solid_faces_;             ///< non-design solid k (1-based) -> its ids
  /// Of the candidates `ids`, the one whose surface lies nearest the triangle with centre `c`,
  /// area normal `n` and longest edge `edge` (within 0.2 edge, normals within 45°); -1 if none.
  int nearest(const std::vector<int>& ids, const gp_Pnt& c, const gp_Vec& n, double edge) const;
};

/// Gives the shared B-Rep edge from point a to point b of the surface, oriented a -> b (the
/// stored edge is a straight line from the lower point number to the higher, parameter 0 to its
/// length).
using EdgeSource = std::function<TopoDS_Edge(int a, int b)>;

/// Faces on the input's surface `surface` for the triangles `region` of `s` (outward triangles,
/// all lying on that surface, one connected piece or several): one face per connected piece,
/// two per piece that wraps round the axis (see the file comment) or whose one face OCCT's
/// check refuses (the halves are tried once each). Each face is bounded by the
/// piece's boundary loops made of `edges`, oriented outwards, checked by BRepCheck. Returns the
/// faces made; the triangles of pieces whose face could not be made or failed the check are
/// appended to `facets` (to be written as triangles), the 2D curves added for them removed, and
/// `refused` counts such pieces.
std::vector<TopoDS_Face> analytic_faces(const TriSurface& s, const std::vector<long>& region,
                                        const Handle(Geom_ElementarySurface) & surface, const EdgeSource& edges,
                                        std::vector<long>& facets, int& refused);

}  // namespace topopt::result
