// Native single-model meshing: surface mesher + 3D advancing front (see native_mesher.h).
#include "mesh/native_mesher.h"

#include <algorithm>
#include <memory>
#include <sstream>
#include <vector>

#include "common/error.h"

namespace topopt::mesh {
namespace {

/// Graded size inside a closed surface: a uniform background grid (cells of h/2) holding
/// min(h, s_i + g·d) for the boundary nodes' spacings s_i, relaxed by a two-pass chamfer
/// sweep (6-neighbour steps), looked up at the nearest cell. Without it the front jumps from
/// fine boundary parts (bores refined by curvature) to the full size in one layer.
class BackgroundSize {
 public:
  BackgroundSize(const MatX3d& V, const MatX3i& F, double h, double g) {
    lo_ = V.colwise().minCoeff().transpose();
    const Eigen::Vector3d hi = V.colwise().maxCoeff().transpose();
    cell_ = h / 2;
    auto dims = [&]() {
      for (int d = 0; d < 3; ++d) n_[d] = static_cast<long>((hi[d] - lo_[d]) / cell_) + 2;
      return n_[0] * n_[1] * n_[2];
    };
    while (dims() > 20'000'000) cell_ *= 1.25;  // memory: at most 80 MB of floats
    size_.assign(n_[0] * n_[1] * n_[2], static_cast<float>(h));
    // boundary nodes: the mean length of their edges
    std::vector<double> sum(V.rows(), 0.0);
    std::vector<int> cnt(V.rows(), 0);
    for (long t = 0; t < F.rows(); ++t)
      for (int k = 0; k < 3; ++k) {
        const int a = F(t, k), b = F(t, (k + 1) % 3);
        const double l = (V.row(a) - V.row(b)).norm();
        sum[a] += l, ++cnt[a], sum[b] += l, ++cnt[b];
      }
    for (long i = 0; i < V.rows(); ++i)
      if (cnt[i]) {
        float& c = size_[index(V.row(i).transpose())];
        c = std::min(c, static_cast<float>(sum[i] / cnt[i]));
      }
    const float step = static_cast<float>(g * cell_);
    for (int pass = 0; pass < 2; ++pass) {
      const long dir = pass == 0 ? 1 : -1;
      for (long i = pass == 0 ? 0 : n_[0] - 1; i >= 0 && i < n_[0]; i += dir)
        for (long j = pass == 0 ? 0 : n_[1] - 1; j >= 0 && j < n_[1]; j += dir)
          for (long k = pass == 0 ? 0 : n_[2] - 1; k >= 0 && k < n_[2]; k += dir) {
            float& c = size_[(i * n_[1] + j) * n_[2] + k];
            if (i - dir >= 0 && i - dir < n_[0]) c = std::min(c, size_[((i - dir) * n_[1] + j) * n_[2] + k] + step);
            if (j - dir >= 0 && j - dir < n_[1]) c = std::min(c, size_[(i * n_[1] + j - dir) * n_[2] + k] + step);
            if (k - dir >= 0 && k - dir < n_[2]) c = std::min(c, size_[(i * n_[1] + j) * n_[2] + k - dir] + step);
          }
    }
  }
  double at(const double* x) const { return size_[index(Eigen::Vector3d(x[0], x[1], x[2]))]; }

 private:
  long index(const Eigen::Vector3d& x) const {
    long c[3];
    for (int d = 0; d < 3; ++d) c[d] = std::clamp(static_cast<long>((x[d] - lo_[d]) / cell_), 0L, n_[d] - 1);
    return (c[0] * n_[1] + c[1]) * n_[2] + c[2];
  }
  double cell_;
  Eigen::Vector3d lo_;
  long n_[3];
  std::vector<float> size_;
};

}  // namespace

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
  std::shared_ptr<BackgroundSize> background;
  if (!vp.size) {
    // the surface's target size inside, graded from finer boundary parts
    const double h = params.surface.size > 0 ? params.surface.size : model.part.diagonal() / 50;
    background = std::make_shared<BackgroundSize>(s.V, s.F, h, params.surface.gradation - 1);
    vp.size = [background](const double* x) { return background->at(x); };
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
