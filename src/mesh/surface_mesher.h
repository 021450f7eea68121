// Surface meshing of one B-Rep model by its hierarchy (steps 1, 5 and 9 of the method for a
// single model): nodes on the vertices, the edges discretised once (so faces that share an
// edge share its nodes), then every face filled by the 2D advancing front (face_front.h) in
// its parameter plane, scaled so that lengths there approximate lengths on the surface.
//
// Sizes: a global size (default diagonal / 50) refined by the curvature of faces and edges
// (max_angle of turning per element, floor min_size), graded along edges from their
// vertices and inside faces from finer boundary pieces (gradation); boundary pieces are split
// where a face's loops come close to each other (proximity) or run longer than the face's
// graded size. The parameter scaling is exact for planes and cylinders and approximate on
// other surfaces; the triangles are then improved on the surface itself (surface_optimize.h).
// A collapsed edge (cone apex, sphere pole) becomes a fan of triangles around its apex.
#pragma once
#include <string>
#include <vector>

#include "brep/topology_index.h"
#include "common/progress.h"
#include "common/types.h"
#include "mesh/face_front.h"

namespace topopt::mesh {

struct SurfaceMeshParams {
  double size = 0;                   ///< target edge length (mm); <= 0: the model's diagonal / 50
  double min_size = 0;               ///< smallest edge length (mm); <= 0: size / 10
  double max_angle = 2 * 3.14159265358979323846 / 16;  ///< turning of the surface or edge per element (rad)
  double gradation = 1.3;            ///< how fast sizes may grow away from finer regions (ratio per element)
  int optimize_rounds = 3;           ///< flip + smoothing rounds judged on the surface (0: none)
  int threads = 0;                   ///< faces meshed in parallel; 0 = all cores
  FaceFrontParams front;             ///< the face engine's settings (its size is set per face)
};

struct SurfaceMesh {
  MatX3d V;      ///< #V by 3 nodes; the first #vertices are the model's vertices, in order
  MatX3i F;      ///< #F by 3 triangles, normals pointing out of the solid that holds the face
  VecXi face;    ///< #F: the face's number, 1-based as FreeCAD's FaceN
  std::vector<int> failed_faces;  ///< faces that could not be meshed (1-based), with reasons below
  std::vector<std::string> reasons;
};

/// Meshes every face of `topo`. A face that cannot be meshed is listed in failed_faces (the
/// rest of the surface is still returned) so callers can name it.
SurfaceMesh mesh_surface(const brep::TopologyIndex& topo, const SurfaceMeshParams& params = {},
                         const Progress& progress = {});

/// Per solid of `topo`: the number of mesh edges not used exactly twice in opposite directions
/// by the triangles of that solid's faces (0 for a closed, consistently oriented surface).
std::vector<long> open_edges_per_solid(const brep::TopologyIndex& topo, const SurfaceMesh& mesh);

/// The triangles (rows of mesh.F) on the faces of solid s (0-based), oriented out of that
/// solid, as their own triangle list over mesh.V.
MatX3i solid_triangles(const brep::TopologyIndex& topo, const SurfaceMesh& mesh, int s);

}  // namespace topopt::mesh
