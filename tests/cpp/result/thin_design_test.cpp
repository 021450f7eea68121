// Thin designs (sheets and ribs one or two elements thick, a one-layer skin on a face, at the
// threshold 0.185 of the crossing box study) cut on the FE mesh and on the refined mesh: the
// finished surface is a valid solid (closed, no exact self-intersection). On these fields only
// the smoothing makes crossings (never the cut or the remeshing), and the repair undoes them.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

#include "mesh/core/structured_box.h"
#include "mesh/surface/surface_check.h"
#include "result/design_surface.h"
#include "result/iso_surface_refine.h"
#include "simp/density_filter.h"

namespace topopt::result {
namespace {

using Field = std::function<double(const Eigen::Vector3d&)>;

/// Node densities of `rho` (at tet centroids) on the 40 x 20 x 10 mm box in 2 mm cells.
TriSurface cut(const Field& rho, int resolution, double threshold) {
  mesh::StructuredBoxParams p;
  p.size = {40, 20, 10};
  p.cells = {20, 10, 5};
  const TetMesh m = mesh::structured_box_mesh(p);
  const MatX3d c = simp::tet_centroids(m);
  VecXd d(m.T.rows());
  for (long t = 0; t < m.T.rows(); ++t) d[t] = rho(c.row(t).transpose());
  const VecXd nd = node_densities(m, d);
  if (resolution == 1) return extract_iso_surface(m, nd, threshold, 0.2);
  const RefinedField r = refine_near_level(m, nd, threshold);
  return extract_iso_surface(r.mesh, r.node_density, threshold, 0.2);
}

void expect_valid_at_every_stage(const std::string& name, const Field& rho) {
  for (int resolution : {1, 2}) {
    TriSurface s = cut(rho, resolution, 0.185);
    EXPECT_TRUE(mesh::self_intersections(s.V, s.F, 1).empty()) << name << ": the cut crosses itself";
    const DesignSurfaceReport r = finish_design_surface(s, SmoothParams{});
    EXPECT_TRUE(r.check.valid()) << name << " at resolution " << resolution << ": " << r.check.crossings.size()
                                 << " crossing pairs (" << r.crossings_smoothed << " after smoothing), open edges "
                                 << r.check.closed.open_edges;
    EXPECT_GE(r.check.min_angle_free, 10.0) << name << " at resolution " << resolution;
  }
}

TEST(ThinDesign, SheetsRibsAndSkinsStayValidSolids) {
  expect_valid_at_every_stage("a one-layer skin on z = 0",
                              [](const Eigen::Vector3d& x) { return x[2] < 2 ? 1.0 : 0.1 + 0.05 * std::sin(x[0]); });
  expect_valid_at_every_stage("a wavy sheet", [](const Eigen::Vector3d& x) {
    const double dz = x[2] - (5 + 2 * std::sin(x[0] / 5));
    return std::exp(-dz * dz);
  });
  expect_valid_at_every_stage("a sheet one element off a face", [](const Eigen::Vector3d& x) {
    const double dz = x[2] - 2.5 - 0.5 * std::sin(x[0] / 4 + x[1] / 3);
    return std::exp(-dz * dz / 0.8);
  });
  expect_valid_at_every_stage("thin ribs on a skin", [](const Eigen::Vector3d& x) {
    const double dy = std::fmod(x[1] + 100, 5.0) - 2.5;
    return std::exp(-dy * dy / 0.6) * (x[2] > 1 ? 1 : 0.5) + (x[2] < 1 ? 0.9 : 0.0);
  });
}

}  // namespace
}  // namespace topopt::result
