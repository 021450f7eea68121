// Projection onto the input's curved faces (see curved_faces.h).
#include "result/curved_faces.h"

#include <GeomAPI_ProjectPointOnSurf.hxx>
#include <map>

#include "result/step_export_analytic.h"

namespace topopt::result {

namespace {

/// Moves p onto the untrimmed surface of `source`'s face `id` (its nearest point); false if none.
bool onto_surface(const SourceFaces& source, int id, Eigen::Vector3d& p) {
  if (id < 0 || id >= source.size()) return false;
  GeomAPI_ProjectPointOnSurf nearest(gp_Pnt(p.x(), p.y(), p.z()), source.surface(id));
  if (nearest.NbPoints() == 0) return false;
  const gp_Pnt q = nearest.NearestPoint();
  p = Eigen::Vector3d(q.X(), q.Y(), q.Z());
  return true;
}

}  // namespace

FaceProjector curved_face_projector(const SourceFaces& source, const TriSurface& s) {
  if (source.empty()) return {};
  std::map<int, int> surface_of;  // Ω face number -> SourceFaces id
  const std::vector<int> on = source.classify(s);
  for (long q = 0; q < s.F.rows(); ++q)
    if (s.tag[q] > 0 && on[q] >= 0) surface_of.emplace(s.tag[q], on[q]);
  FaceProjector out;
  out.onto_face = [&source, surface_of](int tag, Eigen::Vector3d& p) {
    const auto it = surface_of.find(tag);
    return it != surface_of.end() && onto_surface(source, it->second, p);
  };
  out.nondesign_faces = [&source](const TriSurface& t) {
    std::vector<int> id = source.classify(t);
    for (long q = 0; q < t.F.rows(); ++q)
      if (t.tag[q] >= 0) id[q] = -1;
    return id;
  };
  out.onto_nondesign = [&source](int id, Eigen::Vector3d& p) { return onto_surface(source, id, p); };
  return out;
}

}  // namespace topopt::result
