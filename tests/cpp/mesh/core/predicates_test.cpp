// Filtered exact predicates against exact rational arithmetic (GMP), on random, degenerate
// and nearly degenerate inputs.
#include "mesh/core/predicates.h"

#include <gmpxx.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace topopt::mesh::predicates {
namespace {

int sgn(const mpq_class& q) { return q > 0 ? 1 : q < 0 ? -1 : 0; }

int exact_orient3d(const double* a, const double* b, const double* c, const double* d) {
  mpq_class m[3][3];
  const double* p[3] = {b, c, d};
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) m[i][k] = mpq_class(p[i][k]) - mpq_class(a[k]);
  mpq_class det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                  m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  return sgn(det);
}

int exact_orient2d(const double* a, const double* b, const double* c) {
  mpq_class bx = mpq_class(b[0]) - a[0], by = mpq_class(b[1]) - a[1], cx = mpq_class(c[0]) - a[0],
            cy = mpq_class(c[1]) - a[1];
  return sgn(bx * cy - by * cx);
}

/// Inside the circumsphere: sign of the distance comparison, from the exact circumcentre.
int exact_insphere(const double* a, const double* b, const double* c, const double* d, const double* e) {
  // solve for centre x: 2 (p_i − a)·x = |p_i|² − |a|², i = b, c, d
  const double* p[3] = {b, c, d};
  mpq_class M[3][3], r[3];
  for (int i = 0; i < 3; ++i) {
    r[i] = 0;
    for (int k = 0; k < 3; ++k) {
      M[i][k] = 2 * (mpq_class(p[i][k]) - a[k]);
      r[i] += mpq_class(p[i][k]) * p[i][k] - mpq_class(a[k]) * a[k];
    }
  }
  auto det3 = [](mpq_class A[3][3]) -> mpq_class {  // a value, not a GMP expression of temporaries
    return A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) - A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
           A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
  };
  mpq_class D = det3(M);
  if (D == 0) return 0;
  mpq_class x[3];
  for (int k = 0; k < 3; ++k) {
    mpq_class A[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) A[i][j] = j == k ? r[i] : M[i][j];
    x[k] = det3(A) / D;
  }
  mpq_class ra = 0, re = 0;
  for (int k = 0; k < 3; ++k) ra += (x[k] - a[k]) * (x[k] - a[k]), re += (x[k] - e[k]) * (x[k] - e[k]);
  return sgn(ra - re);
}

TEST(Predicates, RandomPointsAgreeWithRationals) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int n = 0; n < 2000; ++n) {
    double p[5][3];
    for (auto& q : p)
      for (double& x : q) x = u(rng);
    ASSERT_EQ(orient3d(p[0], p[1], p[2], p[3]), exact_orient3d(p[0], p[1], p[2], p[3]));
    ASSERT_EQ(orient2d(p[0], p[1], p[2]), exact_orient2d(p[0], p[1], p[2]));
    int o = exact_orient3d(p[0], p[1], p[2], p[3]);
    if (o != 0) {
      ASSERT_EQ(o * insphere(p[0], p[1], p[2], p[3], p[4]), exact_insphere(p[0], p[1], p[2], p[3], p[4]));
    }
  }
}

TEST(Predicates, DegenerateAndNearlyDegenerate) {
  long before = exact_fallbacks();
  // Coplanar points on a tilted plane, at coordinates that do not round trip: many exact zeros
  // and many tiny non-zero determinants, decided only by the exact path.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  int zeros = 0, checked = 0;
  for (int n = 0; n < 3000; ++n) {
    double p[4][3];
    for (auto& q : p) {
      q[0] = u(rng), q[1] = u(rng);
      q[2] = 0.1 * q[0] + 0.3 * q[1] + 0.7;  // rounded: only approximately coplanar
    }
    if (n % 3 == 0) p[3][0] = std::nextafter(p[3][0], 2.0);  // one ulp off
    int e = exact_orient3d(p[0], p[1], p[2], p[3]);
    ASSERT_EQ(orient3d(p[0], p[1], p[2], p[3]), e) << n;
    zeros += e == 0, ++checked;
  }
  // Exactly coplanar and collinear points on a power-of-two grid.
  double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 1, 0}, d[3] = {0.5, 0.25, 0};
  EXPECT_EQ(orient3d(a, b, c, d), 0);
  double e2[3] = {0.5, 0.5, 1e-300};
  EXPECT_EQ(orient3d(a, b, c, e2), 1);  // tiny but positive: above the plane (a, b, c)
  EXPECT_EQ(orient2d(a, b, d), 1);
  double f[3] = {2, 0, 0};
  EXPECT_EQ(orient2d(a, b, f), 0);
  // Cospherical: the eight corners of a cube, and a point nudged by one ulp.
  double cube[8][3];
  for (int i = 0; i < 8; ++i) cube[i][0] = i & 1, cube[i][1] = (i >> 1) & 1, cube[i][2] = (i >> 2) & 1;
  double t0[3] = {0, 0, 0}, t1[3] = {1, 0, 0}, t2[3] = {0, 1, 0}, t3[3] = {0, 0, 1};
  ASSERT_EQ(orient3d(t0, t1, t2, t3), 1);
  EXPECT_EQ(insphere(t0, t1, t2, t3, cube[7]), 0);
  double in[3] = {1, 1, std::nextafter(1.0, 0.0)}, out[3] = {1, 1, std::nextafter(1.0, 2.0)};
  EXPECT_EQ(insphere(t0, t1, t2, t3, in), 1);
  EXPECT_EQ(insphere(t0, t1, t2, t3, out), -1);
  double centre[3] = {0.5, 0.5, 0.5};
  EXPECT_EQ(insphere(t0, t1, t2, t3, centre), 1);
  EXPECT_EQ(insphere(t0, t2, t1, t3, centre), -1);  // reversed orientation flips the sign
  // Cocircular in 2D.
  double q0[2] = {1, 0}, q1[2] = {0, 1}, q2[2] = {-1, 0}, q3[2] = {0, -1}, q4[2] = {0, std::nextafter(-1.0, 0.0)};
  EXPECT_EQ(incircle(q0, q1, q2, q3), 0);
  EXPECT_EQ(incircle(q0, q1, q2, q4), 1);
  EXPECT_GT(exact_fallbacks() - before, 1000);  // the degenerate cases did take the exact path
  (void)zeros;
  EXPECT_EQ(checked, 3000);
}

}  // namespace
}  // namespace topopt::mesh::predicates
