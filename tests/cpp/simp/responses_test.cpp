// Responses beyond compliance (simp/responses): the displacement of a face, the p-norm stress
// and the first eigenvalue against finite differences; mass minimisation under a compliance, a
// displacement or a stress limit, and the first eigenfrequency maximised, with MMA.
#include "simp/responses/responses.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <iostream>
#include <map>
#include <random>
#include <set>

#include "common/error.h"
#include "fem/boundary_conditions.h"
#include "fem/kept_part.h"
#include "mesh/core/structured_box.h"
#include "testing/ccx_modes.h"
#include "testing/self_weight.h"

namespace topopt::simp {
namespace {

/// A 30 × 10 × 5 mm cantilever fixed at Face1 (x = 0) with a load pad at the far end, pulled
/// down (−y, 100 N) and sideways (−z, 60 N) at Face2 in two load cases.
struct Beam {
  TetMesh mesh;
  fem::Material mat;
  fem::Supports supports;
  Eigen::MatrixXd loads;
  std::vector<fem::LoadCase> cases;  ///< what loads were made from
};

Beam beam(std::array<int, 3> cells) {
  Beam b;
  mesh::StructuredBoxParams p;
  p.size = {30, 10, 5};
  p.cells = cells;
  p.nondesign = {{27.5, 0, 0, 30, 10, 5}};
  b.mesh = mesh::structured_box_mesh(p);
  b.supports = fem::make_supports(b.mesh, {fem::support_on(fem::SupportSpec::Kind::Fixed, {1})});
  const fem::LoadSpec pull{fem::LoadSpec::Kind::Force, {2}, {0, -100, 0}, 0, {}};
  const fem::LoadSpec push{fem::LoadSpec::Kind::Force, {2}, {0, 0, -60}, 0, {}};
  b.cases = {fem::LoadCase{"a", {pull}, 1}, fem::LoadCase{"b", {push}, 1}};
  b.loads = fem::make_loads(b.mesh, b.mat, b.cases);
  return b;
}

/// The limit on Face2's mean displacement along `direction`.
DisplacementLimit tip_limit(const Beam& b, const std::array<double, 3>& direction, double limit) {
  const fem::LoadSpec unit{fem::LoadSpec::Kind::Force, {2}, direction, 0, {}};
  return {"Face2", fem::make_loads(b.mesh, b.mat, {fem::LoadCase{"gauge", {unit}, 1}}).col(0), limit};
}

/// The tets of `m` with keep[t] and their boundary triangles, nodes renumbered (fem::kept_part).
TetMesh keep_tets(const TetMesh& m, const std::vector<bool>& keep) {
  return fem::kept_part(m, std::vector<char>(keep.begin(), keep.end()), fem::KeptNodes::Compact);
}

/// A 20 × 20 × 2 mm L (the square with its corner x > 8, y > 8 cut away), held at the top of
/// its upright (Face4, y = 20) and pulled down (−y, 200 N) at the end of its arm (Face2,
/// x = 20), which is a non-design load pad (x >= 18): the classic stress test, whose re-entrant
/// corner at (8, 8) concentrates the stress of a design that keeps it sharp.
Beam l_bracket() {
  mesh::StructuredBoxParams p;
  p.size = {20, 20, 2};
  p.cells = {20, 20, 2};
  p.nondesign = {{18, 0, 0, 20, 8, 2}};
  const TetMesh box = mesh::structured_box_mesh(p);
  std::vector<bool> keep(box.T.rows());
  for (long t = 0; t < box.T.rows(); ++t) {
    Eigen::RowVector3d c = Eigen::RowVector3d::Zero();
    for (int a = 0; a < 4; ++a) c += box.V.row(box.T(t, a)) / 4;
    keep[t] = !(c.x() > 8 && c.y() > 8);
  }
  Beam b;
  b.mesh = keep_tets(box, keep);
  b.supports = fem::make_supports(b.mesh, {fem::support_on(fem::SupportSpec::Kind::Fixed, {4})});
  const fem::LoadSpec pull{fem::LoadSpec::Kind::Force, {2}, {0, -200, 0}, 0, {}};
  b.cases = {fem::LoadCase{"down", {pull}, 1}};
  b.loads = fem::make_loads(b.mesh, b.mat, b.cases);
  return b;
}

/// True when the crisp design (tets with density >= 0.5, #T) has one face-connected piece that
/// holds a tet of every non-design solid 1..num_pads and a tet on each of `supported` faces.
bool one_piece_holds(const TetMesh& mesh, const VecXd& density, int num_pads, const std::vector<int>& supported) {
  const long nt = mesh.T.rows();
  std::vector<long> parent(nt);
  for (long t = 0; t < nt; ++t) parent[t] = t;
  std::function<long(long)> root = [&](long t) { return parent[t] == t ? t : parent[t] = root(parent[t]); };
  std::map<std::array<int, 3>, long> seen;  // a face of a kept tet -> the tet
  std::map<std::array<int, 3>, long> face_tet;
  for (long t = 0; t < nt; ++t) {
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int, 3> f;
      for (int a = 0, k = 0; a < 4; ++a)
        if (a != skip) f[k++] = mesh.T(t, a);
      std::sort(f.begin(), f.end());
      face_tet[f] = t;
      if (density[t] < 0.5) continue;
      auto [it, fresh] = seen.emplace(f, t);
      if (!fresh) parent[root(t)] = root(it->second);
    }
  }
  std::vector<std::set<long>> pieces_of;
  for (int pad = 1; pad <= num_pads; ++pad) {
    std::set<long> s;
    for (long t = 0; t < nt; ++t)
      if (mesh.domain[t] == pad) s.insert(root(t));
    pieces_of.push_back(s);
  }
  for (int face : supported) {
    std::set<long> s;
    for (long f = 0; f < mesh.F.rows(); ++f) {
      if (mesh.face[f] != face) continue;
      std::array<int, 3> k{mesh.F(f, 0), mesh.F(f, 1), mesh.F(f, 2)};
      std::sort(k.begin(), k.end());
      const long t = face_tet.at(k);
      if (density[t] >= 0.5) s.insert(root(t));
    }
    pieces_of.push_back(s);
  }
  // some piece is in every requirement's set
  for (long piece : pieces_of.front()) {
    bool all = true;
    for (const std::set<long>& s : pieces_of) all = all && s.count(piece);
    if (all) return true;
  }
  return false;
}

/// Central differences of face_displacement against its adjoint gradient at a random design.
void check_displacement_gradient(SimpParams params, unsigned seed, const Eigen::Matrix3Xd& gravity = {}) {
  Beam b = beam({6, 2, 2});
  params.solver.recycle_factor = false;  // every solve to machine precision
  const Eigen::MatrixXd loads = testing::with_self_weight(b.mesh, b.mat, b.loads, gravity);
  ComplianceProblem prob(b.mesh, b.mat, b.supports, loads, {}, params, {}, gravity);
  const DisplacementLimit gauge = tip_limit(b, {0, 0.6, -0.8}, 1);
  const int nd = static_cast<int>(prob.design().size());
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(0.2, 0.8);
  VecXd x(nd);
  for (int i = 0; i < nd; ++i) x[i] = uniform(rng);
  prob.compliance(x);
  Eigen::MatrixXd du;
  const VecXd u0 = face_displacement(prob, gauge, &du);
  ASSERT_GT(u0.cwiseAbs().minCoeff(), 0);
  const double h = 1e-4;  // truncation ~h², the solver's round-off ~1e-13/h
  for (int i : {0, nd / 3, nd / 2, nd - 1}) {
    VecXd xp = x, xm = x;
    xp[i] += h, xm[i] -= h;
    prob.compliance(xp);
    const VecXd up = face_displacement(prob, gauge);
    prob.compliance(xm);
    const VecXd um = face_displacement(prob, gauge);
    for (long k = 0; k < u0.size(); ++k) {
      const double fd = (up[k] - um[k]) / (2 * h);
      EXPECT_NEAR(du(i, k), fd, 1e-4 * std::abs(fd) + 1e-9 * std::abs(u0[k])) << "variable " << i << ", case " << k;
    }
  }
}

TEST(Responses, DisplacementGradientMatchesFiniteDifferences) {
  SimpParams p;
  p.filter.radius = 6;
  p.projection.beta_start = 4;  // a projection that bends the chain rule
  check_displacement_gradient(p, 11);
  p.filter.kind = FilterKind::Helmholtz;
  p.projection.enabled = false;
  check_displacement_gradient(p, 12);
}

TEST(Responses, DisplacementGradientWithSelfWeight) {
  SimpParams p;
  p.filter.radius = 6;
  Eigen::Matrix3Xd g(3, 2);
  g << 0, 3e8, -1e9, 0, 0, 5e8;
  check_displacement_gradient(p, 13, g);
}

TEST(Responses, DisplacementIsTheFaceMeanAlongTheDirection) {
  // the gauge of a unit force spread by area: a rigid translation t of every node reads d·t
  Beam b = beam({6, 2, 2});
  const DisplacementLimit gauge = tip_limit(b, {0, 0.6, -0.8}, 1);
  VecXd t(3 * b.mesh.V.rows());
  for (long n = 0; n < b.mesh.V.rows(); ++n) t.segment<3>(3 * n) = Eigen::Vector3d(2, 3, 5);
  EXPECT_NEAR(gauge.gauge.dot(t), 0.6 * 3 - 0.8 * 5, 1e-12);
}

TEST(Responses, MassUnderAComplianceLimitFindsTheVolumeThatMeetsIt) {
  // the compliance-optimal design at 40 % sets the limit; minimising the mass under that
  // limit must then land near 40 % with the compliance at the limit
  Beam b = beam({12, 4, 2});
  SimpParams p;
  p.volume_fraction = 0.4;
  p.filter.radius = 5;
  p.projection.enabled = false;
  p.update = UpdateKind::MMA;
  p.max_iterations = 80;
  const SimpResult reference = optimize(b.mesh, b.mat, b.supports, b.loads, {}, p);
  const double limit = reference.history.back().compliance;
  p.responses.objective = Objective::Mass;
  p.responses.compliance_limit = limit;
  p.volume_fraction = 0.6;  // the start
  const SimpResult r = optimize(b.mesh, b.mat, b.supports, b.loads, {}, p);
  const IterationRecord& last = r.history.back();
  EXPECT_LE(last.compliance, 1.01 * limit);
  EXPECT_GE(last.compliance, 0.95 * limit);  // the limit is active: no material wasted
  EXPECT_NEAR(last.volume_fraction, 0.4, 0.03);
  EXPECT_LT(last.volume_fraction, r.history.front().volume_fraction);
}

TEST(Responses, MassUnderADisplacementLimitKeepsTheTipWithinIt) {
  Beam b = beam({12, 4, 2});
  SimpParams p;
  p.filter.radius = 5;
  p.projection.enabled = false;
  p.update = UpdateKind::MMA;
  p.max_iterations = 60;
  p.volume_fraction = 0.5;
  // the tip's deflection of the full block, doubled, as the limit
  fem::Elasticity full(b.mesh, b.mat, b.supports);
  const DisplacementLimit probe = tip_limit(b, {0, -1, 0}, 1);
  const double solid = std::abs(probe.gauge.dot(full.solve(b.loads).col(0)));
  p.responses.objective = Objective::Mass;
  p.responses.displacements = {tip_limit(b, {0, -1, 0}, 2 * solid)};
  const SimpResult r = optimize(b.mesh, b.mat, b.supports, b.loads, {}, p);
  const IterationRecord& last = r.history.back();
  ASSERT_EQ(last.displacements.size(), 1u);
  EXPECT_LE(last.displacements[0], 1.01 * 2 * solid);
  EXPECT_GE(last.displacements[0], 0.9 * 2 * solid);  // active
  // a uniform design would need ρ³ = 1/2 (ρ = 0.79) to keep within twice the solid's deflection
  EXPECT_LT(last.volume_fraction, 0.75);
}

TEST(Responses, StressGradientMatchesFiniteDifferences) {
  for (const bool gravity : {false, true}) {
    Beam b = beam({6, 2, 2});
    SimpParams p;
    p.filter.radius = 6;
    p.projection.beta_start = 2;
    p.solver.recycle_factor = false;
    p.responses.stress_limit = 50;
    p.responses.stress_pnorm = 6;
    Eigen::Matrix3Xd g;
    if (gravity) {
      g.resize(3, 2);
      g << 0, 3e8, -1e9, 0, 0, 5e8;
    }
    const Eigen::MatrixXd loads = testing::with_self_weight(b.mesh, b.mat, b.loads, g);
    ComplianceProblem prob(b.mesh, b.mat, b.supports, loads, {}, p, {}, g);
    const int nd = static_cast<int>(prob.design().size());
    std::mt19937 rng(21);
    std::uniform_real_distribution<double> uniform(0.2, 0.8);
    VecXd x(nd);
    for (int i = 0; i < nd; ++i) x[i] = uniform(rng);
    prob.compliance(x);
    Eigen::MatrixXd ds;
    VecXd largest;
    const VecXd s0 = pnorm_stress(prob, p.responses, &ds, &largest);
    for (long k = 0; k < s0.size(); ++k) {
      EXPECT_GE(s0[k], largest[k]);  // a p-norm of a sum bounds the largest term from above
      EXPECT_GT(largest[k], 0);
    }
    const double h = 1e-5;
    for (int i : {0, nd / 4, nd / 2, nd - 1}) {
      VecXd xp = x, xm = x;
      xp[i] += h, xm[i] -= h;
      prob.compliance(xp);
      const VecXd sp = pnorm_stress(prob, p.responses);
      prob.compliance(xm);
      const VecXd sm = pnorm_stress(prob, p.responses);
      for (long k = 0; k < s0.size(); ++k) {
        const double fd = (sp[k] - sm[k]) / (2 * h);
        // a component below 1e-5 of the largest meets the solver's round-off over h (about
        // 1e-14 s0 / h): there the floor is 1e-6 of the largest component
        EXPECT_NEAR(ds(i, k), fd, 1e-4 * std::abs(fd) + 1e-6 * ds.col(k).cwiseAbs().maxCoeff())
            << "variable " << i << ", case " << k;
      }
    }
  }
}

TEST(Responses, MassUnderAStressLimitKeepsTheCrispDesignsStressWithinIt) {
  // the limit is twice the largest stress of the full block: the lightest design under it is
  // well below full, and its crisp version (solid or void, analysed anew) must hold the limit
  Beam b = beam({16, 6, 2});
  b.loads = b.loads.col(0).eval();  // the downward pull alone
  b.cases.resize(1);
  const VecXd full = VecXd::Ones(b.mesh.T.rows());
  const double solid = crisp_max_von_mises(b.mesh, b.mat, b.supports, b.cases, full);
  SimpParams p;
  p.filter.radius = 4;
  p.update = UpdateKind::MMA;
  p.move = 0.1;
  p.max_iterations = 200;
  p.volume_fraction = 0.8;
  p.responses.objective = Objective::Mass;
  p.responses.stress_limit = 2 * solid;
  p.responses.load_cases = b.cases;
  const SimpResult r = optimize(b.mesh, b.mat, b.supports, b.loads, {}, p);
  const double crisp = crisp_max_von_mises(b.mesh, b.mat, b.supports, b.cases, r.density);
  EXPECT_LE(crisp, 1.05 * p.responses.stress_limit) << "solid block " << solid << " MPa";
  EXPECT_LT(r.history.back().volume_fraction, 0.7);
  EXPECT_GT(r.history.back().stress_relaxed, 0);
  // the history's crisp stress is this one's, up to the last update (the history's last record
  // is the design before it; r.density after it)
  EXPECT_NEAR(r.history.back().stress_crisp, crisp, 1e-3 * crisp);
  // not asserted: its crisp cut at 0.5 is one piece holding the pad and Face1. On this coarse
  // beam (filter radius 4 over 2 mm cells, β stopped at 8) it is not; the L bracket's is.
}

TEST(Responses, CrispStressLoadsOnlyTheMaterialTheDesignKeeps) {
  // a bare beam (no load pad) whose crisp design removed the upper half of the loaded end face:
  // the tip force must act on the lower half that is left, as on the crisp part analysed alone.
  // Made on the whole mesh, part of it landed on nodes of removed tets only, held by e_min.
  mesh::StructuredBoxParams box;
  box.size = {30, 10, 5};
  box.cells = {15, 5, 3};
  const TetMesh mesh = mesh::structured_box_mesh(box);
  const fem::Material mat;
  const std::vector<fem::SupportSpec> held{fem::support_on(fem::SupportSpec::Kind::Fixed, {1})};
  const std::vector<fem::LoadCase> cases{
      fem::LoadCase{"down", {fem::LoadSpec{fem::LoadSpec::Kind::Force, {2}, {0, -100, 0}, 0, {}}}, 1}};
  VecXd density = VecXd::Ones(mesh.T.rows());
  std::vector<char> kept(mesh.T.rows(), 1);
  for (long t = 0; t < mesh.T.rows(); ++t) {
    Eigen::RowVector3d c = Eigen::RowVector3d::Zero();
    for (int a = 0; a < 4; ++a) c += mesh.V.row(mesh.T(t, a)) / 4;
    if (c.x() > 24 && c.y() > 5) density[t] = 0.1, kept[t] = 0;
  }
  const double crisp = crisp_max_von_mises(mesh, mat, fem::make_supports(mesh, held), cases, density);
  const TetMesh part = fem::kept_part(mesh, kept, fem::KeptNodes::Compact);
  fem::Elasticity alone(part, mat, fem::make_supports(part, held));
  const Eigen::MatrixXd u = alone.solve(fem::make_loads(part, mat, cases));
  const double expected = alone.von_mises(u.col(0)).maxCoeff();
  EXPECT_NEAR(crisp, expected, 1e-3 * expected);
  // the whole mesh's loads put a share of the force on removed material: a different stress
  const double on_all = [&]() {
    fem::Elasticity fe(mesh, mat, fem::make_supports(mesh, held));
    VecXd scale(mesh.T.rows());
    for (long t = 0; t < mesh.T.rows(); ++t) scale[t] = kept[t] ? 1.0 : 1e-9;
    fe.set_scale(scale);
    const VecXd vm = fe.solid_von_mises(fe.solve(fem::make_loads(mesh, mat, cases)).col(0));
    double top = 0;
    for (long t = 0; t < mesh.T.rows(); ++t)
      if (kept[t]) top = std::max(top, vm[t]);
    return top;
  }();
  EXPECT_GT(std::abs(on_all - expected), 0.05 * expected) << "the old loads give " << on_all << " MPa";
}

TEST(Responses, StressLimitRoundsTheReentrantCornerOfAnLBracket) {
  // the lightest L under a stress limit, and the stiffest L of the same volume: the first must
  // keep the limit on its crisp design and carry less stress than the second, whose re-entrant
  // corner stays sharp
  const Beam b = l_bracket();
  const double solid = crisp_max_von_mises(b.mesh, b.mat, b.supports, b.cases, VecXd::Ones(b.mesh.T.rows()));
  SimpParams p;
  p.filter.radius = 1.5;
  p.update = UpdateKind::MMA;
  p.max_iterations = 250;
  p.volume_fraction = 0.8;
  p.responses.objective = Objective::Mass;
  p.responses.stress_limit = 1.2 * solid;
  p.responses.load_cases = b.cases;
  const SimpResult r = optimize(b.mesh, b.mat, b.supports, b.loads, {}, p);
  const double crisp = crisp_max_von_mises(b.mesh, b.mat, b.supports, b.cases, r.density);
  const double volume = r.history.back().volume_fraction;
  EXPECT_LE(crisp, 1.1 * p.responses.stress_limit) << "solid L " << solid << " MPa";
  EXPECT_GT(volume, 0.2);
  EXPECT_LT(volume, 0.75);
  EXPECT_TRUE(one_piece_holds(b.mesh, r.density, 1, {4}));
  SimpParams stiff;
  stiff.filter.radius = 1.5;
  stiff.volume_fraction = volume;
  stiff.max_iterations = 250;
  const SimpResult c = optimize(b.mesh, b.mat, b.supports, b.loads, {}, stiff);
  const double corner = crisp_max_von_mises(b.mesh, b.mat, b.supports, b.cases, c.density);
  EXPECT_LT(crisp, corner) << "the compliance design of volume " << c.history.back().volume_fraction;
  std::cout << "L bracket: solid " << solid << " MPa, limit " << p.responses.stress_limit << " MPa, stress design "
            << crisp << " MPa at volume " << volume << " (" << r.history.size() << " iterations), compliance design "
            << corner << " MPa at volume " << c.history.back().volume_fraction << "\n";
}

TEST(Responses, EigenvalueGradientMatchesFiniteDifferences) {
  Beam b = beam({6, 2, 2});
  SimpParams p;
  p.filter.radius = 6;
  p.projection.beta_start = 2;
  p.solver.recycle_factor = false;
  p.responses.eigen_tolerance = 1e-13;
  ComplianceProblem prob(b.mesh, b.mat, b.supports, b.loads, {}, p);
  const int nd = static_cast<int>(prob.design().size());
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> uniform(0.2, 0.8);  // above Pedersen's 0.1 and below it
  VecXd x(nd);
  for (int i = 0; i < nd; ++i) x[i] = uniform(rng);
  x[nd / 2] = 0.05;
  prob.compliance(x);
  Eigen::MatrixXd warm;
  VecXd grad;
  const fem::ModalResult m0 = first_eigenvalue(prob, b.mat.density, p.responses, warm, &grad);
  ASSERT_FALSE(m0.first_repeated);
  const double h = 1e-5;
  for (int i : {0, nd / 4, nd / 2, nd - 1}) {
    VecXd xp = x, xm = x;
    xp[i] += h, xm[i] -= h;
    prob.compliance(xp);
    const double lp = first_eigenvalue(prob, b.mat.density, p.responses, warm).eigenvalues[0];
    prob.compliance(xm);
    const double lm = first_eigenvalue(prob, b.mat.density, p.responses, warm).eigenvalues[0];
    const double fd = (lp - lm) / (2 * h);
    EXPECT_NEAR(grad[i], fd, 1e-4 * std::abs(fd) + 1e-9 * m0.eigenvalues[0]) << "variable " << i;
  }
}

TEST(Responses, FrequencyDesignIsOnePieceWithTheLoadPadAndAgreesWithCcx) {
  // the cantilever with its load pad as a tip mass: the design of 40 % that maximises the first
  // eigenfrequency, carried through the β continuation to a crisp design, must hold the pad;
  // its crisp design's (kept tets only) first eigenfrequency beats the uniform start's and
  // agrees with CalculiX's on the same tets
  Beam b = beam({24, 8, 4});
  SimpParams p;
  p.volume_fraction = 0.4;
  p.filter.radius = 2.5;
  p.update = UpdateKind::MMA;
  p.move = 0.1;
  p.max_iterations = 300;
  p.responses.objective = Objective::Frequency;
  const SimpResult r = optimize(b.mesh, b.mat, b.supports, b.loads, {}, p);
  ASSERT_GE(r.history.size(), 5u);
  EXPECT_EQ(r.history.back().beta, p.projection.beta_max);
  EXPECT_NEAR(r.history.back().volume_fraction, 0.4, 0.01);
  EXPECT_TRUE(one_piece_holds(b.mesh, r.density, 1, {1}));
  std::vector<bool> keep(b.mesh.T.rows());
  for (long t = 0; t < b.mesh.T.rows(); ++t) keep[t] = r.density[t] >= 0.5;
  const TetMesh crisp = keep_tets(b.mesh, keep);
  const fem::Supports held = fem::make_supports(crisp, {fem::support_on(fem::SupportSpec::Kind::Fixed, {1})});
  fem::Elasticity fe(crisp, b.mat, held);
  const double ours = fem::lowest_modes(fe, b.mat.density, {}).frequencies[0];
  const double uniform = r.history.front().frequency;
  EXPECT_GT(ours, 1.2 * uniform);
  // SIMP's last, nearly crisp iterate against the crisp design (grey tets and the void's e_min)
  EXPECT_NEAR(r.history.back().frequency, ours, 0.05 * ours);
  std::cout << "frequency design: uniform start " << uniform << " Hz, SIMP's last " << r.history.back().frequency
            << " Hz, crisp " << ours << " Hz (" << r.history.size() << " iterations)\n";
  if (!testing::have_ccx()) GTEST_SKIP() << "ccx is not installed";
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("topopt_ccx_freq_design_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::vector<double> theirs = testing::ccx_frequencies(crisp, b.mat, held, 1, dir);
  ASSERT_EQ(theirs.size(), 1u) << "no eigenvalue table from ccx; see " << dir;
  std::cout << "frequency design's crisp tets: ours " << ours << " Hz, ccx " << theirs[0] << " Hz\n";
  // issue 22's bound: within 1 % of CalculiX's *FREQUENCY on the same crisp tets (measured 0.04 %)
  EXPECT_NEAR(ours, theirs[0], 0.01 * theirs[0]);
  std::filesystem::remove_all(dir);
}

TEST(Responses, RefusesWhatCannotRun) {
  SimpParams p;
  p.responses.objective = Objective::Mass;
  p.update = UpdateKind::MMA;
  EXPECT_THROW(check_responses(p, 30), Error);  // no limit
  p.responses.compliance_limit = 10;
  EXPECT_NO_THROW(check_responses(p, 30));
  p.update = UpdateKind::OC;
  EXPECT_THROW(check_responses(p, 30), Error);  // OC cannot
  p.update = UpdateKind::MMA;
  p.responses.displacements = {{"Face2", VecXd::Ones(30), -1}};
  EXPECT_THROW(check_responses(p, 30), Error);  // negative limit
  p.responses.displacements = {{"Face2", VecXd::Ones(12), 1}};
  EXPECT_THROW(check_responses(p, 30), Error);  // gauge of another mesh
}

}  // namespace
}  // namespace topopt::simp
