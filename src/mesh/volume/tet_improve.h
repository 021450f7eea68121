// Tet improvement after the volume fill: kernels that change a few tets or move one node, and
// the drivers that sweep them over the bad tets.
//
// Every kernel has a check-only mode: plan_<kernel>() says whether the change would improve
// the mesh and what it would be, and leaves the mesh as it is (an empty plan: no improving
// change); apply(plan) then makes exactly that change. Every orientation decision goes
// through mesh/core/predicates; quality is the radius ratio (tet_quality.h), and a change is
// kept only when it raises the worst radius ratio of the tets it touches (smoothing: when it
// does not lower it).
//
// Kernels: remove_edge (the k = 3..7 tets around an inner edge replaced by 2(k - 2) tets over
// a triangulation of their ring; on a ring of three it is the 3-2 flip), flip23 (the face of
// two tets replaced by the edge between their apexes), smooth_node (to the centroid of its
// neighbours), search_node (compass search for the position with the best worst tet around
// it), perturb_node (pattern search over many directions), optimise_node (steepest ascent of
// the worst tet around a node with a line search), refill_cavity (a cavity of tets re-filled as a star from one new
// point: sliver removal by point insertion, which also removes a tet with two faces on the boundary).
//
// Only tets in the given list are ever changed: the caller's fixed tets (the existing ones
// and the boundary) stay, because a face is flipped only between two listed tets, an edge only
// when listed tets close a ring around it, and a cavity's faces stay faces of its star.
#pragma once
#include <array>
#include <functional>
#include <vector>

#include "common/progress.h"
#include "common/types.h"
#include "mesh/volume/node_stars.h"

namespace topopt::mesh {

/// One sweep over tets being improved: the node stars as the sweep began (still right for the
/// tets it has not touched and around the nodes it has not locked) and what it has changed.
struct TetSweep {
  /// P: #P by 3 nodes (a refill appends its point); tets: #T tets (removed ones: t[0] < 0).
  TetSweep(std::vector<Eigen::Vector3d>& P, std::vector<Tet>& tets);
  std::vector<Eigen::Vector3d>& P;
  std::vector<Tet>& tets;
  const Adjacency stars;
  std::vector<char> touched;  ///< #T (grows): a tet rewritten, added or retired in this sweep
  std::vector<char> locked;   ///< #P at the start: a node of a changed tet; not used again
  std::vector<char> retired;  ///< per tet (sized by the first refill): removed by it, still readable
  std::vector<Tet> pending;   ///< tets a refill added, appended when the sweep ends
  /// Buffers the plans reuse from call to call (no state: only to spare allocations).
  struct Scratch {
    std::vector<int> tets, other, ring;
    std::vector<std::array<int, 2>> pairs;
    std::vector<char> used;
    std::vector<Tet> fan;
  };
  mutable Scratch scratch;

  /// The tets holding nodes u and w (and x, when x >= 0), by the star of u (ascending).
  void tets_with(int u, int w, int x, std::vector<int>& out) const;
  /// Ends the sweep: removed and retired tets leave the list (the others keep their order),
  /// pending ones are appended.
  void end();
};

/// A change of tets: new_tets[m] takes the slot of old_tets[m], the rest are appended (or,
/// with fewer new tets, the surplus slots are removed). Empty: no improving change.
struct TetReplacement {
  std::vector<int> old_tets;
  std::vector<Tet> new_tets;
  double before = 0, after = 0;  ///< the worst radius ratio of the old tets and of the new ones
  bool empty() const { return new_tets.empty(); }
};

/// Edge removal (check-only): the untouched tets around the inner edge (u, w) — a closed ring
/// of 3 to 7 of them, no node locked — replaced by the fan triangulation of their ring (from
/// the ring node that gives the best worst tet) joined to u and w, when every new tet is
/// positive and the worst radius ratio rises. A ring of three is the 3-2 flip. With `optimal`:
/// rings of up to kOptimalRing tets, triangulated by the best of ALL triangulations of the
/// ring (dynamic programming, Shewchuk's edge removal) instead of the best fan.
TetReplacement plan_remove_edge(const TetSweep& s, int u, int w, bool optimal = false);
/// The largest ring plan_remove_edge takes with `optimal`.
constexpr int kOptimalRing = 12;
/// 2-3 flip (check-only): face `face` (0..3, opposite that node) of untouched tet t, shared
/// with one other untouched tet, replaced by the edge joining the two apexes (which must not
/// exist yet and must cross the face's interior), no node locked, when the worst radius
/// ratio rises.
TetReplacement plan_flip23(const TetSweep& s, int t, int face);
/// Multi-face removal (check-only; Shewchuk's, the inverse of edge removal): u is the node of
/// untouched tet t opposite `face`, w the apex of the tet across it; the faces between u and w
/// (each with a tet to u and a tet to w, grown from `face` across the edge whose face gives the
/// best result, up to kSandwichFaces of them) are replaced by the new edge uw and one tet per
/// edge of their outline — 2m tets by m + 2 —, at the size that gives the best worst radius
/// ratio, when it rises, every new tet is positive and the volume is kept. m = 1 is the 2-3
/// flip. Takes out slivers whose nodes may not move and that no edge removal helps.
TetReplacement plan_remove_faces(const TetSweep& s, int t, int face);
/// The most faces plan_remove_faces removes at once.
constexpr int kSandwichFaces = 10;
/// Makes replacement r: the slots of its old tets are rewritten or removed, the extra tets
/// appended; all of them are touched and every node of the old tets is locked.
void apply(TetSweep& s, const TetReplacement& r);

/// A move of node v from `from` to `to`; empty when it would not help (or v has no tets).
struct NodeMove {
  int v = -1;
  Eigen::Vector3d from, to;
  double before = 0, after = 0;  ///< the worst radius ratio around v before and after
  bool empty() const { return v < 0; }
};
/// Smoothing (check-only): v to the centroid of the other nodes of its tets (each counted once
/// per tet), when every tet around stays positive and the worst radius ratio around does not
/// drop. stars: the current stars of tets.
NodeMove plan_smooth_node(std::vector<Eigen::Vector3d>& P, const std::vector<Tet>& tets, const Adjacency& stars, int v);
/// Compass search (check-only): steps of a tenth of v's mean edge along ±x, ±y, ±z while the
/// worst radius ratio around v rises (halved when no direction helps, 40 tries), every tet
/// staying positive; the best position found when it is better.
NodeMove plan_search_node(std::vector<Eigen::Vector3d>& P, const std::vector<Tet>& tets, const Adjacency& stars, int v);
/// What plan_pattern_search tries.
struct PatternSearchParams {
  std::vector<Eigen::Vector3d> directions;  ///< unit directions tried from the current position at every step
  int tries = 12;                           ///< steps; the step is halved after one that finds nothing better
  /// > 0: a position is taken only when no more tets of the ball are below this radius ratio
  /// than at the start (raising the worst alone can bring more of them below it), and a ball
  /// that does not start all positive is left as it is; 0: the worst tet alone decides.
  double floor = 0;
  /// Set: each point tried is first moved by it (e.g. onto the B-Rep face the node lies on);
  /// a point it returns false for is skipped. Empty: the points as they are.
  std::function<bool(Eigen::Vector3d&)> onto;
};
/// Pattern search (check-only) for node v: from v, steps of a quarter of its mean edge along
/// each of params.directions (moved by params.onto when given), the best point taken while it
/// raises the worst radius ratio of the tets `ball` (v's ball: indices into tets) with every one
/// of them positive (exact orientation) and, with params.floor, no more of them below it; the
/// step halved when none does, params.tries steps. Returns the best position found when it is
/// better. P is as it was on return. plan_perturb_node and the last sliver pass
/// (sliver_pass.h: directions in a plane, the projection onto a face, the floor) are this search.
NodeMove plan_pattern_search(std::vector<Eigen::Vector3d>& P, const std::vector<Tet>& tets, const Adjacency::Row& ball,
                             int v, const PatternSearchParams& params);
/// n unit vectors spread evenly over the sphere (a Fibonacci lattice).
std::vector<Eigen::Vector3d> sphere_directions(int n);
/// Perturbation (check-only), for a node the compass search left at a sliver: plan_pattern_search
/// over kPerturbDirections directions spread evenly over the sphere (sphere_directions),
/// 12 tries, the worst tet alone deciding. Its many directions find the moves that lift the
/// worst tet of a star where the compass's six do not (the perturbation of sliver nodes of
/// Tournois et al., with directions laid out instead of drawn).
NodeMove plan_perturb_node(std::vector<Eigen::Vector3d>& P, const std::vector<Tet>& tets, const Adjacency& stars,
                           int v);
/// Directions the perturbation tries per step.
constexpr int kPerturbDirections = 32;
/// Optimisation-based smoothing (check-only): steepest ascent of the worst radius ratio around
/// v. Each step takes the tets within kActiveBand of the worst (the active set), their
/// gradients in v's position by central differences, and tries as directions each gradient
/// and their normalised sum; along each, a line search from a fifth of v's mean edge, halved
/// up to 12 times, keeps the first step that raises the worst radius ratio with every tet
/// around positive (orient3d); the best direction's step is taken. Up to 30 steps, ending when
/// none helps. Returns the best position when it is better.
NodeMove plan_optimise_node(std::vector<Eigen::Vector3d>& P, const std::vector<Tet>& tets, const Adjacency& stars,
                            int v);
/// Tets within this radius ratio of the ball's worst are active in plan_optimise_node.
constexpr double kActiveBand = 0.02;
/// Makes move m (P[m.v] = m.to).
void apply(std::vector<Eigen::Vector3d>& P, const NodeMove& m);

/// A cavity re-filled as a star from one new point.
struct CavityStar {
  std::vector<int> cavity;  ///< its tets, ascending
  std::vector<Tri> faces;   ///< its boundary, each face turned out of the cavity
  Eigen::Vector3d point;    ///< the star's centre
  double gain = 0;          ///< worst radius ratio of the star minus the cavity's; > 0 improves
  bool empty() const { return faces.empty(); }
};
/// Refill (check-only): the untouched tets `cavity` (no node locked) as a star of its faces
/// from the point that maximises the star's worst radius ratio (a compass search from the
/// faces' centroid, steps of 0.15 of their mean edge), kept when that point sees every face
/// (the star tiles the cavity exactly) and the star has the cavity's volume (a cavity holding a
/// flat or inverted tet has overlapping faces: its star would cover part of it twice), the
/// star's worst tet beats the cavity's and it has no more tets below kSliverShare × bad than
/// the cavity had. P is as it was on return. start: where the search begins (default, null:
/// the faces' centroid).
CavityStar plan_refill_cavity(TetSweep& s, std::vector<int> cavity, double bad, const Eigen::Vector3d* start = nullptr);
/// Makes star c: its point is appended to P, its cavity retired (and its nodes locked), its
/// tets pending until the sweep ends.
void apply(TetSweep& s, const CavityStar& c);

/// A star may not leave more tets below this share of `bad` than its cavity had.
constexpr double kSliverShare = 0.25;
/// A Steiner point for a tet with a face on the boundary stands this share of the face's mean
/// edge above it, on its inward normal (remove_tets_below).
constexpr double kSteinerHeight = 0.6;
/// A Steiner point's conflict cavity (the tets whose circumsphere holds it, grown from the
/// sliver across faces) holds at most this many tets.
constexpr size_t kConflictTets = 48;

// ---- drivers

/// Sweeps of edge removal then 2-3 flips over the tets below `bad` (each tet changed at most
/// once per sweep, up to 4 sweeps while any flip happens). `best`: every edge removal and
/// 2-3 flip at a tet is planned and the one whose new worst radius ratio is highest is made;
/// otherwise the first improving one (edges, then faces). `wide`: plan_remove_edge's optimal
/// mode and plan_remove_faces in place of the 2-3 flip. Returns the number of changes.
long flip_bad_tets(std::vector<Eigen::Vector3d>& P, std::vector<Tet>& tets, double bad, bool best = false,
                   bool wide = false);
/// `iterations` sweeps of smooth_node over the nodes from first_new on.
void smooth_nodes(std::vector<Eigen::Vector3d>& P, const std::vector<Tet>& tets, const Adjacency& stars, int first_new,
                  int iterations);
/// search_node on the nodes from first_new on of the tets below `bad`, each node once, in the
/// order of the tets.
void search_nodes_of_bad_tets(std::vector<Eigen::Vector3d>& P, const std::vector<Tet>& tets, const Adjacency& stars,
                              int first_new, double bad);
/// Sliver removal by point insertion: each tet below `bad`, worst first, is taken out with the
/// best of its candidate cavities (the tets around each of its edges, it with its face
/// neighbours, and with one more layer of them) re-filled by refill_cavity; up to 3 sweeps.
/// Returns the number of cavities re-filled.
long insert_points_at_slivers(std::vector<Eigen::Vector3d>& P, std::vector<Tet>& tets, double bad);

/// The nodes from first_new on of the tets below `floor`, worst tet first, each node once:
/// moved by search_node, else by perturb_node, when that lifts the worst tet around it. With
/// `optimise`: moved to the best of search_node's, optimise_node's and (when those leave the
/// ball below floor) perturb_node's positions, then optimise_node again from there, when that
/// lifts the worst tet around it and leaves no more tets around it below floor (fewest first,
/// then the highest worst). Returns the number of nodes moved.
long perturb_sliver_nodes(std::vector<Eigen::Vector3d>& P, const std::vector<Tet>& tets, int first_new, double floor,
                          bool optimise = false);

/// The last pass at the tets still below `floor` (radius ratio; a flat tet has 0), worst first:
/// each is taken out with the best of wider cavities than insert_points_at_slivers tries —
/// those, the star of each of its nodes, the stars of both ends of each of its edges, three
/// layers of face neighbours, and the conflict cavities (tets whose circumsphere holds the
/// point, exact insphere) of its Steiner points: its circumcentre and, on each of its faces on
/// the boundary, a point kSteinerHeight of the face's edge inside — re-filled from one point
/// (refill_cavity, its search started at the Steiner point for those; with
/// bad = floor / kSliverShare: no more tets below floor than the cavity had); up to `sweeps`
/// sweeps while any cavity is re-filled, progress checked for cancellation between them.
/// Returns the number of cavities re-filled.
long remove_tets_below(std::vector<Eigen::Vector3d>& P, std::vector<Tet>& tets, double floor, int sweeps,
                       const Progress& progress = {});

/// Rounds at the tets below `floor` until none is left or a round removes none: the nodes
/// of the slivers perturbed (perturb_sliver_nodes, nodes from first_new on), edge removal and
/// 2-3 flips at them, and wider cavities re-filled (remove_tets_below, 2 sweeps; the points it
/// adds are the next round's to move); then, for the tets still below floor, the same rounds
/// with perturb_sliver_nodes' optimise and flip_bad_tets' best, then for what those leave the
/// same with flip_bad_tets' wide reconnections too (each phase up to `rounds`).
/// Returns the number of tets below floor left.
long remove_slivers(std::vector<Eigen::Vector3d>& P, std::vector<Tet>& tets, int first_new, double floor, int rounds,
                    const Progress& progress = {});

struct TetImproveParams {
  double flip_below = 0.55;      ///< tets below this radius ratio get edge removal and 2-3 flips (0: none)
  int smoothing_iterations = 1;  ///< smooth_node sweeps per round
  int quality_rounds = 3;        ///< rounds of flips, smoothing and compass search
  double sliver_below = 0.4;     ///< compass search at tets below this each round, then point insertion (0: none)
  /// Then tets below this get wider cavities (remove_tets_below, up to 4 sweeps), then rounds of
  /// perturbation of their nodes, flips and wider cavities (remove_slivers; 0: none).
  double sliver_floor = 0.1;
  int sliver_rounds = 4;  ///< at most this many rounds of remove_slivers
  /// Then the same rounds (remove_slivers, at most sliver_rounds) at this higher floor: the
  /// tets between sliver_floor and it are left by everything above (the compass search alone
  /// moves their nodes), and a fill that closed holes of the Delaunay bulk leaves many of them
  /// (NIST 1's fillet corners: 1 731 below 0.2, 750 of them without a boundary node). Every
  /// change lifts the worst tet it touches, so nothing falls below the worst there was
  /// (not above sliver_floor, e.g. 0: none).
  double shape_floor = 0.2;
};

/// The improvement after a fill: `quality_rounds` rounds of flips, smoothing of the nodes
/// from first_new on and compass search at the bad tets; then up to three rounds of sliver
/// insertion, each followed by flips and compass search; then remove_tets_below(sliver_floor)
/// and remove_slivers(sliver_floor, sliver_rounds), then remove_slivers(shape_floor, sliver_rounds).
/// Nodes below first_new never move. Checks progress for cancellation between rounds.
void improve_tets(std::vector<Eigen::Vector3d>& P, std::vector<Tet>& tets, int first_new,
                  const TetImproveParams& params, const Progress& progress = {});

}  // namespace topopt::mesh
