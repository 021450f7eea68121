// Each tet improvement kernel on a small hand-made configuration whose answer is known (radius
// ratios worked out by hand and checked numerically): its check-only plan says what would
// change and leaves the mesh as it was; applying it gives the known tets or position, with the
// volume kept. Then the drivers that sweep the kernels over the bad tets.
#include "mesh/volume/tet_improve.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Eigenvalues>

#include "common/face_key.h"
#include "common/tet_boundary.h"
#include "io/msh.h"
#include "mesh/core/conformity.h"
#include "mesh/core/predicates.h"
#include "mesh/core/tet_quality.h"

namespace topopt::mesh {
namespace {

using Vec3 = Eigen::Vector3d;
using Points = std::vector<Vec3>;

Tet positive(const Points& P, Tet t) {
  if (predicates::orient3d(P[t[0]].data(), P[t[1]].data(), P[t[2]].data(), P[t[3]].data()) < 0) std::swap(t[2], t[3]);
  return t;
}

double rho(const Points& P, const Tet& t) { return radius_ratio(P[t[0]], P[t[1]], P[t[2]], P[t[3]]); }

double worst(const Points& P, const std::vector<Tet>& tets) {
  double w = 1;
  for (const Tet& t : tets) w = std::min(w, rho(P, t));
  return w;
}

/// Sum of the tets' signed volumes; every tet must be positive.
double volume(const Points& P, const std::vector<Tet>& tets) {
  double v = 0;
  for (const Tet& t : tets) {
    EXPECT_GT(predicates::orient3d(P[t[0]].data(), P[t[1]].data(), P[t[2]].data(), P[t[3]].data()), 0);
    v += (P[t[1]] - P[t[0]]).dot((P[t[2]] - P[t[0]]).cross(P[t[3]] - P[t[0]])) / 6;
  }
  return v;
}

bool has(const Tet& t, int x) { return std::find(t.begin(), t.end(), x) != t.end(); }

/// An equilateral triangle a, b, c (nodes 0-2, circumradius 1, z = 0) and apexes d = (0, 0, h),
/// e = (0, 0, -h) (nodes 3, 4).
Points bipyramid(double h) {
  const double s = std::sqrt(3.0) / 2;
  return {{1, 0, 0}, {-0.5, s, 0}, {-0.5, -s, 0}, {0, 0, h}, {0, 0, -h}};
}

/// The bipyramid as the two tets on the face abc.
std::vector<Tet> two_tets(const Points& P) { return {positive(P, {0, 1, 2, 3}), positive(P, {0, 2, 1, 4})}; }

/// The bipyramid as the three tets around the edge de.
std::vector<Tet> three_tets(const Points& P) {
  return {positive(P, {0, 1, 3, 4}), positive(P, {1, 2, 3, 4}), positive(P, {2, 0, 3, 4})};
}

TEST(TetImprove, Flip23TurnsTwoFlatTetsIntoThreeAroundTheEdgeOfTheirApexes) {
  // h = 0.3: the two tets on abc have radius ratio 0.2287, the three around de 0.5053
  Points P = bipyramid(0.3);
  std::vector<Tet> tets = two_tets(P);
  const std::vector<Tet> before = tets;
  const Points P0 = P;
  const double v0 = volume(P, tets);
  TetSweep s(P, tets);
  const int face = static_cast<int>(std::find(tets[0].begin(), tets[0].end(), 3) - tets[0].begin());  // abc
  const TetReplacement r = plan_flip23(s, 0, face);
  ASSERT_FALSE(r.empty());
  EXPECT_EQ(tets, before) << "the plan changed the tets";
  EXPECT_EQ(P, P0);
  EXPECT_EQ(r.old_tets, (std::vector<int>{0, 1}));
  EXPECT_NEAR(r.before, 0.2287, 1e-4);
  EXPECT_NEAR(r.after, 0.5053, 1e-4);
  apply(s, r);
  s.end();
  ASSERT_EQ(tets.size(), 3u);
  for (const Tet& t : tets) EXPECT_TRUE(has(t, 3) && has(t, 4)) << "every new tet holds the edge de";
  EXPECT_NEAR(volume(P, tets), v0, 1e-15);
  EXPECT_NEAR(worst(P, tets), 0.5053, 1e-4);
  // h = 1: the two tets (0.927) beat the three (0.660): no flip
  Points Q = bipyramid(1.0);
  std::vector<Tet> good = two_tets(Q);
  TetSweep q(Q, good);
  const int qf = static_cast<int>(std::find(good[0].begin(), good[0].end(), 3) - good[0].begin());
  EXPECT_TRUE(plan_flip23(q, 0, qf).empty());
}

TEST(TetImprove, RemoveEdgeOnARingOfThreeIsTheThreeTwoFlip) {
  // h = 1: the three tets around de (0.660) become the two on abc (0.927)
  Points P = bipyramid(1.0);
  std::vector<Tet> tets = three_tets(P);
  const std::vector<Tet> before = tets;
  const double v0 = volume(P, tets);
  TetSweep s(P, tets);
  EXPECT_TRUE(plan_remove_edge(s, 0, 1).empty()) << "ab is a boundary edge: two tets, no ring";
  const TetReplacement r = plan_remove_edge(s, 3, 4);
  ASSERT_FALSE(r.empty());
  EXPECT_EQ(tets, before);
  EXPECT_NEAR(r.before, 0.6600, 1e-4);
  EXPECT_NEAR(r.after, 0.9271, 1e-4);
  ASSERT_EQ(r.new_tets.size(), 2u);
  apply(s, r);
  s.end();
  ASSERT_EQ(tets.size(), 2u);
  for (const Tet& t : tets) {
    EXPECT_TRUE(has(t, 0) && has(t, 1) && has(t, 2)) << "both tets stand on abc";
    EXPECT_NE(has(t, 3), has(t, 4));
  }
  EXPECT_NEAR(volume(P, tets), v0, 1e-15);
}

/// Five tets around the edge u = (0, 0, -L), w = (0, 0, L) (nodes 5, 6) over a regular
/// pentagon of radius 1 (nodes 0-4).
Points pentagon_ring(double L, std::vector<Tet>& tets) {
  Points P;
  for (int i = 0; i < 5; ++i) P.emplace_back(std::cos(2 * M_PI * i / 5), std::sin(2 * M_PI * i / 5), 0);
  P.emplace_back(0, 0, -L);
  P.emplace_back(0, 0, L);
  tets.clear();
  for (int i = 0; i < 5; ++i) tets.push_back(positive(P, {5, 6, i, (i + 1) % 5}));
  return P;
}

TEST(TetImprove, RemoveEdgeReplacesARingOfFiveBySixTets) {
  // L = 2: the long edge's five needles (0.320) give way to a fan of the pentagon joined to u
  // and w (0.616); at L = 0.5 the ring (0.988) is better than any fan (0.338)
  std::vector<Tet> tets;
  Points P = pentagon_ring(2.0, tets);
  const double v0 = volume(P, tets);
  TetSweep s(P, tets);
  const TetReplacement r = plan_remove_edge(s, 5, 6);
  ASSERT_FALSE(r.empty());
  EXPECT_NEAR(r.before, 0.3201, 1e-4);
  EXPECT_NEAR(r.after, 0.6163, 1e-4);
  apply(s, r);
  s.end();
  ASSERT_EQ(tets.size(), 6u);
  for (const Tet& t : tets) EXPECT_FALSE(has(t, 5) && has(t, 6)) << "the edge uw is gone";
  EXPECT_NEAR(volume(P, tets), v0, 1e-14);
  std::vector<Tet> fat;
  Points Q = pentagon_ring(0.5, fat);
  TetSweep q(Q, fat);
  EXPECT_TRUE(plan_remove_edge(q, 5, 6).empty());
}

TEST(TetImprove, LockedNodesAndTouchedTetsAreLeftAlone) {
  std::vector<Tet> tets;
  Points P = pentagon_ring(2.0, tets);
  {
    TetSweep s(P, tets);
    s.locked[2] = 1;  // a ring node changed earlier in the sweep: its star is stale
    EXPECT_TRUE(plan_remove_edge(s, 5, 6).empty());
  }
  {
    TetSweep s(P, tets);
    s.touched[3] = 1;
    EXPECT_TRUE(plan_remove_edge(s, 5, 6).empty());
  }
  TetSweep s(P, tets);
  EXPECT_FALSE(plan_remove_edge(s, 5, 6).empty());
}

/// The octahedron of vertices ±e_i (nodes 0-5) as 8 tets around node 6 at x.
Points octahedron_star(const Vec3& x, std::vector<Tet>& tets) {
  Points P = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, x};
  tets.clear();
  for (int i : {0, 1})
    for (int j : {2, 3})
      for (int k : {4, 5}) tets.push_back(positive(P, {6, i, j, k}));
  return P;
}

/// The octahedron star with its centre node off the centre, at (0.3, 0.2, 0.1).
struct DisplacedStar {
  std::vector<Tet> tets;
  Points P = octahedron_star({0.3, 0.2, 0.1}, tets);
  const Points P0 = P;
  const Adjacency stars = node_stars(P.size(), tets);
};

TEST(TetImprove, SmoothNodeMovesToTheCentroidOfItsNeighbours) {
  // every octahedron vertex is in four of the eight tets: the centroid is the origin, where
  // each tet has radius ratio 0.7321
  DisplacedStar d;
  auto& [tets, P, P0, stars] = d;
  const NodeMove m = plan_smooth_node(P, tets, stars, 6);
  ASSERT_FALSE(m.empty());
  EXPECT_EQ(P, P0) << "the plan moved the node";
  EXPECT_LT(m.to.norm(), 1e-15);
  EXPECT_EQ(m.from, P0[6]);
  EXPECT_NEAR(m.after, 0.7321, 1e-4);
  EXPECT_LT(m.before, m.after - 0.1);
  apply(P, m);
  EXPECT_EQ(P[6], m.to);
  // at the centroid already: a move onto itself, the worst unchanged
  const NodeMove again = plan_smooth_node(P, tets, stars, 6);
  ASSERT_FALSE(again.empty());
  EXPECT_EQ(again.to, again.from);
  EXPECT_EQ(again.after, again.before);
}

TEST(TetImprove, SearchNodeClimbsTowardsTheBestPosition) {
  DisplacedStar d;
  auto& [tets, P, P0, stars] = d;
  const NodeMove m = plan_search_node(P, tets, stars, 6);
  ASSERT_FALSE(m.empty());
  EXPECT_EQ(P, P0);
  EXPECT_GT(m.after, m.before + 0.1);
  EXPECT_LT(m.to.norm(), 0.5 * m.from.norm()) << "towards the centre";
  apply(P, m);
  EXPECT_NEAR(worst(P, tets), m.after, 1e-15);
  // at the centre no step helps: by symmetry it is the best position
  P[6] = Vec3::Zero();
  EXPECT_TRUE(plan_search_node(P, tets, stars, 6).empty());
}

/// An octahedron (apexes (0, 0, ±1), nodes 4, 5) around a warped square a, c = (±1, 0, w),
/// b, d = (0, ±1, -w) (nodes 0-3) as five tets: the sliver abcd, the top pyramid split along
/// ac and the bottom one along bd.
Points warped_octahedron(double w, std::vector<Tet>& tets) {
  Points P = {{1, 0, w}, {0, 1, -w}, {-1, 0, w}, {0, -1, -w}, {0, 0, 1}, {0, 0, -1}};
  tets = {positive(P, {0, 1, 2, 3}), positive(P, {4, 0, 1, 2}), positive(P, {4, 0, 2, 3}), positive(P, {5, 0, 1, 3}),
          positive(P, {5, 1, 2, 3})};
  return P;
}

TEST(TetImprove, RefillCavityReplacesASliverByAStarFromItsCentre) {
  // w = 0.05: the sliver has radius ratio 0.149; the star of the eight faces from the origin
  // (the best point, by the symmetries x -> -x and y -> -y) has 0.7296
  std::vector<Tet> tets;
  Points P = warped_octahedron(0.05, tets);
  const std::vector<Tet> before = tets;
  const Points P0 = P;
  const double v0 = volume(P, tets);
  EXPECT_NEAR(worst(P, tets), 0.149, 1e-3);
  TetSweep s(P, tets);
  const CavityStar star = plan_refill_cavity(s, {4, 3, 2, 1, 0}, 0.4);
  ASSERT_FALSE(star.empty());
  EXPECT_EQ(P, P0) << "the plan left its point behind";
  EXPECT_EQ(tets, before);
  EXPECT_EQ(star.cavity, (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_EQ(star.faces.size(), 8u);
  EXPECT_LT(star.point.norm(), 1e-6);
  EXPECT_NEAR(star.gain, 0.7296 - worst(P, tets), 1e-3);
  apply(s, star);
  s.end();
  ASSERT_EQ(tets.size(), 8u);
  ASSERT_EQ(P.size(), 7u);
  for (const Tet& t : tets) EXPECT_TRUE(has(t, 6));
  EXPECT_NEAR(volume(P, tets), v0, 1e-14);
  EXPECT_NEAR(worst(P, tets), 0.7296, 1e-3);
  // a cavity already a star from its best point: nothing to gain
  std::vector<Tet> regular;
  Points Q = octahedron_star(Vec3::Zero(), regular);
  TetSweep q(Q, regular);
  EXPECT_TRUE(plan_refill_cavity(q, {0, 1, 2, 3, 4, 5, 6, 7}, 0.4).empty());
  // nor from tets this sweep has changed, or around nodes it has locked
  std::vector<Tet> again;
  Points W = warped_octahedron(0.05, again);
  TetSweep t(W, again);
  t.touched[0] = 1;
  EXPECT_TRUE(plan_refill_cavity(t, {0, 1, 2, 3, 4}, 0.4).empty());
  TetSweep u(W, again);
  u.locked[4] = 1;
  EXPECT_TRUE(plan_refill_cavity(u, {0, 1, 2, 3, 4}, 0.4).empty());
  TetSweep v(W, again);
  EXPECT_FALSE(plan_refill_cavity(v, {0, 1, 2, 3, 4}, 0.4).empty());
}

TEST(TetImprove, RemoveTetsBelowTakesOutFlatTetsAndSlivers) {
  // w = 0: the middle tet's four nodes lie on one plane (exactly flat); w = 1e-9: positive but
  // at radius ratio ~1e-9; w = 0.02: a sliver of radius ratio 0.06. Each goes with its
  // cavity re-filled, the volume kept, every tet positive.
  for (const double w : {0.0, 1e-9, 0.02}) {
    std::vector<Tet> tets;
    Points P = warped_octahedron(w, tets);
    double v0 = 0;
    for (const Tet& t : tets) v0 += (P[t[1]] - P[t[0]]).dot((P[t[2]] - P[t[0]]).cross(P[t[3]] - P[t[0]])) / 6;
    EXPECT_LT(worst(P, tets), 0.1) << w;
    EXPECT_EQ(remove_tets_below(P, tets, 0.1, 4), 1) << w;
    EXPECT_GT(worst(P, tets), 0.7) << w;
    EXPECT_NEAR(volume(P, tets), v0, 1e-14) << w;
    std::vector<Tet> scratch;
    const Points P0 = warped_octahedron(w, scratch);
    for (int i = 0; i < 6; ++i) EXPECT_EQ(P[i], P0[i]) << "a node moved";
  }
  // nothing below the floor: nothing changes
  std::vector<Tet> regular;
  Points Q = octahedron_star(Vec3::Zero(), regular);
  const std::vector<Tet> before = regular;
  EXPECT_EQ(remove_tets_below(Q, regular, 0.1, 4), 0);
  EXPECT_EQ(regular, before);
}

TEST(TetImprove, DriversSweepTheKernelsOverTheBadTets) {
  {  // flips: the two flat tets become three; two good ones stay
    Points P = bipyramid(0.3);
    std::vector<Tet> tets = two_tets(P);
    EXPECT_EQ(flip_bad_tets(P, tets, 0.55), 1);
    EXPECT_EQ(tets.size(), 3u);
    Points Q = bipyramid(1.0);
    std::vector<Tet> good = two_tets(Q);
    EXPECT_EQ(flip_bad_tets(Q, good, 0.5), 0);
    EXPECT_EQ(good.size(), 2u);
  }
  {  // node moves only from first_new on
    DisplacedStar d;
    auto& [tets, P, P0, stars] = d;
    smooth_nodes(P, tets, stars, 7, 1);
    search_nodes_of_bad_tets(P, tets, stars, 7, 0.9);
    EXPECT_EQ(P, P0);
    smooth_nodes(P, tets, stars, 6, 1);
    EXPECT_LT(P[6].norm(), 1e-15);
    P[6] = P0[6];
    search_nodes_of_bad_tets(P, tets, stars, 6, 0.9);
    EXPECT_LT(P[6].norm(), 0.5 * P0[6].norm());
  }
  {  // sliver insertion, and the whole improvement with no node allowed to move
    std::vector<Tet> tets;
    Points P = warped_octahedron(0.05, tets);
    EXPECT_EQ(insert_points_at_slivers(P, tets, 0.4), 1);
    EXPECT_EQ(tets.size(), 8u);
    Points Q = warped_octahedron(0.05, tets);
    const Points Q0 = Q;
    const double v0 = volume(Q, tets);
    improve_tets(Q, tets, 6, TetImproveParams());
    EXPECT_GT(worst(Q, tets), 0.7);
    EXPECT_NEAR(volume(Q, tets), v0, 1e-14);
    for (int i = 0; i < 6; ++i) EXPECT_EQ(Q[i], Q0[i]);
  }
}

TEST(TetImprove, PerturbNodeFindsABetterPlaceForTheNodeOfAFlatTet) {
  // node 6 at 0.02 below the octahedron's face x + y + z = 1 (over its centre): the tet on that
  // face is a flat cap; the plan (P as it was) moves the node inwards and lifts the worst
  DisplacedStar d;
  auto& [tets, P, P0, stars] = d;
  P[6] = Vec3::Constant((1.0 - 0.02 * std::sqrt(3.0)) / 3);
  const Points before = P;
  EXPECT_LT(worst(P, tets), 0.1);
  const NodeMove m = plan_perturb_node(P, tets, stars, 6);
  ASSERT_FALSE(m.empty());
  EXPECT_EQ(P, before) << "the plan moved the node";
  EXPECT_GT(m.after, 0.5);
  EXPECT_LT(m.to.norm(), 0.5 * m.from.norm()) << "towards the centre";
  apply(P, m);
  EXPECT_NEAR(worst(P, tets), m.after, 1e-15);
  // at the centre of the regular star every move lowers the worst tet
  P[6] = Vec3::Zero();
  EXPECT_TRUE(plan_perturb_node(P, tets, stars, 6).empty());
}

TEST(TetImprove, OptimiseNodeClimbsFromAFlatCapToNearlyTheBestPosition) {
  // node 6 at 0.02 under the centre of the face x + y + z = 1: the tet on it is a flat cap
  // (radius ratio < 0.1); the ascent of the worst tet leads it to near the centre, where all
  // eight tets have 0.7321 (the best position, by symmetry), every step positive
  DisplacedStar d;
  auto& [tets, P, P0, stars] = d;
  P[6] = Vec3::Constant((1.0 - 0.02 * std::sqrt(3.0)) / 3);
  const Points before = P;
  ASSERT_LT(worst(P, tets), 0.1);
  const NodeMove m = plan_optimise_node(P, tets, stars, 6);
  ASSERT_FALSE(m.empty());
  EXPECT_EQ(P, before) << "the plan moved the node";
  EXPECT_NEAR(m.before, worst(P, tets), 1e-15);
  EXPECT_GT(m.after, 0.7);
  EXPECT_LE(m.after, 0.7321 + 1e-4) << "above the best a position can give";
  EXPECT_LT(m.to.norm(), 0.2 * m.from.norm()) << "towards the centre";
  apply(P, m);
  EXPECT_NEAR(worst(P, tets), m.after, 1e-15);
  for (const Tet& t : tets)
    EXPECT_GT(predicates::orient3d(P[t[0]].data(), P[t[1]].data(), P[t[2]].data(), P[t[3]].data()), 0);
  // at the centre every tet is active and no direction raises them all: no move
  P[6] = Vec3::Zero();
  EXPECT_TRUE(plan_optimise_node(P, tets, stars, 6).empty());
}

/// The classic shapes of tets with a small radius ratio (nodes 0-3, w the small length):
/// flat cap (a node at height w over the centre of the opposite equilateral face), wedge (a
/// short edge of length w, the opposite edge long and skew to it), needle (an equilateral
/// base of circumradius w under an apex at distance 1) and sliver (four nodes near one circle,
/// no short edge: a square warped by ±w).
Points classic_bad_tet(const std::string& shape, double w) {
  const double s = std::sqrt(3.0) / 2;
  if (shape == "cap") return {{1, 0, 0}, {-0.5, s, 0}, {-0.5, -s, 0}, {0, 0, w}};
  if (shape == "wedge") return {{-0.5 * w, 0, 0}, {0.5 * w, 0, 0}, {0, 1, 0.3}, {0, -1, 0.3}};
  if (shape == "needle") return {{w, 0, 0}, {-0.5 * w, s * w, 0}, {-0.5 * w, -s * w, 0}, {0, 0, 1}};
  return {{1, 0, w}, {0, 1, -w}, {-1, 0, w}, {0, -1, -w}};
}

/// Bad tet 0-3 of P embedded in a small mesh: seen along z (the direction in which its
/// nodes spread least), its faces turned towards +z are joined to one apex over its centroid
/// and the others to one apex under it (nodes 4, 5, at `height` × its longest edge): the
/// bipyramid over its silhouette, conformal; every node on the mesh's boundary (none may move).
std::vector<Tet> embedded(Points& P, double height) {
  const Vec3 centre = (P[0] + P[1] + P[2] + P[3]) / 4;
  Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();
  double longest = 0;
  for (int i = 0; i < 4; ++i) {
    spread += (P[i] - centre) * (P[i] - centre).transpose();
    for (int j = 0; j < i; ++j) longest = std::max(longest, (P[i] - P[j]).norm());
  }
  const Vec3 z = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(spread).eigenvectors().col(0);
  P.push_back(centre + height * longest * z);
  P.push_back(centre - height * longest * z);
  std::vector<Tet> tets = {positive(P, {0, 1, 2, 3})};
  const Tet t = tets[0];
  for (const auto& o : kTetFace) {  // kTetFace turns a face out of its tet
    const Vec3 n = (P[t[o[1]]] - P[t[o[0]]]).cross(P[t[o[2]]] - P[t[o[0]]]);
    tets.push_back({t[o[0]], t[o[1]], t[o[2]], n.dot(z) > 0 ? 4 : 5});
  }
  return tets;
}

MatX4i rows_of(const std::vector<Tet>& tets) {
  MatX4i T(static_cast<long>(tets.size()), 4);
  for (size_t t = 0; t < tets.size(); ++t)
    T.row(static_cast<long>(t)) << tets[t][0], tets[t][1], tets[t][2], tets[t][3];
  return T;
}

/// Checks that `tets` on P are valid (every tet positive: exact orientation, none flat) and
/// conformal with `boundary` as their boundary, on the nodes they use (a refill may leave a
/// node unused; the fill's output drops those).
void expect_valid(const Points& P, const std::vector<Tet>& tets, const MatX3i& boundary, const std::string& what) {
  TetMesh m;
  m.V.resize(static_cast<long>(P.size()), 3);
  std::vector<int> renum(P.size(), -1);
  int used = 0;
  for (const Tet& t : tets)
    for (int x : t)
      if (renum[x] < 0) m.V.row(used) = P[x].transpose(), renum[x] = used++;
  m.V.conservativeResize(used, 3);
  m.T = rows_of(tets);
  for (long t = 0; t < m.T.rows(); ++t)
    for (int k = 0; k < 4; ++k) m.T(t, k) = renum[m.T(t, k)];
  m.F = boundary;
  for (long t = 0; t < m.F.rows(); ++t)
    for (int k = 0; k < 3; ++k) m.F(t, k) = renum[m.F(t, k)];
  m.domain = VecXi::Zero(m.T.rows());
  m.face = VecXi::Ones(m.F.rows());
  const ConformityReport c = check_conformity(m);
  EXPECT_EQ(c.inverted_tets + c.flat_tets + c.overshared_faces + c.duplicate_nodes, 0) << what;
  EXPECT_EQ(c.boundary_not_in_F + c.F_not_boundary + c.open_boundary_edges, 0) << what << ": the boundary changed";
}

TEST(TetImprove, RemoveSliversTakesOutTheClassicBadTetsKeepingTheMeshValid) {
  // boundary-locked: the cap and the sliver embedded with every node fixed (edge removal,
  // flips and refills take them out)
  for (const std::string shape : {"cap", "sliver"}) {
    Points P = classic_bad_tet(shape, 0.03);
    std::vector<Tet> tets = embedded(P, 0.6);
    const Points P0 = P;
    const double v0 = volume(P, tets);
    ASSERT_LT(worst(P, tets), 0.1) << shape;
    const MatX3i boundary = boundary_triangles(rows_of(tets));
    EXPECT_EQ(remove_slivers(P, tets, static_cast<int>(P.size()), 0.1, 4), 0) << shape;
    EXPECT_GE(worst(P, tets), 0.1) << shape;
    for (size_t i = 0; i < P0.size(); ++i) EXPECT_EQ(P[i], P0[i]) << shape << ": a node moved";
    EXPECT_NEAR(volume(P, tets), v0, 1e-12 * v0) << shape;
    expect_valid(P, tets, boundary, shape);
  }
  // with a free node: the octahedron star with its centre 0.03 from vertex 0 (the tets on
  // that vertex are wedges: a short edge, the opposite one long) and 0.02 under the centre of
  // a face (a flat cap); perturbation and compass search move the node away
  for (const Vec3& x : std::vector<Vec3>{Vec3(0.97, 0, 0), Vec3::Constant((1.0 - 0.02 * std::sqrt(3.0)) / 3)}) {
    std::vector<Tet> tets;
    Points P = octahedron_star(x, tets);
    const double v0 = volume(P, tets);
    ASSERT_LT(worst(P, tets), 0.1);
    const MatX3i boundary = boundary_triangles(rows_of(tets));
    EXPECT_EQ(remove_slivers(P, tets, 6, 0.1, 4), 0);
    EXPECT_GE(worst(P, tets), 0.1);
    EXPECT_NEAR(volume(P, tets), v0, 1e-12);
    expect_valid(P, tets, boundary, "free node");
  }
  // nothing below the floor: nothing changes
  std::vector<Tet> regular;
  Points Q = octahedron_star(Vec3::Zero(), regular);
  const std::vector<Tet> before = regular;
  const Points Q0 = Q;
  EXPECT_EQ(remove_slivers(Q, regular, 6, 0.1, 4), 0);
  EXPECT_EQ(regular, before);
  EXPECT_EQ(Q, Q0);
}

TEST(TetImprove, ShapeFloorLiftsTheTetsBelowPointTwoOfTheFillAtAFilletCorner) {
  // NIST 1's fill at one fillet corner (tests/data/slivers/README.md): 1198 tets, 238 of them
  // between 0.1 and 0.2, the boundary nodes (the part's faces and the cut) first. The whole
  // improvement again without the shape floor still leaves 56 below 0.2 (measured), with it 2
  // (measured); the worst never drops, the boundary and the volume stay
  const TetMesh cut = io::read_msh(std::string(TOPOPT_TEST_DATA) + "/slivers/nist1_corner_fill.msh");
  Points P0(static_cast<size_t>(cut.V.rows()));
  for (long i = 0; i < cut.V.rows(); ++i) P0[i] = cut.V.row(i).transpose();
  std::vector<Tet> tets0(static_cast<size_t>(cut.T.rows()));
  for (long t = 0; t < cut.T.rows(); ++t) tets0[t] = positive(P0, {cut.T(t, 0), cut.T(t, 1), cut.T(t, 2), cut.T(t, 3)});
  const int fixed = cut.F.maxCoeff() + 1;  // the nodes of the boundary are 0 .. fixed - 1
  ASSERT_EQ(fixed, 289);
  auto below = [](const Points& P, const std::vector<Tet>& tets, double floor) {
    return std::count_if(tets.begin(), tets.end(), [&](const Tet& t) { return rho(P, t) < floor; });
  };
  const double worst0 = worst(P0, tets0), v0 = volume(P0, tets0);
  ASSERT_EQ(below(P0, tets0, 0.2), 238);
  ASSERT_GE(worst0, 0.1);

  TetImproveParams without;
  without.shape_floor = 0;
  Points P = P0;
  std::vector<Tet> tets = tets0;
  improve_tets(P, tets, fixed, without);
  EXPECT_GE(below(P, tets, 0.2), 40) << "the fixture no longer shows what the shape floor is for";

  P = P0, tets = tets0;
  improve_tets(P, tets, fixed, TetImproveParams());
  EXPECT_LE(below(P, tets, 0.2), 10);
  EXPECT_EQ(below(P, tets, 0.1), 0);
  EXPECT_GE(worst(P, tets), worst0);
  EXPECT_NEAR(volume(P, tets), v0, 1e-9 * v0);
  for (int i = 0; i < fixed; ++i) EXPECT_EQ(P[i], P0[i]) << "boundary node " << i << " moved";
  expect_valid(P, tets, cut.F, "the corner's fill");
}

TEST(TetImprove, RemoveTetsBelowTakesOutAFlatTetOnTheChordsOfACurvedFace) {
  // a convex boundary bent along the ridge a-c: boundary triangles abc and acd, with b and d
  // `drop` below the ridge; the tet abcd between them (both its faces on the boundary, all four
  // nodes on the surface: the flat tet on a curved face's chords) is a sliver; the tets on its
  // inner faces abd and bcd reach the apex e below. Every node is on the boundary and may not
  // move: only a Steiner point inside (on the inward normal of a boundary face, or in a
  // cavity) can take the sliver out, keeping the boundary, the volume and every tet positive.
  for (const double drop : {0.02, 0.005, 1e-4}) {
    Points P = {{0, 0, 0}, {1, 0, -drop}, {1, 1, 0}, {0, 1, -drop}, {0.5, 0.5, -0.8}};
    std::vector<Tet> tets = {positive(P, {0, 1, 2, 3}), positive(P, {0, 1, 3, 4}), positive(P, {1, 2, 3, 4})};
    const Points P0 = P;
    const double v0 = volume(P, tets);
    ASSERT_LT(worst(P, tets), 0.1) << drop;
    const MatX3i boundary = boundary_triangles(rows_of(tets));
    ASSERT_EQ(boundary.rows(), 6) << drop;
    EXPECT_GE(remove_tets_below(P, tets, 0.1, 4), 1) << drop;
    EXPECT_GE(worst(P, tets), 0.1) << drop;
    for (size_t i = 0; i < P0.size(); ++i) EXPECT_EQ(P[i], P0[i]) << drop << ": a boundary node moved";
    EXPECT_NEAR(volume(P, tets), v0, 1e-12) << drop;
    expect_valid(P, tets, boundary, "ridge");
  }
}

/// A sandwich: the ring P[0..n-1] (n = P.size() - 2) triangulated as the fan from node 0, each
/// triangle joined to u = node n (above it) and to w = node n + 1 (below): 2(n - 2) tets, every
/// node on their boundary (none may move).
std::vector<Tet> sandwich(const Points& P) {
  const int n = static_cast<int>(P.size()) - 2;
  std::vector<Tet> tets;
  for (int j = 1; j + 1 < n; ++j) tets.push_back(positive(P, {0, j, j + 1, n})), tets.push_back(positive(P, {0, j, j + 1, n + 1}));
  return tets;
}

/// A sandwich of three faces with a sliver of boundary nodes: a regular pentagon (circumradius
/// 1) with its nodes at heights -0.5, 0.5, -0.5, 0, 0, u = (0, 0, 1), w = (0, 0, -1); the tet on
/// (0, 1, 2) and w is a sliver (radius ratio 0.0063, worked out numerically). The edge uw with
/// one tet per pentagon edge is good (worst 0.759).
Points pentagon_sandwich(std::vector<Tet>& tets) {
  const double z[5] = {-0.5, 0.5, -0.5, 0, 0};
  Points P;
  for (int i = 0; i < 5; ++i) P.push_back({std::cos(2 * M_PI * i / 5), std::sin(2 * M_PI * i / 5), z[i]});
  P.push_back({0, 0, 1});
  P.push_back({0, 0, -1});
  tets = sandwich(P);
  return P;
}

TEST(TetImprove, RemoveFacesReplacesASandwichOfThreeFacesByTheEdgeBetweenItsApexes) {
  std::vector<Tet> tets;
  Points P = pentagon_sandwich(tets);
  const double v0 = volume(P, tets);
  ASSERT_LT(worst(P, tets), 0.01);
  const MatX3i boundary = boundary_triangles(rows_of(tets));
  ASSERT_EQ(boundary.rows(), 10);
  // from the sliver (tet 1: (0, 1, 2) and w), across its face (0, 1, 2) to u
  const int face = static_cast<int>(std::find(tets[1].begin(), tets[1].end(), 6) - tets[1].begin());
  TetSweep s(P, tets);
  const TetReplacement r = plan_remove_faces(s, 1, face);
  ASSERT_FALSE(r.empty());
  EXPECT_EQ(r.old_tets.size(), 6u) << "all three faces";
  ASSERT_EQ(r.new_tets.size(), 5u) << "one tet per edge of the pentagon";
  for (const Tet& t : r.new_tets) EXPECT_TRUE(has(t, 5) && has(t, 6)) << "around the new edge uw";
  EXPECT_NEAR(r.after, 0.759, 1e-3);
  EXPECT_EQ(s.tets, tets) << "the plan changed the tets";
  apply(s, r);
  s.end();
  EXPECT_EQ(tets.size(), 5u);
  EXPECT_NEAR(worst(P, tets), 0.759, 1e-3);
  EXPECT_NEAR(volume(P, tets), v0, 1e-12 * v0);
  expect_valid(P, tets, boundary, "pentagon");
  // a touched tet or a locked node: no plan
  std::vector<Tet> again;
  Points Q = pentagon_sandwich(again);
  TetSweep q(Q, again);
  q.locked[3] = 1;
  const TetReplacement partial = plan_remove_faces(q, 1, face);
  EXPECT_TRUE(partial.empty() || partial.old_tets.size() < 6u) << "node 3 is locked: its faces stay";
}

TEST(TetImprove, RemoveEdgeOptimalIsAtLeastTheBestFanOnEveryRing) {
  // rings of 4 to 9 nodes around a long edge (its tets are needles: replacing them helps),
  // jittered in angle and radius: the best of all triangulations (dynamic programming) is never
  // worse than the best fan, and each is a valid replacement
  std::srand(7);
  auto jitter = [] { return 0.3 * (std::rand() / double(RAND_MAX) - 0.5); };
  int better = 0;
  for (int k = 4; k <= 9; ++k)
    for (int trial = 0; trial < 20; ++trial) {
      Points P{{jitter(), jitter(), -1.5}, {jitter(), jitter(), 1.5}};
      for (int i = 0; i < k; ++i) {
        const double a = 2 * M_PI * (i + jitter()) / k, r = 1 + 2.5 * jitter();
        P.push_back({r * std::cos(a), r * std::sin(a), jitter()});
      }
      std::vector<Tet> tets;
      for (int i = 0; i < k; ++i) tets.push_back(positive(P, {0, 1, 2 + i, 2 + (i + 1) % k}));
      const double v0 = volume(P, tets);
      TetSweep s(P, tets);
      const TetReplacement fan = plan_remove_edge(s, 0, 1);
      const TetReplacement best = plan_remove_edge(s, 0, 1, true);
      if (k <= 7 && !fan.empty()) {
        ASSERT_FALSE(best.empty());
        EXPECT_GE(best.after, fan.after - 1e-15);
        better += best.after > fan.after + 1e-9;
      }
      if (best.empty()) continue;
      EXPECT_EQ(best.new_tets.size(), static_cast<size_t>(2 * (k - 2)));
      std::vector<Tet> after = best.new_tets;
      EXPECT_NEAR(volume(P, after), v0, 1e-12 * v0) << k;
      EXPECT_NEAR(worst(P, after), best.after, 1e-15);
      const MatX3i boundary = boundary_triangles(rows_of(tets));
      expect_valid(P, after, boundary, "ring of " + std::to_string(k));
    }
  EXPECT_GT(better, 0) << "on some ring of 6 or 7 a triangulation that is no fan is better";
}

TEST(TetImprove, RemoveSliversMendsASliverOfBoundaryNodesThatNoPointNorFlipOfTwoOrThreeTetsTakesOut) {
  // a sandwich of four faces on a warped hexagon (found by a random search over sandwiches for
  // one that the sliver removal before the wide reconnections could not mend; coordinates
  // rounded to 0.01): worst radius ratio 0.033, every node on the boundary
  Points P = {{0.01, 0.63, 0.01},  {-0.70, 0.18, -0.25}, {-0.73, -0.91, -0.23}, {0.84, -1.12, -0.40},
              {0.89, -0.91, 0.46}, {1.23, -0.85, 0.19},  {0.20, -0.06, 0.49},   {0.24, 0.15, -1.10}};
  std::vector<Tet> tets = sandwich(P);
  ASSERT_LT(worst(P, tets), 0.05);
  {  // what the sliver removal had before the wide reconnections leaves the sliver
    std::vector<Tet> old_way = tets;
    Points Q = P;
    flip_bad_tets(Q, old_way, 0.1, true);
    remove_tets_below(Q, old_way, 0.1, 4);
    flip_bad_tets(Q, old_way, 0.1, true);
    EXPECT_LT(worst(Q, old_way), 0.1);
  }
  const Points P0 = P;
  const double v0 = volume(P, tets);
  const MatX3i boundary = boundary_triangles(rows_of(tets));
  EXPECT_EQ(remove_slivers(P, tets, static_cast<int>(P.size()), 0.1, 4), 0);
  EXPECT_GE(worst(P, tets), 0.1);
  for (size_t i = 0; i < P0.size(); ++i) EXPECT_EQ(P[i], P0[i]) << "a boundary node moved";
  EXPECT_NEAR(volume(P, tets), v0, 1e-12 * v0);
  expect_valid(P, tets, boundary, "hexagon");
}

}  // namespace
}  // namespace topopt::mesh

