// Surface meshing by the B-Rep hierarchy on the shared examples: every face meshed, every
// solid's surface closed and consistently oriented (each mesh edge used once in each
// direction), outward (the enclosed volume equals the B-Rep's), triangles tagged with their
// face (the tagged areas equal the faces' areas).
#include "mesh/surface_mesher.h"

#include <gtest/gtest.h>

#include <string>

#include "brep/shape_io.h"
#include "mesh/surface_check.h"

namespace topopt::mesh {
namespace {

/// size_factor times the default size (diagonal / 50)
void check_model(const std::string& file, double size_factor, double area_tolerance = 0.02) {
  SCOPED_TRACE(file + " at " + std::to_string(size_factor) + " x the default size");
  brep::TopologyIndex topo = brep::index_topology(brep::read_shape_file(std::string(TOPOPT_SHARED_DATA) + "/" + file));
  SurfaceMeshParams p;
  p.size = size_factor * topo.diagonal() / 50;
  SurfaceMesh m = mesh_surface(topo, p);
  for (size_t k = 0; k < m.failed_faces.size(); ++k)
    ADD_FAILURE() << "Face" << m.failed_faces[k] << ": " << m.reasons[k];
  ASSERT_GT(m.F.rows(), 0);
  std::vector<long> open = open_edges_per_solid(topo, m);
  for (size_t s = 0; s < open.size(); ++s) EXPECT_EQ(open[s], 0) << "solid " << s + 1;
  for (int s = 0; s < topo.num_solids(); ++s) {
    const auto pairs = self_intersections(m.V, solid_triangles(topo, m, s), 5);
    EXPECT_TRUE(pairs.empty()) << "solid " << s + 1 << ": triangles " << pairs[0].first << " and " << pairs[0].second
                               << " intersect";
  }
  // quality floor (bench/surface compares with Gmsh): few triangles below 20°, none flat
  const SurfaceQuality q = surface_quality(m.V, m.F);
  EXPECT_LT(q.share_below_20, 0.01);
  EXPECT_GT(q.min_angle, 0.05);
  EXPECT_GT(q.mean_min_angle, 45);
  // volume enclosed (divergence theorem over all triangles; solids do not share faces here)
  // and area per face
  double vol = 0;
  std::vector<double> area(topo.num_faces(), 0.0);
  for (long t = 0; t < m.F.rows(); ++t) {
    Eigen::Vector3d a = m.V.row(m.F(t, 0)), b = m.V.row(m.F(t, 1)), c = m.V.row(m.F(t, 2));
    vol += a.dot(b.cross(c)) / 6;
    area[m.face[t] - 1] += 0.5 * (b - a).cross(c - a).norm();
  }
  double bvol = 0;
  for (long s = 0; s < topo.solid_volume.size(); ++s) bvol += std::abs(topo.solid_volume[s]);
  EXPECT_NEAR(vol, bvol, 0.01 * bvol);  // chordal error of curved faces at this size
  for (int f = 0; f < topo.num_faces(); ++f)
    EXPECT_NEAR(area[f], topo.face_area[f], area_tolerance * topo.face_area[f] + 1e-9) << "Face" << f + 1;
}

TEST(SurfaceMesher, EverySharedPartIsClosedAndOriented) {
  // NIST's PMI parts and OCCT's samples: B-spline, conical, spherical and toroidal faces,
  // seams and poles, at the default size and at half of it.
  for (double factor : {1.0, 0.5})
    for (std::string name : {"nist/NIST_MBE_PMI_1.stp", "nist/NIST_MBE_PMI_2.stp", "nist/NIST_MBE_PMI_3.stp",
                             "nist/NIST_MBE_PMI_4.stp", "nist/NIST_MBE_PMI_5.stp", "nist/NIST_MBE_PMI_6.stp",
                             "nist/NIST_MBE_PMI_11.stp", "occt/CrankArm.brep", "occt/linkrods.step"})
      check_model(name, factor, 0.05);
}

TEST(SurfaceMesher, ExamplesAreClosedOrientedAndTagged) {
  for (double factor : {1.0, 0.5})
    for (std::string name : {"cantilever", "rocker", "bracket"}) {
      check_model("examples/" + name + ".step", factor);
      check_model("examples/" + name + "_nondesign.step", factor);
    }
}

}  // namespace
}  // namespace topopt::mesh
