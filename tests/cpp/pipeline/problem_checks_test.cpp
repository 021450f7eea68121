// Checks before SIMP: loads that put no force on the part, or only on supported nodes, and
// filter radii larger than the part or too large for memory, each with what to change; and
// the neighbour-pair estimate against the filter's own count.
#include "pipeline/problem_checks.h"

#include <gtest/gtest.h>

#include <functional>

#include "common/error.h"
#include "mesh/core/structured_box.h"
#include "simp/density_filter.h"
#include "testing/expect_error.h"

namespace topopt::pipeline {
namespace {
using topopt::testing::expect_error;

/// A 20 x 4 x 4 mm beam, Face1 at x = 0, Face2 at x = 20.
TetMesh beam() {
  mesh::StructuredBoxParams p;
  p.size = {20, 4, 4};
  p.cells = {20, 4, 4};
  return mesh::structured_box_mesh(p);
}

fem::LoadCase force_on(int face, std::array<double, 3> v) {
  return fem::LoadCase{"tip", {fem::LoadSpec{fem::LoadSpec::Kind::Force, {face}, v, 0, {}}}, 1};
}

TEST(ProblemChecks, LoadsMustReachTheFreePart) {
  const TetMesh m = beam();
  const fem::Material mat;
  const fem::Supports fixed1 =
      fem::make_supports(m, {fem::SupportSpec{fem::SupportSpec::Kind::Fixed, {1}, {true, true, true}, {}}});
  const std::vector<fem::LoadCase> ok{force_on(2, {0, 0, -100})};
  EXPECT_NO_THROW(check_loads_reach_the_part(fem::make_loads(m, mat, ok), fixed1, ok));
  // a zero force: SIMP would divide by a zero compliance
  const std::vector<fem::LoadCase> zero{force_on(2, {0, 0, 0})};
  expect_error([&] { check_loads_reach_the_part(fem::make_loads(m, mat, zero), fixed1, zero); },
               ErrorCode::InvalidParameter, {"load case \"tip\" puts no force on the part"});
  // every face fixed: the load acts only on held nodes
  std::vector<int> all;
  for (int f = 1; f <= m.face.maxCoeff(); ++f) all.push_back(f);
  const fem::Supports everywhere =
      fem::make_supports(m, {fem::SupportSpec{fem::SupportSpec::Kind::Fixed, all, {true, true, true}, {}}});
  expect_error([&] { check_loads_reach_the_part(fem::make_loads(m, mat, ok), everywhere, ok); },
               ErrorCode::InvalidParameter, {"acts only where the supports hold the part"});
}

TEST(ProblemChecks, PairEstimateFollowsTheFilter) {
  const TetMesh m = beam();
  std::vector<int> design(m.T.rows());
  for (long t = 0; t < m.T.rows(); ++t) design[t] = static_cast<int>(t);
  for (double r : {1.5, 3.0}) {
    simp::FilterParams fp;
    fp.radius = r;
    const simp::DensityFilter filter(m, design, simp::tet_volumes(m), fp);
    const double exact = filter.mean_neighbours() * static_cast<double>(m.T.rows());
    EXPECT_NEAR(estimated_filter_pairs(m, r), exact, 0.25 * exact) << "radius " << r;
  }
}

TEST(ProblemChecks, FilterRadiusLargerThanThePartOrThanMemory) {
  const TetMesh m = beam();  // diagonal 21.5 mm
  expect_error([&] { check_filter_radius(m, 500, true, 1e12); }, ErrorCode::InvalidParameter,
               {"'optimization.filter_radius' (500 mm) is larger than the part"});
  EXPECT_NO_THROW(check_filter_radius(m, 3, true, 1e12));
  // the filter may take half of 1 MB, at 8 bytes a pair 62 500 pairs: radius 3 needs more
  const std::string msg = expect_error([&] { check_filter_radius(m, 3, true, 1e6); }, ErrorCode::TooLarge,
                                       {"give 'optimization.filter_radius' at most"});
  // the radius it names fits
  const double fits = std::stod(msg.substr(msg.find("at most ") + 8));
  EXPECT_GT(fits, 0.3);
  EXPECT_LT(fits, 3);
  EXPECT_NO_THROW(check_filter_radius(m, fits, true, 1e6));
  expect_error([&] { check_filter_radius(m, 3, false, 1e6); }, ErrorCode::TooLarge, {"use a coarser mesh size"});
  EXPECT_GT(physical_memory_bytes(), 1e8);
}

TEST(ProblemChecks, IterationCapBeforeTheDesignIsCrispIsNamed) {
  const TetMesh m = beam();
  const fem::Material mat;
  const fem::Supports supports = fem::make_supports(m, {fem::support_on(fem::SupportSpec::Kind::Fixed, {1})});
  const Eigen::MatrixXd loads = fem::make_loads(m, mat, {force_on(2, {0, 0, -100})});
  simp::SimpParams p;
  p.max_iterations = 4;  // β starts at 1: four iterations cannot reach 32
  simp::SimpResult capped = simp::optimize(m, mat, supports, loads, {}, p);
  ASSERT_FALSE(capped.converged);
  ASSERT_LT(capped.history.back().beta, p.projection.beta_max);
  const std::string w = not_crisp_warning(capped, p);
  for (const char* part :
       {"iteration cap (4)", "of 32", "% of the design volume is grey", "'optimization.max_iterations'"})
    EXPECT_NE(w.find(part), std::string::npos) << part << " missing from: " << w;
  // a run that converged, or one at full β with little grey, is not warned about
  simp::SimpResult settled = capped;
  settled.converged = true;
  EXPECT_EQ(not_crisp_warning(settled, p), "");
  simp::SimpResult sharp = capped;
  sharp.history.back().beta = p.projection.beta_max;
  sharp.history.back().grey = 0.01;
  EXPECT_EQ(not_crisp_warning(sharp, p), "");
  sharp.history.back().grey = 0.2;  // at full β but still grey
  EXPECT_NE(not_crisp_warning(sharp, p).find("20 % of the design volume is grey"), std::string::npos);
}

}  // namespace
}  // namespace topopt::pipeline
