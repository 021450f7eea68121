// Projection onto Ω's curved faces (see curved_faces.h).
#include "result/curved_faces.h"

#include <GeomAPI_ProjectPointOnSurf.hxx>
#include <map>

#include "result/step_export_analytic.h"

namespace topopt::result {

FaceProjector curved_face_projector(const SourceFaces& source, const TriSurface& s) {
  std::map<int, int> surface_of;  // Ω face number -> SourceFaces id
  if (!source.empty()) {
    const std::vector<int> on = source.classify(s);
    for (long q = 0; q < s.F.rows(); ++q)
      if (s.tag[q] > 0 && on[q] >= 0) surface_of.emplace(s.tag[q], on[q]);
  }
  return [&source, surface_of](int tag, Eigen::Vector3d& p) {
    const auto it = surface_of.find(tag);
    if (it == surface_of.end()) return false;
    GeomAPI_ProjectPointOnSurf nearest(gp_Pnt(p.x(), p.y(), p.z()), source.surface(it->second));
    if (nearest.NbPoints() == 0) return false;
    const gp_Pnt q = nearest.NearestPoint();
    p = Eigen::Vector3d(q.X(), q.Y(), q.Z());
    return true;
  };
}

}  // namespace topopt::result
