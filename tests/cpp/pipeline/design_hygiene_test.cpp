// Design hygiene on hand-made density fields of a structured box: a loose piece is removed
// and its volume given, a non-design solid apart from the supports is named and kept, closed
// voids are filled (or kept when allowed) while open ones stay, the thinnest member is
// measured, and the result surface of a job warns the same way at any threshold; a piece of
// the result shape the crisp tets do not see (a node at the threshold whose tets all average
// below it: the lever example's crumb) goes too, and the finished surface is checked by the
// same rule (a design piece apart goes, a non-design one stays, named).
#include "result/design_hygiene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>

#include "mesh/core/structured_box.h"
#include "pipeline/optimize_job.h"
#include "result/iso_surface.h"
#include "result/step_export.h"

namespace topopt::result {
namespace {

/// A 10 mm cube of 1 mm cells (6000 tets), non-design boxes as given.
TetMesh cube(std::vector<std::array<double, 6>> nondesign = {}, int cells = 10) {
  mesh::StructuredBoxParams p;
  p.size = {10, 10, 10};
  p.cells = {cells, cells, cells};
  p.nondesign = std::move(nondesign);
  return mesh::structured_box_mesh(p);
}

Eigen::Vector3d centre(const TetMesh& m, long t) {
  return 0.25 * (m.V.row(m.T(t, 0)) + m.V.row(m.T(t, 1)) + m.V.row(m.T(t, 2)) + m.V.row(m.T(t, 3))).transpose();
}

bool inside(const Eigen::Vector3d& c, std::array<double, 6> b) {
  return c[0] > b[0] && c[1] > b[1] && c[2] > b[2] && c[0] < b[3] && c[1] < b[4] && c[2] < b[5];
}

/// Density 1 in the boxes, 0 elsewhere (non-design tets 1).
VecXd densities(const TetMesh& m, const std::vector<std::array<double, 6>>& solid) {
  VecXd d = VecXd::Zero(m.T.rows());
  for (long t = 0; t < m.T.rows(); ++t) {
    if (m.domain[t] != 0) d[t] = 1;
    for (const auto& b : solid)
      if (inside(centre(m, t), b)) d[t] = 1;
  }
  return d;
}

/// Nodes on the plane x = 0.
std::vector<char> anchors_at_x0(const TetMesh& m) {
  std::vector<char> a(m.V.rows(), 0);
  for (long v = 0; v < m.V.rows(); ++v) a[v] = m.V(v, 0) < 1e-9;
  return a;
}

TEST(DesignHygiene, NeighboursAreSymmetricAndTheBoundaryIsTheBoxSurface) {
  const TetMesh m = cube({}, 4);
  const MatX4i nb = tet_neighbours(m.T);
  long boundary = 0;
  for (long t = 0; t < m.T.rows(); ++t)
    for (int k = 0; k < 4; ++k) {
      const int n = nb(t, k);
      if (n < 0) {
        ++boundary;
        continue;
      }
      EXPECT_TRUE((nb.row(n).array() == t).any()) << t << " and " << n;
    }
  EXPECT_EQ(boundary, 6 * 4 * 4 * 2);  // two triangles per boundary square
}

TEST(DesignHygiene, ALoosePieceIsRemovedWithItsVolumeAndTheRestIsOnePiece) {
  const TetMesh m = cube();
  // a slab on the supported face x = 0, and a 2 x 4 x 4 mm block floating in the void
  const VecXd d = densities(m, {{0, 0, 0, 3, 10, 10}, {6, 3, 3, 8, 7, 7}});
  HygieneReport rep;
  const VecXd clean = clean_design(m, d, 0.5, anchors_at_x0(m), {}, rep);
  EXPECT_EQ(rep.pieces, 2);
  EXPECT_EQ(rep.anchored_pieces, 1);
  ASSERT_EQ(rep.apart.size(), 1u);
  EXPECT_TRUE(rep.apart[0].removed);
  EXPECT_TRUE(rep.apart[0].nondesign.empty());
  // the crisp block: tets whose node densities average 0.5 or more, about its 32 mm³
  EXPECT_GT(rep.apart[0].volume, 16);
  EXPECT_LT(rep.apart[0].volume, 64);
  ASSERT_EQ(rep.warnings.size(), 1u);
  EXPECT_NE(rep.warnings[0].find("removed a loose piece"), std::string::npos) << rep.warnings[0];
  EXPECT_NE(rep.warnings[0].find("mm³"), std::string::npos) << rep.warnings[0];
  for (long t = 0; t < m.T.rows(); ++t) {
    if (inside(centre(m, t), {6, 3, 3, 8, 7, 7})) {
      EXPECT_EQ(clean[t], 0) << t;
    }
    if (inside(centre(m, t), {0, 0, 0, 3, 10, 10})) {
      EXPECT_EQ(clean[t], 1) << t;
    }
  }
  // cleaned once, clean for good
  HygieneReport again;
  clean_design(m, clean, 0.5, anchors_at_x0(m), {}, again);
  EXPECT_EQ(again.pieces, 1);
  EXPECT_TRUE(again.warnings.empty());
}

/// The hygiene with result.join_non_design off: non-design solids apart stay apart, named.
HygieneParams apart_kept() {
  HygieneParams h;
  h.join_non_design = false;
  return h;
}

TEST(DesignHygiene, ANonDesignSolidApartFromTheSupportsIsNamedAndKept) {
  // non-design solids 1 at x = 0 (supported) and 2 at x = 10, the design between them empty
  // (join_non_design off; join_bridges_test has it on)
  const TetMesh m = cube({{0, 0, 0, 2, 10, 10}, {8, 0, 0, 10, 10, 10}});
  const VecXd d = densities(m, {});
  HygieneReport rep;
  const VecXd clean = clean_design(m, d, 0.5, anchors_at_x0(m), apart_kept(), rep);
  ASSERT_EQ(rep.apart.size(), 1u);
  EXPECT_FALSE(rep.apart[0].removed);
  EXPECT_EQ(rep.apart[0].nondesign, std::vector<int>{2});
  EXPECT_NEAR(rep.apart[0].volume, 200, 1e-9);
  ASSERT_EQ(rep.warnings.size(), 1u);
  EXPECT_NE(rep.warnings[0].find("non-design solid 2 is not connected"), std::string::npos) << rep.warnings[0];
  EXPECT_NE(rep.warnings[0].find("touches no support and no load"), std::string::npos) << rep.warnings[0];
  EXPECT_EQ(clean, d);
  // the support at x = 0 and the load at x = 10: the load does not reach the support
  std::vector<char> both = anchors_at_x0(m);
  for (long v = 0; v < m.V.rows(); ++v)
    if (m.V(v, 0) > 10 - 1e-9) both[v] = kAnchorLoad;
  clean_design(m, d, 0.5, both, apart_kept(), rep);
  EXPECT_EQ(rep.anchored_pieces, 2);
  ASSERT_EQ(rep.warnings.size(), 1u);
  EXPECT_NE(rep.warnings[0].find("falls apart into 2 pieces"), std::string::npos) << rep.warnings[0];
  EXPECT_NE(rep.warnings[0].find("non-design solid 1; non-design solid 2"), std::string::npos) << rep.warnings[0];
}

TEST(DesignHygiene, APieceWithASupportButNoLoadIsApartFromTheOneCarryingTheLoad) {
  // non-design solids 1 (supported, x = 0) and 2 (supported, x = 10); the load on solid 1's
  // top; the design connects nothing, so solid 2 holds a support that carries nothing
  const TetMesh m = cube({{0, 0, 0, 2, 10, 10}, {8, 0, 0, 10, 10, 10}});
  std::vector<char> anchors(m.V.rows(), 0);
  for (long v = 0; v < m.V.rows(); ++v) {
    if (m.V(v, 0) < 1e-9 || m.V(v, 0) > 10 - 1e-9) anchors[v] = kAnchorSupport;
    if (m.V(v, 2) > 10 - 1e-9 && m.V(v, 0) < 2 + 1e-9) anchors[v] |= kAnchorLoad;
  }
  HygieneReport rep;
  clean_design(m, densities(m, {}), 0.5, anchors, apart_kept(), rep);
  EXPECT_EQ(rep.anchored_pieces, 1);
  ASSERT_EQ(rep.apart.size(), 1u);
  EXPECT_EQ(rep.apart[0].nondesign, std::vector<int>{2});
  ASSERT_EQ(rep.warnings.size(), 1u);
  EXPECT_NE(rep.warnings[0].find("holds a support but no load"), std::string::npos) << rep.warnings[0];
}

TEST(DesignHygiene, ClosedVoidsAreFilledUnlessAllowedAndOpenOnesStay) {
  const TetMesh m = cube();
  VecXd d = VecXd::Ones(m.T.rows());
  for (long t = 0; t < m.T.rows(); ++t) {
    const Eigen::Vector3d c = centre(m, t);
    if (inside(c, {3, 3, 3, 7, 7, 7})) d[t] = 0;   // closed cavity, 64 mm³
    if (inside(c, {0, 0, 8, 2, 2, 10})) d[t] = 0;  // notch open at a corner
  }
  HygieneReport rep;
  const VecXd clean = clean_design(m, d, 0.5, anchors_at_x0(m), {}, rep);
  EXPECT_EQ(rep.pieces, 1);
  EXPECT_EQ(rep.voids_filled, 1);
  EXPECT_GT(rep.void_volume_filled, 20);
  EXPECT_LT(rep.void_volume_filled, 64);
  for (long t = 0; t < m.T.rows(); ++t) {
    if (inside(centre(m, t), {3, 3, 3, 7, 7, 7})) {
      EXPECT_EQ(clean[t], 1);
    }
    if (inside(centre(m, t), {0, 0, 8, 2, 2, 10})) {
      EXPECT_EQ(clean[t], 0);
    }
  }
  ASSERT_EQ(rep.warnings.size(), 1u);
  EXPECT_NE(rep.warnings[0].find("filled 1 closed internal void"), std::string::npos) << rep.warnings[0];
  // allowed: the cavity stays, and the report says so
  HygieneParams keep;
  keep.fill_voids = false;
  EXPECT_EQ(clean_design(m, d, 0.5, anchors_at_x0(m), keep, rep), d);
  EXPECT_EQ(rep.voids_filled, 0);
  EXPECT_EQ(rep.voids_kept, 1);
  EXPECT_NEAR(rep.void_volume_kept, 0, 64);
  EXPECT_GT(rep.void_volume_kept, 20);
}

/// A grey, holed field: solid with random spherical holes, and noise, clamped to [0, 1].
VecXd lumpy(const TetMesh& m, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<std::pair<Eigen::Vector3d, double>> blobs(30);
  for (auto& [c, r] : blobs) c = Eigen::Vector3d(10 * u(rng), 10 * u(rng), 10 * u(rng)), r = 1 + 2 * u(rng);
  VecXd d(m.T.rows());
  for (long t = 0; t < m.T.rows(); ++t) {
    const Eigen::Vector3d x = centre(m, t);
    double v = 1;
    for (const auto& [c, r] : blobs) v = std::min(v, (x - c).norm() / r);
    d[t] = std::clamp(v + 0.6 * (u(rng) - 0.5), 0.0, 1.0);
  }
  return d;
}

TEST(DesignHygiene, CleaningTheCleanedDesignFindsNothing) {
  // taking a piece out lowers the node densities around it and filling a void raises them, so
  // one pass can leave a piece or a void in the crisp design of its own output: the design
  // handed over must be clean by the same test (the pipeline's CrispExamples re-clean it)
  const TetMesh m = cube();
  int cleaned_something = 0;
  for (unsigned seed = 0; seed < 60; ++seed) {
    const double threshold = 0.3 + 0.1 * (seed % 5);
    SCOPED_TRACE("seed " + std::to_string(seed));
    const VecXd d = lumpy(m, seed);
    HygieneReport first, again;
    const VecXd clean = clean_design(m, d, threshold, anchors_at_x0(m), {}, first);
    cleaned_something += first.voids_filled > 0 || !first.apart.empty();
    const VecXd twice = clean_design(m, clean, threshold, anchors_at_x0(m), {}, again);
    EXPECT_EQ(again.voids_filled, 0);
    for (const DesignPiece& piece : again.apart) EXPECT_FALSE(piece.removed) << piece.volume << " mm³ removed again";
    EXPECT_EQ(twice, clean);
  }
  EXPECT_GE(cleaned_something, 10) << "the fields must give the cleaning work";
}

TEST(DesignHygiene, TheThinnestMemberIsMeasuredToAboutAnElementSize) {
  // 0.5 mm cells: a 6 mm thick slab on x = 0 carrying a 2 mm plate across the cube
  const TetMesh m = cube({}, 20);
  const VecXd d = densities(m, {{0, 0, 0, 6, 10, 10}, {0, 0, 4, 10, 10, 6}});
  HygieneReport rep;
  clean_design(m, d, 0.5, anchors_at_x0(m), {}, rep);
  EXPECT_GT(rep.min_feature, 2 - 0.75) << rep.min_feature_at[0] << " " << rep.min_feature_at[1] << " "
                                       << rep.min_feature_at[2];
  EXPECT_LT(rep.min_feature, 2 + 0.75);
  EXPECT_GT(rep.min_feature_at[0], 6 - 0.5) << "in the plate, not the slab";
  EXPECT_NEAR(rep.min_feature_at[2], 5, 1);
  // a thicker plate measures thicker
  HygieneReport thick;
  clean_design(m, densities(m, {{0, 0, 0, 6, 10, 10}, {0, 0, 3, 10, 10, 7}}), 0.5, anchors_at_x0(m), {}, thick);
  EXPECT_GT(thick.min_feature, rep.min_feature + 1);
}

TEST(DesignHygiene, TheResultSurfaceWarnsAtEveryThreshold) {
  // the job's path and a re-extraction from densities alone (the workbench's slider): the
  // loose block goes and is warned about either way, and the surface has one piece
  const TetMesh m = cube();
  const VecXd d = densities(m, {{0, 0, 0, 3, 10, 10}, {6, 3, 3, 8, 7, 7}});
  for (const double threshold : {0.5, 0.7}) {
    for (const bool with_anchors : {true, false}) {
      std::vector<std::string> warnings;
      Progress progress;
      progress.log = [&](LogLevel level, const std::string& w) {
        if (level == LogLevel::Warning) warnings.push_back(w);
      };
      HygieneReport rep;
      VecXd design;
      const TriSurface s =
          pipeline::result_surface(m, d, threshold, 0.3, SmoothParams{}, nullptr,
                                   with_anchors ? anchors_at_x0(m) : std::vector<char>{}, {}, &rep, &design, progress);
      ASSERT_EQ(warnings.size(), 1u) << threshold;
      EXPECT_NE(warnings[0].find("removed a loose piece"), std::string::npos) << warnings[0];
      EXPECT_EQ(check_surface(s.V, s.F).open_edges, 0);
      // the surface encloses the slab only (30 mm³ x 10, less what smoothing rounds off)
      EXPECT_NEAR(check_surface(s.V, s.F).volume, 300, 40) << threshold;
    }
  }
}

/// The pieces of a triangle surface (triangles sharing points), counted here by union-find.
int surface_pieces(const TriSurface& s) {
  std::vector<int> parent(s.V.rows());
  std::iota(parent.begin(), parent.end(), 0);
  const auto find = [&](int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (long q = 0; q < s.F.rows(); ++q)
    for (int k = 1; k < 3; ++k) parent[find(s.F(q, 0))] = find(s.F(q, k));
  std::vector<char> root(s.V.rows(), 0);
  for (long q = 0; q < s.F.rows(); ++q) root[find(s.F(q, 0))] = 1;
  return static_cast<int>(std::count(root.begin(), root.end(), 1));
}

/// The node of m nearest to x.
int nearest_node(const TetMesh& m, const Eigen::Vector3d& x) {
  Eigen::Index best = 0;
  (m.V.rowwise() - x.transpose()).rowwise().squaredNorm().minCoeff(&best);
  return static_cast<int>(best);
}

TEST(DesignHygiene, ANodeAtTheThresholdWhoseTetsAllAverageBelowItLeavesNoCrumb) {
  // the lever example's crumb (issue 19): every tet around one node in the void has density
  // 1, so that node's density is 1 while its neighbours', shared with void tets, stay low and
  // every tet around it averages below the threshold: no crisp tet there, but the iso-surface,
  // cut from the node densities, wraps the node in a closed blob apart from the slab
  const TetMesh m = cube();
  VecXd d = densities(m, {{0, 0, 0, 3, 10, 10}});
  const int n = nearest_node(m, {7, 5, 5});
  for (long t = 0; t < m.T.rows(); ++t)
    if ((m.T.row(t).array() == n).any()) d[t] = 1;
  const VecXd nd = node_densities(m, d);
  ASSERT_GE(nd[n], 0.5);
  for (long t = 0; t < m.T.rows(); ++t)
    if ((m.T.row(t).array() == n).any()) {
      ASSERT_LT(0.25 * (nd[m.T(t, 0)] + nd[m.T(t, 1)] + nd[m.T(t, 2)] + nd[m.T(t, 3)]), 0.5);
    }
  // the premise holds: the crisp tets make one piece, the result shape two
  int crisp_count = 0, level_count = 0;
  node_components(m, crisp_tets(m, nd, 0.5), crisp_count);
  level_components(m, nd, 0.5, level_count);
  EXPECT_EQ(crisp_count, 1);
  EXPECT_EQ(level_count, 2);
  for (const bool with_anchors : {true, false}) {
    SCOPED_TRACE(with_anchors ? "anchors at x = 0" : "no anchors");
    std::vector<std::string> warnings;
    Progress progress;
    progress.log = [&](LogLevel level, const std::string& w) {
      if (level == LogLevel::Warning) warnings.push_back(w);
    };
    HygieneReport rep;
    const TriSurface s =
        pipeline::result_surface(m, d, 0.5, 0.3, SmoothParams{}, nullptr,
                                 with_anchors ? anchors_at_x0(m) : std::vector<char>{}, {}, &rep, nullptr, progress);
    EXPECT_EQ(surface_pieces(s), 1);
    EXPECT_EQ(result_bodies(s), 1);
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_NE(warnings[0].find("removed a loose piece"), std::string::npos) << warnings[0];
    EXPECT_NE(warnings[0].find("mm³"), std::string::npos) << warnings[0];
    EXPECT_NEAR(check_surface(s.V, s.F).volume, 300, 40);
  }
}

TEST(DesignHygiene, ANodeBelowTheThresholdWhoseTetsAllAverageAboveItLeavesNoCavity) {
  // the crumb's twin (the mount at 5 mm had one, -0.88 mm³): every tet around one node inside
  // the solid cube is void, so that node's density is 0 while every tet around it averages
  // above the threshold: no void tet for the crisp design, but the iso-surface wraps the node
  // in a closed cavity
  const TetMesh m = cube();
  VecXd d = VecXd::Ones(m.T.rows());
  const int n = nearest_node(m, {5, 5, 5});
  for (long t = 0; t < m.T.rows(); ++t)
    if ((m.T.row(t).array() == n).any()) d[t] = 0;
  const VecXd nd = node_densities(m, d);
  ASSERT_LT(nd[n], 0.5);
  for (long t = 0; t < m.T.rows(); ++t)
    if ((m.T.row(t).array() == n).any()) {
      ASSERT_GE(0.25 * (nd[m.T(t, 0)] + nd[m.T(t, 1)] + nd[m.T(t, 2)] + nd[m.T(t, 3)]), 0.5);
    }
  for (const bool fill : {true, false}) {
    SCOPED_TRACE(fill ? "voids filled" : "voids allowed");
    HygieneParams params;
    params.fill_voids = fill;
    HygieneReport rep;
    const TriSurface s =
        pipeline::result_surface(m, d, 0.5, 0.3, SmoothParams{}, nullptr, anchors_at_x0(m), params, &rep, nullptr, {});
    EXPECT_EQ(result_bodies(s), 1);
    // filled: one closed surface, the cube's; allowed: the cavity's shell inside it as well
    EXPECT_EQ(surface_pieces(s), fill ? 1 : 2);
    EXPECT_EQ(rep.voids_filled, fill ? 1 : 0);
    EXPECT_EQ(rep.voids_kept, fill ? 0 : 1);
    const double cavity = fill ? rep.void_volume_filled : rep.void_volume_kept;
    EXPECT_GT(cavity, 0);
    EXPECT_LT(cavity, 4);  // within the node's 24 tets of 1/6 mm³
    EXPECT_NEAR(check_surface(s.V, s.F).volume, 1000 - (fill ? 0 : cavity), fill ? 1e-6 : 0.5 + cavity);
  }
}

TEST(DesignHygiene, TheFinishedSurfaceLosesADesignPieceApartAndKeepsANonDesignOneNamed) {
  // cut with no cleaning: a slab on the supported and loaded face x = 0 (Face1), a 2 x 4 x 4
  // mm block floating in the void, and non-design solid 1 at the far end (x = 8 .. 10) apart
  const TetMesh m = cube({{8, 0, 0, 10, 10, 10}});
  const VecXd d = densities(m, {{0, 0, 0, 3, 10, 10}, {5, 3, 3, 7, 7, 7}});
  TriSurface s = extract_iso_surface(m, node_densities(m, d), 0.5, 0.2);
  ASSERT_EQ(surface_pieces(s), 3);
  const double before = check_surface(s.V, s.F).volume;
  std::vector<char> face_anchors(7, 0);
  face_anchors[1] = kAnchorSupport | kAnchorLoad;
  HygieneReport rep;
  const int added = clean_surface_pieces(s, face_anchors, rep);
  EXPECT_EQ(surface_pieces(s), 2);
  EXPECT_EQ(check_surface(s.V, s.F).open_edges, 0);
  ASSERT_EQ(added, 2);
  ASSERT_EQ(rep.apart.size(), 2u);
  // the block: removed, its volume the surface's (2 x 4 x 4 mm, the level between cells)
  EXPECT_TRUE(rep.apart[0].removed);
  EXPECT_GT(rep.apart[0].volume, 16);
  EXPECT_LT(rep.apart[0].volume, 64);
  EXPECT_NEAR(check_surface(s.V, s.F).volume, before - rep.apart[0].volume, 1e-6 * before);
  // solid 1: kept and named, with its 200 mm³
  EXPECT_FALSE(rep.apart[1].removed);
  EXPECT_EQ(rep.apart[1].nondesign, std::vector<int>{1});
  EXPECT_NEAR(rep.apart[1].volume, 200, 1e-6);
  const std::vector<std::string> added_warnings(rep.warnings.end() - added, rep.warnings.end());
  EXPECT_NE(added_warnings[0].find("removed a loose piece of the result surface"), std::string::npos)
      << added_warnings[0];
  EXPECT_NE(added_warnings[0].find("mm³"), std::string::npos) << added_warnings[0];
  EXPECT_NE(added_warnings[1].find("non-design solid 1 is not connected"), std::string::npos) << added_warnings[1];
  // checked again: nothing more to do; and a report that names solid 1 already gets no second name
  EXPECT_EQ(clean_surface_pieces(s, face_anchors, rep), 0);
  EXPECT_EQ(surface_pieces(s), 2);
}

}  // namespace
}  // namespace topopt::result
