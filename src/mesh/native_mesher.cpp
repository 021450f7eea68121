// Native single-model meshing: surface mesher + 3D advancing front (see native_mesher.h).
#include "mesh/native_mesher.h"

#include <sstream>

#include "common/error.h"

namespace topopt::mesh {

TetMesh mesh_native(const brep::TwoBReps& model, const NativeMeshParams& params, const Progress& progress) {
  if (model.nondesign.num_solids() > 0)
    throw Error(ErrorCode::InvalidParameter,
                "the native mesher does not take non-design solids yet (the 14-step driver is issue 5); "
                "use the default mesher for a part with non-design solids");
  progress.say("mesh", 0.05, "surface mesh");
  SurfaceMesh s = mesh_surface(model.part, params.surface, progress);
  if (!s.failed_faces.empty()) {
    std::ostringstream m;
    m << "the surface mesher could not mesh";
    for (size_t k = 0; k < s.failed_faces.size() && k < 5; ++k) m << (k ? ", " : " ") << "Face" << s.failed_faces[k];
    m << " (" << s.reasons[0] << ")";
    throw Error(ErrorCode::MeshingFailed, m.str());
  }
  progress.say("mesh", 0.3, "volume mesh");
  VolumeFillParams vp = params.volume;
  if (!vp.size) {
    // the surface's target size inside; the front grades towards it from finer boundary parts
    const double h = params.surface.size > 0 ? params.surface.size : model.part.diagonal() / 50;
    vp.size = [h](const double*) { return h; };
  }
  VolumeFillResult r = fill_volume(s.V, s.F, MatX4i(), vp, progress);
  TetMesh m;
  m.V = std::move(r.V);
  m.T = std::move(r.T);
  m.domain = VecXi::Zero(m.T.rows());
  m.F = s.F;
  m.face = s.face;
  return m;
}

}  // namespace topopt::mesh
