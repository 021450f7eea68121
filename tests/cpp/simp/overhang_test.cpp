// The overhang control (src/simp/controls/overhang_filter, lattice_transfer, overhang_measure):
// the printed field keeps what is supported and drops what is not, the lattice transfer works
// on a lattice turned against the mesh, non-design solids and a picked base face support, bad
// settings are named, the chain rule against finite differences, and the property on an
// optimised beam: less of its downward-facing surface is flatter than the critical angle
// with the control than without, the issue's ≤ 1 % on the result surface the user gets (its last
// pass lifting the facets the surface stage tilted: result/overhang_lift.h) and on the crisp
// iso-surface of the design; printed upright, the pad's downward face carried, not bared.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <iostream>
#include <random>

#include "common/error.h"
#include "fem/boundary_conditions.h"
#include "mesh/core/structured_box.h"
#include "pipeline/optimize_job.h"
#include "result/design_hygiene.h"
#include "result/iso_surface.h"
#include "simp/controls/column_grid.h"
#include "simp/controls/design_map.h"
#include "simp/controls/lattice_transfer.h"
#include "simp/controls/overhang_filter.h"
#include "simp/controls/overhang_measure.h"
#include "simp/density_filter.h"
#include "simp/optimizer.h"

namespace topopt::simp {
namespace {

/// A structured box mesh of `cells` cubes of 1 mm from the origin, with optional non-design boxes.
TetMesh box_mesh(std::array<int, 3> cells, std::vector<std::array<double, 6>> nondesign = {}) {
  mesh::StructuredBoxParams p;
  p.size = {double(cells[0]), double(cells[1]), double(cells[2])};
  p.cells = cells;
  p.nondesign = std::move(nondesign);
  return mesh::structured_box_mesh(p);
}

std::vector<int> design_of(const TetMesh& m) {
  std::vector<int> d;
  for (long t = 0; t < m.T.rows(); ++t)
    if (m.domain[t] == 0) d.push_back(static_cast<int>(t));
  return d;
}

/// The design field (#D) that is 1 where inside(centroid), else 0.
template <class Inside>
VecXd field(const TetMesh& m, const std::vector<int>& design, Inside inside) {
  const Eigen::MatrixX3d c = design_centroids(m, design);
  VecXd r(c.rows());
  for (long i = 0; i < c.rows(); ++i) r[i] = inside(Eigen::Vector3d(c.row(i))) ? 1.0 : 0.0;
  return r;
}

/// The control without a margin: the filter prints for `angle` itself (the stencil's tests).
OverhangControl control(Eigen::Vector3d d = Eigen::Vector3d::UnitZ(), double angle = 45) {
  OverhangControl c;
  c.enabled = true;
  c.direction = d;
  c.angle = angle;
  c.margin = 0;
  return c;
}

/// The property test's settings and bounds: the target, <= 1 % with the control, on the
/// result surface the user gets, every triangle of it counted (the pad's faces too, none of which
/// faces down on this beam), no tolerance, β at its end, the default margin of 20°. The surface
/// stage lifts its downward facets back above the angle when the job prints along a direction
/// (result/overhang_lift.h): 0.19 % on the surface of 2026-12-03 (2.10 % without that last pass:
/// the crossing margin and the smoothing tilt facets of the lattice's staircase next to the pad and
/// under the beam's middle below 45°), 34.6 % free (docs/optimization.md, "Overhang").
constexpr int kBeamIterations = 200;
constexpr double kBeamMargin = 20;
constexpr double kBeamShareBound = 0.01;
/// The same 1 %, met by the design the filter makes before the surface stage: the crisp
/// iso-surface at the volume's threshold (marching tetrahedra, hygiene, no remeshing or
/// smoothing), every facet, no tolerance: 0.81 %.
constexpr double kBeamCrispShareBound = 0.01;
/// The last pass restores slopes; it cannot print a design that does not: the free design's
/// surface through the same stage keeps 25.4 % (34.6 % without the pass).
constexpr double kFreeLiftedShareAtLeast = 0.2;

TEST(Overhang, SmoothMinAndMaxBoundTheExactOnes) {
  double da, db, dx[5];
  EXPECT_NEAR(smooth_min(0.3, 0.3, 1e-4, &da, &db), 0.3, 1e-15);
  EXPECT_NEAR(smooth_min(0, 0, 1e-4, &da, &db), 0, 1e-15);
  const double m = smooth_min(0.2, 0.9, 1e-4, &da, &db);
  EXPECT_GE(m, 0.2);
  EXPECT_LE(m, 0.2 + 0.005);
  const double p = 40, q = p + std::log(5.0) / std::log(0.5);
  const double half[5] = {0.5, 0.5, 0.5, 0.5, 0.5};
  EXPECT_NEAR(smooth_support(half, 5, p, q, dx), 0.5, 1e-12);  // ξ₀ exactly (Langelaar 2017)
  const double one_of[5] = {0, 0, 0.8, 0, 0};
  EXPECT_NEAR(smooth_support(one_of, 5, p, q, dx), std::pow(0.8, p / q), 1e-12);
  EXPECT_GT(smooth_support(one_of, 5, p, q, dx), 0.78);  // one support carries nearly its value
  const double none[5] = {0, 0, 0, 0, 0};
  EXPECT_EQ(smooth_support(none, 5, p, q, dx), 0.0);
  EXPECT_EQ(dx[0], 0.0);
}

TEST(Overhang, LatticeTransferKeepsAConstantOnATurnedLattice) {
  // a lattice turned against the 1 mm mesh, finer, equal and coarser than its cells: every
  // element reaches the lattice, a constant comes back exactly and a linear field to within a
  // lattice cell; the centroid map of the column grid leaves cells inside the part empty on the
  // fine lattice (the holes the draw direction met on a turned grid)
  const TetMesh m = box_mesh({8, 6, 5});
  const std::vector<int> design = design_of(m);
  const VecXd vol = tet_volumes(m);
  VecXd vd(design.size());
  for (size_t i = 0; i < design.size(); ++i) vd[i] = vol[design[i]];
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.5, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::MatrixX3d c = design_centroids(m, design);
  Eigen::MatrixX3d local = c * turn.transpose();
  const Eigen::RowVector3d lo = (m.V * turn.transpose()).colwise().minCoeff();
  local.rowwise() -= lo;
  const std::vector<int> variable = [&] {
    std::vector<int> v(design.size());
    for (size_t i = 0; i < v.size(); ++i) v[i] = static_cast<int>(i);
    return v;
  }();
  for (double h : {0.45, 1.0, 2.5}) {
    const Eigen::Vector3d spacing(h, h, 0.8 * h);
    std::array<int, 3> n;
    for (int a = 0; a < 3; ++a) n[a] = static_cast<int>(local.col(a).maxCoeff() / spacing[a]) + 2;
    const LatticeTransfer t(local, vd, variable, static_cast<int>(design.size()), spacing, n);
    const VecXd ones = VecXd::Ones(design.size());
    EXPECT_NEAR((t.to_elements(t.to_grid(ones)) - ones).cwiseAbs().maxCoeff(), 0, 1e-12) << "cell " << h;
    VecXd active(t.num_nodes());
    for (long q = 0; q < t.num_nodes(); ++q) active[q] = t.active()[q];
    EXPECT_GT(t.to_grid_transpose(active).minCoeff(), 0) << "an element does not reach the lattice, cell " << h;
    const VecXd x = c.col(0);  // a linear field: back to within the cell's diagonal
    EXPECT_LE((t.to_elements(t.to_grid(x)) - x).cwiseAbs().maxCoeff(), 1.8 * h + 1) << "cell " << h;
  }
  const ColumnGrid centroid_map(c, vd, turn.row(2).transpose(), 0.45);
  long empty_inside = 0;
  for (long col = 0; col < centroid_map.num_columns(); ++col) {
    int first = -1, last = -1;
    for (int k = 0; k < centroid_map.num_layers(); ++k)
      if (centroid_map.occupied()[col * centroid_map.num_layers() + k]) last = k, first = first < 0 ? k : first;
    for (int k = first + 1; k < last; ++k)
      empty_inside += !centroid_map.occupied()[col * centroid_map.num_layers() + k];
  }
  EXPECT_GT(empty_inside, 0) << "the centroid map should leave holes in its columns on this lattice";
}

TEST(Overhang, PrintsWhatIsSupportedAndDropsWhatIsNot) {
  // 12 × 4 × 10 mm, 1 mm cells, built along +z from z = 0, lattice of 1 mm (45°: layers 1 mm)
  const TetMesh m = box_mesh({12, 4, 10});
  const std::vector<int> design = design_of(m);
  const Eigen::MatrixX3d c = design_centroids(m, design);
  const OverhangFilter f(m, design, control(), 1.0);
  EXPECT_NEAR(f.plate_height(), 0, 1e-12);
  // a block floating 4 mm above the plate: not printable, dropped
  const VecXd floating = field(m, design, [](const Eigen::Vector3d& p) { return p.z() > 4 && p.z() < 8; });
  EXPECT_LE(f.apply(floating).maxCoeff(), 0.05);
  // a wall leaning out at 45°, x < 3 + z: printable, kept (but within a cell of its slope)
  const VecXd lean45 = field(m, design, [](const Eigen::Vector3d& p) { return p.x() < 3 + p.z(); });
  const VecXd printed45 = f.apply(lean45);
  // a shelf leaning out at 63° from the vertical, x < 3 + 2z: cut back to the 45° cone
  const VecXd lean63 = field(m, design, [](const Eigen::Vector3d& p) { return p.x() < 3 + 2 * p.z(); });
  const VecXd printed63 = f.apply(lean63);
  double kept45 = 0, in45 = 0, cut63 = 0, beyond = 0;
  for (long i = 0; i < c.rows(); ++i) {
    const double x = c(i, 0), z = c(i, 2);
    if (x < 3 + z - 1.5) kept45 += printed45[i] > 0.9, ++in45;  // a cell inside the slope
    if (x > 3 + z + 1.5 && x < 3 + 2 * z - 0.5) cut63 += printed63[i] < 0.1, ++beyond;
  }
  EXPECT_GE(kept45 / in45, 0.98);
  EXPECT_GE(cut63 / beyond, 0.95);
  // nothing grows: printed <= 1 (+ √ε/2), and 0 more than a cell (the transfer's blur) off the given shape
  EXPECT_LE(printed63.maxCoeff(), 1 + 0.5 * std::sqrt(1e-4));  // smin exceeds min by up to √ε/2
  for (long i = 0; i < c.rows(); ++i)
    if (c(i, 0) > 3 + 2 * c(i, 2) + 1.5) {
      EXPECT_LE(printed63[i], 0.01) << "grown at " << c.row(i);
    }
  // 60° from the plate: layers tan 60° = 1.73 mm, the 45° wall is too flat now and is cut; the
  // same lattice with 45° and a margin of 15°
  OverhangControl with_margin = control();
  with_margin.margin = 15;
  EXPECT_EQ((OverhangFilter(m, design, with_margin, 1.0).apply(lean45) -
             OverhangFilter(m, design, control(Eigen::Vector3d::UnitZ(), 60), 1.0).apply(lean45))
                .cwiseAbs()
                .maxCoeff(),
            0.0);
  const OverhangFilter steep(m, design, control(Eigen::Vector3d::UnitZ(), 60), 1.0);
  const VecXd printed45_at60 = steep.apply(lean45);
  double cut = 0, out = 0;
  for (long i = 0; i < c.rows(); ++i)
    if (c(i, 0) > 3 + c(i, 2) / std::tan(M_PI / 3) + 2 && c(i, 0) < 3 + c(i, 2) - 0.5)
      cut += printed45_at60[i] < 0.1, ++out;
  EXPECT_GT(out, 20);
  EXPECT_GE(cut / out, 0.9);
}

TEST(Overhang, NonDesignSolidsAndThePickedPlateSupport) {
  // a non-design block in the middle carries what sits on it; built downwards (−z) from the
  // top face (Face6 of the box) the floating block hangs from the plate instead
  const TetMesh m = box_mesh({12, 4, 10}, {{{4, 0, 2, 8, 4, 3}}});
  const std::vector<int> design = design_of(m);
  const VecXd on_pad =
      field(m, design, [](const Eigen::Vector3d& p) { return p.z() > 3 && p.z() < 6 && p.x() > 4 && p.x() < 8; });
  const Eigen::MatrixX3d c = design_centroids(m, design);
  const VecXd up = OverhangFilter(m, design, control(), 1.0).apply(on_pad);
  OverhangControl down = control({0, 0, -1});
  down.base_face = 6;
  const OverhangFilter from_top(m, design, down, 1.0);
  EXPECT_NEAR(from_top.plate_height(), -10, 1e-12);
  const VecXd hanging = field(m, design, [](const Eigen::Vector3d& p) { return p.z() > 7; });
  const VecXd hung = from_top.apply(hanging);
  const VecXd floor_only = OverhangFilter(m, design, control(), 1.0).apply(hanging);
  for (long i = 0; i < c.rows(); ++i) {
    if (on_pad[i] > 0 && c(i, 0) > 5 && c(i, 0) < 7 && c(i, 2) < 5) {  // a cell off the pad's free faces
      EXPECT_GE(up[i], 0.9) << "resting on the non-design block at " << c.row(i);
    }
    if (c(i, 2) > 8.2) {  // a cell off the block's free face
      EXPECT_GE(hung[i], 0.9) << "built from the top plate at " << c.row(i);
      EXPECT_LE(floor_only[i], 0.05) << "floating when built from the floor at " << c.row(i);
    }
  }
}

TEST(Overhang, NoShelfHangsFromANonDesignWall) {
  // a non-design wall standing on the plate (x in [8, 12]); a sheet of design half a lattice
  // cell thick along its side (x in (7.5, 8)), 3 mm above the plate with nothing under it: the
  // wall's lattice nodes hold wall and sheet, and printing them as given would keep the sheet
  // (its bottom a ceiling). Only what rests on top of a non-design solid is carried by it: the
  // sheet prints as an empty design does there (the wall's own share, the same at every height)
  const TetMesh m = box_mesh({12, 4, 10}, {{{8, 0, 0, 12, 4, 10}}});
  const std::vector<int> design = design_of(m);
  const VecXd sheet =
      field(m, design, [](const Eigen::Vector3d& p) { return p.x() > 7.5 && p.z() > 3 && p.z() < 6; });
  const OverhangFilter f(m, design, control(), 1.0);
  const VecXd printed = f.apply(sheet), empty = f.apply(VecXd::Zero(sheet.size()));
  const Eigen::MatrixX3d c = design_centroids(m, design);
  long in_sheet = 0;
  for (long i = 0; i < c.rows(); ++i)
    if (sheet[i] > 0) {
      ++in_sheet;
      EXPECT_LE(printed[i], empty[i] + 0.01) << "a shelf on the wall's side kept at " << c.row(i);
    }
  EXPECT_GT(in_sheet, 20);
}

TEST(Overhang, BadSettingsNameWhatToFix) {
  const TetMesh m = box_mesh({4, 4, 4});
  const std::vector<int> design = design_of(m);
  const auto message = [&](const OverhangControl& c) -> std::string {
    try {
      OverhangFilter(m, design, c, 1.0);
    } catch (const Error& e) {
      return std::string(error_code_name(e.code())) + ": " + e.what();
    }
    return "no error";
  };
  EXPECT_NE(message(control({0, 0, 0})).find("controls.overhang.direction"), std::string::npos);
  EXPECT_NE(message(control({0, 0, 1}, 90)).find("controls.overhang.angle must lie in [10, 80]"), std::string::npos);
  OverhangControl c = control();
  c.base_face = 6;  // the top face faces along +z, not against it
  EXPECT_NE(message(c).find("InvalidParameter: controls.overhang.base_face = 6: Face6 is not a flat face facing "
                            "against the build direction"),
            std::string::npos)
      << message(c);
  c.base_face = 9;
  EXPECT_NE(message(c).find("FaceNotFound: controls.overhang.base_face = 9: the part has no Face9 (its faces are "
                            "Face1 … Face6)"),
            std::string::npos)
      << message(c);
  c = control();
  c.exponent = 2;
  EXPECT_NE(message(c).find("controls.overhang.exponent must exceed"), std::string::npos) << message(c);
  c = control({0, 0, 1}, 70);
  c.margin = 20;  // 90 degrees: no slope left
  EXPECT_NE(message(c).find("controls.overhang.margin must lie in [0, 20] degrees with angle + margin <= 85"),
            std::string::npos)
      << message(c);
  c = control();
  c.base_face = 5;
  EXPECT_EQ(message(c), "no error");
}

/// dF/dr of F = w · apply(r) against central differences, at a random r in (0.05, 0.95).
void check_filter_gradient(const OverhangFilter& f, long n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.05, 0.95);
  VecXd r(n), w(n);
  for (long i = 0; i < n; ++i) r[i] = u(rng), w[i] = u(rng) - 0.5;
  const VecXd g = f.apply_transpose(r, w);
  const double h = 1e-6;
  for (long i = 0; i < n; i += std::max<long>(1, n / 25)) {
    VecXd rp = r, rm = r;
    rp[i] += h, rm[i] -= h;
    const double fd = (w.dot(f.apply(rp)) - w.dot(f.apply(rm))) / (2 * h);
    EXPECT_NEAR(g[i], fd, 1e-5 * (std::abs(fd) + 1e-3)) << "element " << i;
  }
}

TEST(Overhang, GradientsMatchFiniteDifferences) {
  const TetMesh m = box_mesh({6, 4, 5});
  const std::vector<int> design = design_of(m);
  check_filter_gradient(OverhangFilter(m, design, control(), 1.0), design.size(), 1);
  check_filter_gradient(OverhangFilter(m, design, control({0.3, -0.2, 1}, 35), 0.8), design.size(), 2);
  OverhangControl c = control({1, 0, 0});
  c.base_face = 1;
  c.margin = 5;
  check_filter_gradient(OverhangFilter(m, design, c, 1.7), design.size(), 3);
}

/// The test beam: a cantilever 30 × 10 × 10 mm (3888 tets) fixed at x = 0, a non-design pad at
/// x = 28 … 30 loaded down (−z) and sideways (−y), printed lying (+z) from z = −5.
struct Beam {
  TetMesh mesh;
  fem::Supports supports;
  Eigen::MatrixXd loads;
  std::vector<char> anchors;  ///< #V: the nodes where supports and loads act (the product's hygiene)
};

Beam test_beam() {
  mesh::StructuredBoxParams box;
  box.origin = {0, -5, -5};
  box.size = {30, 10, 10};
  box.cells = {18, 6, 6};
  box.nondesign = {{28, -5, -5, 30, 5, 5}};
  Beam b;
  b.mesh = mesh::structured_box_mesh(box);
  b.supports = fem::make_supports(b.mesh, {fem::support_on(fem::SupportSpec::Kind::Fixed, {1})});
  fem::LoadSpec pull{fem::LoadSpec::Kind::Force, {2}, {0, -30, -100}, 0, {}};
  b.loads = fem::make_loads(b.mesh, fem::Material{}, {fem::LoadCase{"a", {pull}, 1}});
  b.anchors.assign(b.mesh.V.rows(), 0);
  for (int dof : b.supports.dofs) b.anchors[dof / 3] |= result::kAnchorSupport;
  for (long i = 0; i < b.loads.rows(); ++i)
    if (b.loads(i, 0) != 0) b.anchors[i / 3] |= result::kAnchorLoad;
  return b;
}

/// The overhang share of the result surface the user gets (pipeline::result_surface with the
/// product's defaults: the threshold that keeps the volume fraction, hygiene, smoothing,
/// remeshing, and with `printed` the last pass of a job with an overhang control, which lifts the
/// too-flat downward facets: pipeline::surface_settings), every triangle a design could change
/// (Ω's faces and the pad's too, split by kind: an exposed face of the pad that faces down needs
/// supports as much as the design's own; the part's given faces, a non-design solid's on Ω's
/// boundary, apart — none faces down on this beam), built along +z from z = −5; a facet counts
/// when it rises less than angle − tolerance from the plate. `smooth`: the surface stage's
/// settings (the crisp stage: no remeshing, no smoothing).
OverhangShare product_overhang(const Beam& b, const VecXd& density, double volume_fraction, bool printed,
                               double tolerance, result::SmoothParams smooth = {}) {
  if (printed) {
    smooth.build.direction = Eigen::Vector3d::UnitZ();
    smooth.build.angle = 45;
    smooth.build.plate = base_plate_height(b.mesh, Eigen::Vector3d::UnitZ(), 0);
  }
  const result::TriSurface s = pipeline::result_surface(b.mesh, density, -1, volume_fraction, smooth, nullptr, b.anchors);
  OverhangMeasureParams m;
  m.angle = 45;
  m.plate = -5;
  m.tolerance = tolerance;
  return overhang_share(s.V, s.F, Eigen::Vector3d::UnitZ(), m, &s.tag, &s.lock);
}

TEST(Overhang, MeasureCountsEveryFaceAndSaysWhose) {
  // three triangles facing down: a flat one of the design (an overhang), one of the design at
  // 40° from the plate (an overhang at 45°, not with a tolerance of 6°), and a flat one of a
  // non-design solid (a load pad's face the design leaves bare: it needs supports as much as the
  // design's own, so it counts; the tags only say whose it is — without locks nothing is set
  // apart as the part's given shape: MeasureSetsThePartsGivenFacesApart)
  MatX3d V(9, 3);
  const double t = std::tan(40 * M_PI / 180);
  V << 0, 0, 1, 0, 1, 1, 1, 0, 1,     // flat, facing down
      0, 0, 2, 0, 1, 2, 1, 0, 2 + t,  // rising 40° along x, facing down
      0, 0, 3, 0, 1, 3, 1, 0, 3;      // flat, the pad's face
  MatX3i F(3, 3);
  F << 0, 1, 2, 3, 4, 5, 6, 7, 8;
  VecXi tag(3);
  tag << 0, 0, -1;
  OverhangMeasureParams p;
  const OverhangShare all = overhang_share(V, F, Eigen::Vector3d::UnitZ(), p);
  const OverhangShare split = overhang_share(V, F, Eigen::Vector3d::UnitZ(), p, &tag);
  const double a_flat = 0.5, a_40 = 0.5 / std::cos(40 * M_PI / 180);
  EXPECT_NEAR(all.downward_area, 2 * a_flat + a_40, 1e-12);
  EXPECT_NEAR(all.share(), 1.0, 1e-12);
  EXPECT_NEAR(split.share(), all.share(), 1e-15);
  EXPECT_NEAR(split.design_overhang, a_flat + a_40, 1e-12);
  EXPECT_NEAR(split.nondesign_overhang, a_flat, 1e-12);
  EXPECT_EQ(split.omega_overhang, 0.0);
  tag[2] = 4;  // Ω's Face4 instead
  EXPECT_NEAR(overhang_share(V, F, Eigen::Vector3d::UnitZ(), p, &tag).omega_overhang, a_flat, 1e-12);
  p.tolerance = 6;
  EXPECT_NEAR(overhang_share(V, F, Eigen::Vector3d::UnitZ(), p, &tag).share(), 2 * a_flat / (2 * a_flat + a_40),
              1e-12);
  p.plate = 1;  // the flat triangle at z = 1 rests on the plate now
  EXPECT_NEAR(overhang_share(V, F, Eigen::Vector3d::UnitZ(), p, &tag).downward_area, a_flat + a_40, 1e-12);
}

TEST(Overhang, MeasureSetsThePartsGivenFacesApart) {
  // a solid 12 × 4 × 3 mm box, a non-design block in its corner x < 2 standing on its bottom
  // face, measured as if the plate lay 1 mm below the box: the whole bottom faces down off the
  // plate. The design's part of it (Ω's face where the design reaches it, 10 × 4 mm²) counts;
  // the block's bottom (2 × 4 mm², a non-design face on Ω's boundary: no design changes it) is
  // set apart as the part's given shape, on the result surface the product makes
  const TetMesh m = box_mesh({12, 4, 3}, {{{0, 0, 0, 2, 4, 3}}});
  const VecXd full = VecXd::Ones(m.T.rows());
  const result::TriSurface s = pipeline::result_surface(m, full, 0.5, -1, result::SmoothParams{});
  OverhangMeasureParams p;
  p.plate = -1;
  const OverhangShare o = overhang_share(s.V, s.F, Eigen::Vector3d::UnitZ(), p, &s.tag, &s.lock);
  EXPECT_NEAR(o.given_overhang_area, 8, 1e-9);
  EXPECT_NEAR(o.given_downward_area, 8, 1e-9);
  EXPECT_NEAR(o.omega_overhang, 40, 1e-9);
  EXPECT_NEAR(o.downward_area, 40, 1e-9);
  EXPECT_EQ(o.design_overhang + o.nondesign_overhang, 0.0);
  const OverhangShare untagged = overhang_share(s.V, s.F, Eigen::Vector3d::UnitZ(), p);
  EXPECT_NEAR(untagged.overhang_area, 48, 1e-9) << "without tags every triangle counts";
}

TEST(Overhang, BeamHasLessOverhangWithTheControl) {
  // measured on the result surface the user gets (product_overhang), β to its end (32)
  const Beam b = test_beam();
  SimpParams p;
  p.volume_fraction = 0.3;
  p.filter.radius = 2.5;
  p.max_iterations = kBeamIterations;
  const SimpResult free_run = optimize(b.mesh, fem::Material{}, b.supports, b.loads, {}, p);
  p.controls.overhang = OverhangControl{};
  p.controls.overhang.enabled = true;
  p.controls.overhang.margin = kBeamMargin;
  p.controls.overhang.cell = 10.0 / 6;
  const SimpResult printed = optimize(b.mesh, fem::Material{}, b.supports, b.loads, {}, p);
  const OverhangShare with = product_overhang(b, printed.density, 0.3, true, 0);
  const OverhangShare unlifted = product_overhang(b, printed.density, 0.3, false, 0);
  const OverhangShare without = product_overhang(b, free_run.density, 0.3, false, 0);
  const OverhangShare free_lifted = product_overhang(b, free_run.density, 0.3, true, 0);
  result::SmoothParams crisp;  // the iso-surface the design's densities make, as marching tetrahedra cut it
  crisp.iterations = 0;
  crisp.remesh = false;
  crisp.repair = false;
  const OverhangShare crisp_with = product_overhang(b, printed.density, 0.3, false, 0, crisp);
  std::cout << "overhang share with the control " << with.share() << " (" << with.overhang_area << " of "
            << with.downward_area << " mm2: design " << with.design_overhang << ", pad " << with.nondesign_overhang
            << ", part " << with.omega_overhang << "), without the last pass " << unlifted.share()
            << ", its crisp iso-surface " << crisp_with.share() << ", without the control " << without.share()
            << " (through the last pass " << free_lifted.share() << "); compliance "
            << printed.history.back().compliance << " against " << free_run.history.back().compliance << ", beta "
            << printed.history.back().beta << ", grey " << printed.history.back().grey << ", " << printed.history.size()
            << " iterations\n";
  EXPECT_LE(crisp_with.share(), kBeamCrispShareBound) << "the filter's own design, before the surface stage";
  EXPECT_EQ(printed.history.back().beta, 32) << "beta should reach its end";
  EXPECT_LE(with.share(), kBeamShareBound) << "the issue's 1 % on the surface the user gets";
  EXPECT_LE(with.share(), 0.2 * without.share());
  EXPECT_GE(without.share(), 0.2) << "the free design should need supports printed this way";
  EXPECT_GE(free_lifted.share(), kFreeLiftedShareAtLeast) << "the last pass must not make a free design print";
  EXPECT_NEAR(printed.history.back().volume_fraction, 0.3, 0.01);
  EXPECT_LE(printed.history.back().compliance, 2 * free_run.history.back().compliance);
}

TEST(Overhang, UprightBeamCarriesItsPadsUnderside) {
  // the test beam printed upright on its fixed end (build +x from Face1, x = 0): the pad's face
  // x = 28 (10 × 10 mm, inside Ω) faces straight down and stands on the design alone. Through the
  // product's run (pipeline::optimize_job: the control holds the design under that face solid,
  // simp::carried_tets) the result surface the user gets leaves none of it bare — main left 81.7
  // of 334 mm² of downward area bare (overhang6) — and meets the 1 % as a whole
  const Beam b = test_beam();
  pipeline::Job job;
  job.supports = {fem::support_on(fem::SupportSpec::Kind::Fixed, {1})};
  job.load_cases = {fem::LoadCase{"a", {fem::LoadSpec{fem::LoadSpec::Kind::Force, {2}, {0, -30, -100}, 0, {}}}, 1}};
  SimpParams& p = job.optimization.simp;
  p.volume_fraction = 0.3;
  p.filter.radius = 2.5;
  p.max_iterations = kBeamIterations;
  job.optimization.filter_automatic = false;
  OverhangControl& o = p.controls.overhang;
  o.enabled = true;
  o.direction = Eigen::Vector3d::UnitX();
  o.base_face = 1;
  o.margin = kBeamMargin;
  o.cell = 10.0 / 6;
  const pipeline::OptimizeResult r = pipeline::optimize_job(job, b.mesh);
  OverhangMeasureParams m;
  m.angle = 45;
  m.plate = 0;
  const OverhangShare s = overhang_share(r.surface.V, r.surface.F, Eigen::Vector3d::UnitX(), m, &r.surface.tag,
                                         &r.surface.lock);
  std::cout << "upright beam: overhang " << s.share() << " (" << s.overhang_area << " of " << s.downward_area
            << " mm2: design " << s.design_overhang << ", pad bared " << s.nondesign_overhang << ", part "
            << s.omega_overhang << "); compliance " << r.simp.history.back().compliance << ", "
            << r.simp.history.size() << " iterations\n";
  EXPECT_LE(s.nondesign_overhang, 0.01 * s.downward_area) << "the pad's underside must be carried, not bared";
  EXPECT_LE(s.share(), kBeamShareBound) << "the issue's 1 % on the surface the user gets";
  EXPECT_GT(s.downward_area, 50.0) << "the pad's face and the design under it face down";
}

}  // namespace
}  // namespace topopt::simp

