// Which vertices, edges and faces of a model a point lies on, within tolerance. Built once
// per model (bounding boxes from exact geometry cut the candidates before any projection);
// used by the classification, the conformity checker and the mesh transfers.
#pragma once
#include <Bnd_Box.hxx>
#include <gp_Pnt.hxx>
#include <vector>

#include "brep/topology_index.h"

namespace topopt::brep {

/// A point found on an entity: its 0-based index, the parameters there (edge: t0 = curve
/// parameter; face: (t0, t1) = (u, v)) and the distance.
struct Hit {
  int index;
  double t0, t1, distance;
};

class PointLocator {
 public:
  /// model: the indexed shape (kept by reference: it must outlive the locator).
  /// tol: absolute tolerance added to the entities' own tolerances.
  PointLocator(const TopologyIndex& model, double tol);

  /// Vertices within tolerance of p (extra_tol is added, e.g. the querying entity's own).
  std::vector<Hit> vertices_at(const gp_Pnt& p, double extra_tol = 0) const;
  /// Non-degenerate edges whose curve, within its range, passes within tolerance of p.
  std::vector<Hit> edges_at(const gp_Pnt& p, double extra_tol = 0) const;
  /// Faces whose surface passes within tolerance of p at a (u, v) inside the trimmed face.
  std::vector<Hit> faces_at(const gp_Pnt& p, double extra_tol = 0) const;

 private:
  const TopologyIndex& m_;
  double tol_;
  std::vector<Bnd_Box> edge_box_, face_box_;
};

}  // namespace topopt::brep
