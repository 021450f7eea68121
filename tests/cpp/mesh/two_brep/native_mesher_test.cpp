// The native mesher end to end on the shared examples: a part alone (our surface mesh filled
// by our advancing front), and the part with its non-design solids through the 14 steps —
// one conformal tagged mesh (no duplicate nodes, interior faces shared by two tets, boundary
// equal to the surface mesh, interface between domains on Ω̄'s faces, every domain's volume
// within 0.5 % of the B-Rep's), the bracket's touching clamp pads conformal across their
// shared face, a load pad's face tagged on the part's boundary.
#include "mesh/two_brep/native_mesher.h"

#include <gtest/gtest.h>
#include <BRepAlgoAPI_Cut.hxx>
#include <BRepAlgoAPI_Fuse.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <ShapeUpgrade_UnifySameDomain.hxx>
#include <gp_Ax2.hxx>

#include <functional>
#include <map>

#include "brep/shape_io.h"
#include "common/error.h"
#include "fem/boundary_conditions.h"
#include "fem/elasticity.h"
#include "mesh/core/conformity.h"
#include "mesh/core/tet_quality.h"
#include "pipeline/mesh_model.h"
#include "pipeline/mesh_settings.h"
#include "testing/expect_error.h"

namespace topopt::mesh {
namespace {

brep::TwoBReps load(const std::string& name, bool with_nd = false) {
  const std::string dir = std::string(TOPOPT_SHARED_DATA) + "/examples/";
  return brep::load_two_breps(brep::read_shape_file(dir + name + ".step"),
                              with_nd ? brep::read_shape_file(dir + name + "_nondesign.step") : TopoDS_Shape());
}

/// The product's parameters (pipeline/mesh_settings.h) at `factor` times the default size.
NativeMeshParams params_at(const brep::TwoBReps& model, double factor) {
  pipeline::MeshSettings s;
  s.size = factor * model.part.diagonal() / 50;
  return pipeline::native_mesh_params(s, pipeline::resolve_mesh_sizes(s, model.part.diagonal(), 0));
}

TetMesh mesh_at(const brep::TwoBReps& model, double factor) { return mesh_native(model, params_at(model, factor)); }

/// The product's mesher choice (pipeline::mesh_model) with `mesher` and `wall_layers`.
TetMesh mesh_with(const brep::TwoBReps& model, pipeline::Mesher mesher, int wall_layers = 0, MeshRun* run = nullptr) {
  pipeline::MeshSettings s;
  s.mesher = mesher;
  s.wall_layers = wall_layers;
  return pipeline::mesh_model(model, s, {}, run);
}

using topopt::testing::expect_error;

/// NIST 1's corner in miniature: a block (x 0..20, y -10..10, z -10..0) under a step (x -5..20,
/// y 0..10, z 0..10) whose wall is a cylinder of radius 10 about the line x = -10, y = 0 that
/// leaves the plane x = 0 tangentially at the origin. The step's floor over the air (z = 0,
/// between x = 0 and the cylinder) has a cusp there, between a reflex edge and a right angle.
TopoDS_Shape tangent_cusp_part() {
  const TopoDS_Shape block = BRepPrimAPI_MakeBox(gp_Pnt(0, -10, -10), 20, 20, 10).Shape();
  const TopoDS_Shape step = BRepPrimAPI_MakeBox(gp_Pnt(-5, 0, 0), 25, 10, 10).Shape();
  const TopoDS_Shape wall = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(-10, 0, -1), gp::DZ()), 10, 12).Shape();
  ShapeUpgrade_UnifySameDomain unify(BRepAlgoAPI_Fuse(block, BRepAlgoAPI_Cut(step, wall).Shape()).Shape());
  unify.Build();
  return unify.Shape();
}

double triangle_area(const TetMesh& m, int a, int b, int c) {
  return 0.5 * (m.V.row(b) - m.V.row(a)).cross(m.V.row(c) - m.V.row(a)).norm();
}

TEST(NativeMesher, NoSliverWhereAnArcLeavesALineTangentially) {
  // The floor's corner at the cusp was closed over pieces of unequal length (1.50 mm on the
  // arc, 1.86 on the line at 4 mm): a cap (158°) under tets of radius ratio 0.06 with all four
  // nodes on the boundary, which nothing in the volume can lift. At equal pieces the corner is
  // a needle (at these sizes 4-9°) and the tets on it stay above 0.1.
  const brep::TwoBReps model = brep::load_two_breps(tangent_cusp_part(), TopoDS_Shape());
  ASSERT_EQ(model.part.num_solids(), 1);
  for (double size : {2.0, 4.0}) {
    SCOPED_TRACE("size " + std::to_string(size) + " mm");
    pipeline::MeshSettings s;
    s.size = size;
    const TetMesh m =
        mesh_native(model, pipeline::native_mesh_params(s, pipeline::resolve_mesh_sizes(s, model.part.diagonal(), 0)));
    const ConformityReport c = check_conformity(m, &model);
    EXPECT_TRUE(c.ok()) << c.to_json().dump();
    EXPECT_NEAR(c.domain_volume[0], c.expected_volume[0], 0.005 * c.expected_volume[0]);
    EXPECT_GE(tet_quality(m).min_radius_ratio, 0.1);
    // the floor's triangle at the cusp (the origin) is not a cap
    int at_cusp = 0;
    for (long t = 0; t < m.F.rows(); ++t) {
      const Eigen::Vector3d p[3] = {m.V.row(m.F(t, 0)), m.V.row(m.F(t, 1)), m.V.row(m.F(t, 2))};
      if (std::min({p[0].norm(), p[1].norm(), p[2].norm()}) > 1e-9) continue;
      bool floor = true;
      for (const auto& q : p) floor = floor && std::abs(q.z()) < 1e-9 && q.x() < 1e-9 && q.y() > -1e-9;
      if (!floor) continue;
      ++at_cusp;
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d u = p[(k + 1) % 3] - p[k], v = p[(k + 2) % 3] - p[k];
        EXPECT_LT(std::atan2(u.cross(v).norm(), u.dot(v)) * 180 / M_PI, 100) << "Face" << m.face[t];
      }
    }
    EXPECT_EQ(at_cusp, 1);
  }
}

TEST(NativeMesher, PartsAloneAreConformalWithTheBRepVolume) {
  for (auto [name, factor] :
       {std::pair<const char*, double>{"rocker", 1.0}, {"rocker", 0.5}, {"cantilever", 1.0}, {"bracket", 1.0}}) {
    SCOPED_TRACE(std::string(name) + " at " + std::to_string(factor) + " x the default size");
    const brep::TwoBReps model = load(name);
    const TetMesh m = mesh_at(model, factor);
    const ConformityReport c = check_conformity(m, &model);
    EXPECT_TRUE(c.ok()) << c.to_json().dump();
    EXPECT_LT(c.max_volume_error, 0.005);
    const QualityReport q = tet_quality(m);
    EXPECT_GT(q.min_radius_ratio, 0);  // no flat or inverted tet
    EXPECT_GT(q.mean_radius_ratio, 0.7);
  }
}

TEST(NativeMesher, WallLayersLetAThinPlateBendLikeABeam) {
  // A cantilever plate 40 x 10 x 1 mm, Face1 (x = 0) fixed, 1 N down on Face2 (x = 40), at the
  // default size (0.83 mm). One layer of linear tets across the thickness (91 % of the volume
  // in tets touching both big faces) locks in bending: 0.27 of the beam's F L³ / 3 E I. With
  // wall_layers = 2 the surface is refined from the thickness and the volume's size is seeded
  // at mid-wall: 0.1 % of the volume left in such tets, 0.63 of the beam (linear tets stay
  // stiff in bending until much finer: 0.77 with 4 layers; quadratic elements would be the cure).
  const brep::TwoBReps model = brep::load_two_breps(BRepPrimAPI_MakeBox(40, 10, 1).Shape(), TopoDS_Shape());
  const fem::Material mat;
  const double beam = 1.0 * 40 * 40 * 40 / (3 * mat.young * 10 * 1.0 / 12);
  double deflection[2], spanning[2];
  for (int layers : {0, 2}) {
    const int k = layers ? 1 : 0;
    const TetMesh m = mesh_with(model, pipeline::Mesher::Native, layers);
    const fem::Supports sup = fem::make_supports(m, {fem::support_on(fem::SupportSpec::Kind::Fixed, {1})});
    const fem::LoadSpec tip{fem::LoadSpec::Kind::Force, {2}, {0, 0, -1}, 0, {}};
    const Eigen::MatrixXd F = fem::make_loads(m, mat, {fem::LoadCase{"tip", {tip}, 1}});
    fem::Elasticity fe(m, mat, sup, {});
    // F·U over the 1 N: the load-weighted mean deflection of the end face
    deflection[k] = F.col(0).dot(fe.solve(F).col(0));
    double span = 0, total = 0;
    for (long t = 0; t < m.T.rows(); ++t) {
      bool bottom = false, top = false;
      for (int c = 0; c < 4; ++c) {
        const double z = m.V(m.T(t, c), 2);
        bottom |= std::abs(z) < 1e-9, top |= std::abs(z - 1) < 1e-9;
      }
      const Eigen::Vector3d a = m.V.row(m.T(t, 0)), b = m.V.row(m.T(t, 1)), c = m.V.row(m.T(t, 2)),
                            d = m.V.row(m.T(t, 3));
      const double v = std::abs((b - a).dot((c - a).cross(d - a))) / 6;
      total += v, span += bottom && top ? v : 0;
    }
    EXPECT_NEAR(total, 400, 1e-6 * 400);
    spanning[k] = span / total;
  }
  EXPECT_GT(spanning[0], 0.8);
  EXPECT_LT(spanning[1], 0.02);
  EXPECT_LT(deflection[0], 0.35 * beam);
  EXPECT_GT(deflection[1], 2 * deflection[0]);
  EXPECT_LT(deflection[1], beam);
}

TEST(TwoBRepSteps, ExamplesMeshIntoOneConformalTaggedMesh) {
  for (auto [name, factor] : {std::pair<const char*, double>{"rocker", 1.0},
                              {"rocker", 0.5},
                              {"cantilever", 1.0},
                              {"cantilever", 0.6},
                              {"bracket", 1.0},
                              {"bracket", 0.75}}) {
    SCOPED_TRACE(std::string(name) + " at " + std::to_string(factor) + " x the default size");
    const brep::TwoBReps model = load(name, true);
    const TetMesh m = mesh_at(model, factor);
    const ConformityReport c = check_conformity(m, &model);
    // duplicates, over-shared faces, boundary = surface mesh, interface on Ω̄, volumes
    EXPECT_TRUE(c.ok()) << c.to_json().dump();
    EXPECT_EQ(c.duplicate_nodes, 0);
    EXPECT_EQ(c.interface_off_nondesign, 0);
    EXPECT_GT(c.interface_sampled, 0);
    ASSERT_EQ(c.domain_volume.size(), static_cast<size_t>(model.nondesign.num_solids() + 1));
    for (size_t d = 0; d < c.domain_volume.size(); ++d) {
      ASSERT_LT(d, c.expected_volume.size());
      EXPECT_NEAR(c.domain_volume[d], c.expected_volume[d], 0.005 * c.expected_volume[d]) << "domain " << d;
    }
    const QualityReport q = tet_quality(m);
    EXPECT_GT(q.min_radius_ratio, 0.1);
    EXPECT_GT(q.mean_radius_ratio, 0.7);
    // every boundary triangle carries one of Ω's faces
    EXPECT_GE(m.face.minCoeff(), 1);
    EXPECT_LE(m.face.maxCoeff(), model.part.num_faces());
  }
}

TEST(TwoBRepSteps, TouchingClampPadsAreConformalAcrossTheirSharedFace) {
  // bracket: pads 6 and 7 (domains 6, 7) share the square x = 52, 0 <= y, z <= 10
  const brep::TwoBReps model = load("bracket", true);
  ASSERT_EQ(model.relations.contacts.size(), 1u);
  const TetMesh m = mesh_at(model, 1.0);
  std::map<std::array<int, 3>, std::vector<int>> owners;  // face on the plane -> domains of its tets
  static const int kF[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  for (long t = 0; t < m.T.rows(); ++t)
    for (const auto& f : kF) {
      std::array<int, 3> k{m.T(t, f[0]), m.T(t, f[1]), m.T(t, f[2])};
      bool on = true;
      for (int v : k) on &= std::abs(m.V(v, 0) - 52) < 1e-9;
      if (!on) continue;
      std::sort(k.begin(), k.end());
      owners[k].push_back(m.domain[t]);
    }
  double shared_area = 0;
  for (const auto& [k, doms] : owners) {
    double ymax = 0, zmax = 0;
    for (int v : k) ymax = std::max(ymax, m.V(v, 1)), zmax = std::max(zmax, m.V(v, 2));
    if (ymax > 10 + 1e-9 || zmax > 10 + 1e-9) continue;  // the plane x = 52 elsewhere
    // inside the square: one tet of each pad, nothing else
    ASSERT_EQ(doms.size(), 2u);
    EXPECT_EQ(std::min(doms[0], doms[1]), 6);
    EXPECT_EQ(std::max(doms[0], doms[1]), 7);
    shared_area += triangle_area(m, k[0], k[1], k[2]);
  }
  EXPECT_NEAR(shared_area, 100.0, 1e-9);
}

TEST(TwoBRepSteps, LoadPadFaceIsTaggedOnThePartBoundary) {
  // cantilever: the pad's top face (Face12 of Ω̄, 4 x 6 mm) lies on Ω's top face (Face6)
  const brep::TwoBReps model = load("cantilever", true);
  const TetMesh m = mesh_at(model, 1.0);
  ASSERT_EQ(m.nd_face.size(), m.F.rows());
  double area = 0;
  for (long t = 0; t < m.F.rows(); ++t)
    if (m.nd_face[t] == 12) {
      EXPECT_EQ(m.face[t], 6);
      area += triangle_area(m, m.F(t, 0), m.F(t, 1), m.F(t, 2));
    }
  EXPECT_NEAR(area, 24.0, 1e-9);
}

TEST(NativeMesher, RefusesParamsWithoutSizes) {
  // the sizes are decided by pipeline::MeshSettings, never by the mesher
  const brep::TwoBReps model = load("cantilever");
  expect_error([&] { mesh_native(model, NativeMeshParams{}); }, ErrorCode::Internal, {"sizes"});
}

}  // namespace
}  // namespace topopt::mesh
