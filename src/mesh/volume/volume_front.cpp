// 3D advancing front: the driver of named steps (see volume_front.h).
#include "mesh/volume/volume_front.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <queue>
#include <sstream>
#include <unordered_map>
#include <vector>

#include "common/cpu_time.h"
#include "common/error.h"
#include "common/face_key.h"
#include "mesh/core/predicates.h"
#include "mesh/core/tet_quality.h"
#include "mesh/volume/background_size.h"
#include "mesh/volume/delaunay_bulk.h"
#include "mesh/volume/front_cavities.h"
#include "mesh/volume/tet_front.h"
#include "mesh/volume/tet_improve.h"

namespace topopt::mesh {
namespace {

using Vec3 = Eigen::Vector3d;
using predicates::orient3d;

/// Without a size, the size grows from the boundary's edge lengths by this per unit distance
/// (the surface mesher's default gradation, 1.3).
constexpr double kDefaultGrowth = 0.3;
/// The front gives up past this many times the tets its size asks for (expected_tets).
constexpr double kBudgetFactor = 10.0;
/// The bulk is dropped when its tetrahedralisation lacks more than this share of the boundary.
constexpr double kMaxMissingShare = 0.02;
/// The front's rounds re-meshing around a stuck region on a Delaunay bulk re-make at most this
/// share of the bulk's tets in all before the bulk is given up (FrontFill::bulk_round_pays).
constexpr double kMaxBulkRemeshShare = 0.05;
/// A front face weighs at most this many of the front nodes nearest its ideal point.
constexpr size_t kMaxNodeCandidates = 40;
/// Fronts left with fewer faces than this are closed cavity by cavity (front_cavities.h).
constexpr long kSmallFront = 400;
/// Per widening pass (the pass number plus the round, at most 4): the radius ratio a new tet
/// must reach, and how far from the ideal point front nodes are weighed (× the size).
constexpr double kMinQuality[] = {-1, 0.1, 0.02, 1e-4, 0};  // [0]: VolumeFillParams::min_quality
constexpr double kReach[] = {1.0, 1.6, 2.5, 4.0, 6.0};
/// The height of the regular tet over its base, per unit edge.
const double kSqrt23 = std::sqrt(2.0 / 3.0);

/// The finest cell of the front's grid (the shortest boundary edge, or the mean if shorter, and
/// never degenerate) and the corner of the boundary's box.
void front_grid(const std::vector<Vec3>& P, const MatX3i& F, double& cell, Vec3& lo) {
  double mean_edge = 0, min_edge = 1e300;
  lo = P[F(0, 0)];
  Vec3 hi = lo;
  for (long t = 0; t < F.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      const double l = (P[F(t, k)] - P[F(t, (k + 1) % 3)]).norm();
      mean_edge += l;
      if (l > 0) min_edge = std::min(min_edge, l);
      lo = lo.cwiseMin(P[F(t, k)]), hi = hi.cwiseMax(P[F(t, k)]);
    }
  mean_edge /= 3.0 * F.rows();
  cell = std::max(std::min(min_edge, mean_edge), 1e-9 * (hi - lo).norm());
}

/// The front could not finish a fill that started from a Delaunay bulk (its holes did not
/// close, even re-meshed around locally while that paid, or the front ran past its tet budget
/// around them): fill_volume retries the region by the front alone. Any other failure (a fill
/// by the front alone, nothing to fill) is final.
class BulkFillFailed : public Error {
 public:
  explicit BulkFillFailed(const std::string& message) : Error(ErrorCode::MeshingFailed, message) {}
};

/// The fill of one region: its boundary F (outward) around the existing tets T0, optionally
/// a Delaunay bulk first, then the front's rounds. run() returns the new tets; P gains the
/// new nodes.
class FrontFill {
 public:
  FrontFill(std::vector<Vec3>& P, const MatX3i& F, const MatX4i& T0, const VolumeFillParams& params, long budget,
            const Progress& progress, double cell, const Vec3& origin)
      : P_(P), F_(F), T0_(T0), params_(params), budget_(budget), progress_(progress), front_(P, cell, origin) {}

  /// Seeds the front, then rounds: advance (with widening passes), close what is left as
  /// cavities from single points, and if a stuck region remains, reopen the new tets around
  /// it and advance again (on a Delaunay bulk while that pays: bulk_round_pays). Throws
  /// Error(MeshingFailed) when the front does not close, BulkFillFailed when it started from a
  /// Delaunay bulk.
  std::vector<Tet> run() {
    try {
      return fill();
    } catch (const BulkFillFailed&) {
      throw;
    } catch (const Error& e) {
      if (e.code() != ErrorCode::MeshingFailed || bulk_tets_ == 0) throw;
      throw BulkFillFailed(e.what());
    }
  }

 private:
  using Item = std::pair<double, int>;  ///< (face size, face)

  std::vector<Tet> fill() {
    seed();
    requeue();
    std::vector<long> left;  // live front faces after each round
    for (int round = 0; round < 10 && front_.size() > 0; ++round) {
      if (round > 0 && bulk_tets_ > 0 && !bulk_round_pays(left))  // fill_volume goes without the bulk
        throw BulkFillFailed("the front could not close the holes of the Delaunay bulk (" +
                             std::to_string(front_.size()) + " front faces left after " + std::to_string(round - 1) +
                             " rounds of re-meshing around them, " + std::to_string(remeshed_) + " tets re-meshed)");
      if (round > 0) reopen_stuck_region(round);
      advance(round);
      if (front_.size() > 0 && front_.size() < kSmallFront) close_cavities(front_, P_, tets_, progress_);
      left.push_back(front_.size());
    }
    if (front_.size() > 0) fail_unclosed();
    tets_.erase(std::remove_if(tets_.begin(), tets_.end(), [](const Tet& t) { return t[0] < 0; }), tets_.end());
    return std::move(tets_);
  }

  /// The tets of the Delaunay bulk, where its tetrahedralisation holds the boundary, and the
  /// initial front: the boundary triangles no tet covers, reversed (normals into the region),
  /// then the free faces of the existing and the bulk's tets (outward from them).
  void seed() {
    std::unordered_map<FaceKey, int, FaceKeyHash> covered;  // faces of existing tets, free faces of bulk tets
    for (long t = 0; t < T0_.rows(); ++t)
      for (const auto& f : kTetFace) covered[face_key(T0_(t, f[0]), T0_(t, f[1]), T0_(t, f[2]))]++;
    std::unordered_map<FaceKey, char, FaceKeyHash> boundary;
    for (long t = 0; t < F_.rows(); ++t) boundary[face_key(F_(t, 0), F_(t, 1), F_(t, 2))] = 1;
    auto free_face = [&](int a, int b, int c) {
      const FaceKey k = face_key(a, b, c);
      return covered[k] == 1 && !boundary.count(k);
    };
    std::vector<Tri> bulk_free;
    if (params_.delaunay_bulk) bulk_free = fill_bulk(covered, free_face);
    for (long t = 0; t < F_.rows(); ++t)
      if (!covered.count(face_key(F_(t, 0), F_(t, 1), F_(t, 2)))) front_.add_face(F_(t, 0), F_(t, 2), F_(t, 1));
    for (long t = 0; t < T0_.rows(); ++t)
      for (const auto& f : kTetFace)
        if (free_face(T0_(t, f[0]), T0_(t, f[1]), T0_(t, f[2])))
          front_.add_face(T0_(t, f[0]), T0_(t, f[1]), T0_(t, f[2]));
    for (const Tri& f : bulk_free)
      if (free_face(f[0], f[1], f[2])) front_.add_face(f[0], f[1], f[2]);
    bulk_tets_ = static_cast<long>(tets_.size());
  }

  /// The bulk by Delaunay refinement of the region bounded by the boundary triangles no
  /// existing tet covers and the existing tets' free faces turned outwards; its tets become
  /// the fill's first, its free faces count as covered once more. Returns those free faces
  /// (none when it gave up).
  template <class FreeFace>
  std::vector<Tri> fill_bulk(std::unordered_map<FaceKey, int, FaceKeyHash>& covered, FreeFace&& free_face) {
    std::vector<Tri> region;
    for (long t = 0; t < F_.rows(); ++t)
      if (!covered.count(face_key(F_(t, 0), F_(t, 1), F_(t, 2)))) region.push_back({F_(t, 0), F_(t, 1), F_(t, 2)});
    for (long t = 0; t < T0_.rows(); ++t)
      for (const auto& f : kTetFace)
        if (free_face(T0_(t, f[0]), T0_(t, f[1]), T0_(t, f[2])))
          region.push_back({T0_(t, f[0]), T0_(t, f[2]), T0_(t, f[1])});
    DelaunayBulkParams dp;
    dp.size = params_.size;
    dp.max_tets = params_.max_tets;
    dp.max_missing_share = kMaxMissingShare;
    DelaunayBulkResult bulk = delaunay_bulk(P_, region, dp, progress_);
    if (static_cast<long>(bulk.tets.size()) >= params_.max_tets) throw_too_large();
    if (bulk.gave_up) {
      // a boundary far from Delaunay (e.g. the cocircular squares of a structured face): the
      // holes would be most of the volume, bounded by long flat tets: the front alone does better
      progress_.info("volume: the Delaunay tetrahedralisation lacks " + std::to_string(bulk.missing_triangles) +
                     " of " + std::to_string(region.size()) + " boundary triangles; the front fills it alone");
      return {};
    }
    tets_ = std::move(bulk.tets);
    for (const Tri& f : bulk.free_faces) covered[face_key(f[0], f[1], f[2])]++;
    progress_.info("volume: Delaunay bulk of " + std::to_string(tets_.size()) + " tets (" +
                   std::to_string(bulk.points) + " points, " + std::to_string(bulk.repaired) +
                   " with their cavity cut back to what they see, " + std::to_string(bulk.refused_unseen) +
                   " refused for it, " + std::to_string(bulk.refused_poor) +
                   " for a poor star); the front fills around " + std::to_string(bulk.missing_triangles) +
                   " boundary triangles it did not hold");
    return std::move(bulk.free_faces);  // only these can meet the boundary or T0's faces
  }

  /// One decision: may the next round re-mesh the stuck region locally on a Delaunay bulk
  /// (`left`: the live front faces after each round so far)? The alternative is fill_volume's
  /// retry by the front alone, which throws the bulk away and makes all its tets again, at
  /// several times the cost (NIST 2, 3 Dec 2026: 1.08 M tets, 12 faces stuck, the retry 165 s
  /// of a 234 s fill); a round re-makes only the tets around the stuck faces. So the rounds
  /// go on while the front shrinks (the first round always, then each must have left fewer
  /// faces than the one before it) and the tets they removed stay within kMaxBulkRemeshShare
  /// of the bulk's.
  bool bulk_round_pays(const std::vector<long>& left) const {
    const size_t n = left.size();
    const bool shrinks = n < 2 || left[n - 1] < left[n - 2];
    return shrinks && static_cast<double>(remeshed_) <= kMaxBulkRemeshShare * static_cast<double>(bulk_tets_);
  }

  /// The new tets around the stuck front's nodes, widened by one ring of nodes every third
  /// round, go back to the front.
  void reopen_stuck_region(int round) {
    const long stuck = front_.size();
    const Vec3 where = centroid(front_.any_alive());
    const Adjacency stars = node_stars(P_.size(), tets_);
    std::vector<char> in_region(P_.size(), 0);
    std::vector<int> region;
    for (int id : front_.alive_faces())
      for (int v : front_.face(id))
        if (!in_region[v]) in_region[v] = 1, region.push_back(v);
    for (int ring = 0; ring < (round - 1) / 3; ++ring) {
      const size_t n = region.size();
      for (size_t i = 0; i < n; ++i)
        for (int t : stars.row(region[i]))
          for (int x : tets_[t])
            if (!in_region[x]) in_region[x] = 1, region.push_back(x);
    }
    std::vector<int> doomed;
    for (int v : region)
      for (int t : stars.row(v)) doomed.push_back(t);
    std::sort(doomed.begin(), doomed.end());
    doomed.erase(std::unique(doomed.begin(), doomed.end()), doomed.end());
    for (int t : doomed) {
      front_.reopen(tets_[t]);
      tets_[t][0] = -1;
    }
    remeshed_ += static_cast<long>(doomed.size());
    std::ostringstream s;
    s << "advancing front: re-meshing around a stuck region near (" << where.x() << ", " << where.y() << ", "
      << where.z() << ") (" << stuck << " front faces left, " << doomed.size() << " tets removed)";
    progress_.info(s.str());
    requeue();
  }

  /// Widening passes over the queue, smallest face first: every face that fails stays on the
  /// front for the next pass, which weighs more nodes and accepts worse tets.
  void advance(int round) {
    for (int pass = 0; pass < std::max(1, params_.passes) + 1 && front_.size() > 0; ++pass) {
      const int ip = std::min(pass + round, 4);
      if (pass > 0 || round > 0) {
        progress_.info("advancing front: pass " + std::to_string(pass + 1) + " over " + std::to_string(front_.size()) +
                       " faces that failed");
        requeue();
      }
      while (!queue_.empty()) {
        const int f = queue_.top().second;
        queue_.pop();
        if (!front_.alive(f)) continue;
        check_limits(f);
        const int p = choose_point(f, ip, pass);
        if (p == -2) continue;
        for (int id : front_.close_with(f, p, tets_))
          if (id >= 0) queue_.push({face_size(id), id});
      }
      if (front_.size() == 0) break;
    }
  }

  /// The fourth node for front face f on pass `pass` (widening index ip): front nodes near
  /// the ideal point first (connecting closes the front; best quality first), then new points
  /// (the ideal one where no front node is already close to it; on wide passes also a lower
  /// one: a thin cavity, e.g. a twisted prism between the two sides of a thin wall, has room
  /// only close to the face). The first that the front admits is taken (a new point is
  /// appended to P); -2 when none is.
  int choose_point(int f, int ip, int pass) {
    const Tri face = front_.face(f);
    const int a = face[0], b = face[1], c = face[2];
    const Vec3 n = (P_[b] - P_[a]).cross(P_[c] - P_[a]);
    const double L = face_size(f) / 3.0;
    const Vec3 centre = (P_[a] + P_[b] + P_[c]) / 3.0;
    const double h = params_.size ? std::clamp(params_.size(centre.data()), 0.55 * L, 1.8 * L) : L;
    const Vec3 ideal = centre + n.normalized() * h * kSqrt23;
    const double qmin = ip == 0 ? params_.min_quality : kMinQuality[ip];
    const bool crowded = node_candidates(face, ideal, h, ip, qmin);
    new_points_.clear();
    if (!crowded || pass > 0) new_points_.push_back(ideal);
    if (ip >= 2) new_points_.push_back(centre + n.normalized() * h * kSqrt23 * 0.5);
    for (size_t k = 0; k < new_points_.size(); ++k) {
      P_.push_back(new_points_[k]);
      const double rho = radius_ratio(P_[a], P_[b], P_[c], P_.back());
      P_.pop_back();
      candidates_.push_back({-rho + 0.01 * static_cast<double>(k), -1 - static_cast<int>(k)});
    }
    std::sort(candidates_.begin(), candidates_.end());
    for (const auto& [score, q] : candidates_) {
      int p = q;
      if (q < 0) {
        P_.push_back(new_points_[-1 - q]);
        p = static_cast<int>(P_.size()) - 1;
      }
      if (front_.admits(a, b, c, p, qmin, f)) return p;
      if (q < 0) P_.pop_back();
    }
    return -2;
  }

  /// Fills candidates_ (cleared) with the nearest front nodes within reach of the ideal point,
  /// on the face's side and of radius ratio >= qmin, scored by quality and distance; returns
  /// whether one of them is closer than 0.7 h to the ideal point (no new point is needed there).
  bool node_candidates(const Tri& face, const Vec3& ideal, double h, int ip, double qmin) {
    const int a = face[0], b = face[1], c = face[2];
    candidates_.clear();
    const double r = kReach[ip] * h;
    front_.nodes_near(ideal - Vec3::Constant(r), ideal + Vec3::Constant(r), near_nodes_);
    // the nearest front nodes only (a large face facing a finely meshed region would
    // otherwise weigh thousands of them)
    near_by_distance_.clear();
    for (int q : near_nodes_) {
      if (q == a || q == b || q == c) continue;
      const double d = (P_[q] - ideal).norm();
      if (d <= r) near_by_distance_.push_back({d, q});
    }
    if (near_by_distance_.size() > kMaxNodeCandidates) {
      std::nth_element(near_by_distance_.begin(), near_by_distance_.begin() + kMaxNodeCandidates,
                       near_by_distance_.end());
      near_by_distance_.resize(kMaxNodeCandidates);
    }
    bool crowded = false;
    for (const auto& [d, q] : near_by_distance_) {
      if (d < 0.7 * h) crowded = true;
      if (orient3d(P_[a].data(), P_[b].data(), P_[c].data(), P_[q].data()) <= 0) continue;
      const double rho = radius_ratio(P_[a], P_[b], P_[c], P_[q]);
      if (rho < qmin) continue;
      candidates_.push_back({-rho + 0.25 * d / h - 10.0, q});
    }
    return crowded;
  }

  /// Stops with TooLarge past max_tets, with MeshingFailed past the budget (a front whose
  /// faces keep shrinking instead of closing; f locates it); checks for cancellation.
  void check_limits(int f) {
    if (static_cast<long>(tets_.size()) > params_.max_tets) throw_too_large();
    if (budget_ > 0 && static_cast<long>(tets_.size()) > budget_) {
      const Vec3 c = centroid(f);
      std::ostringstream s;
      s << "the volume front made " << tets_.size() << " tets without closing, far more than the size asks for ("
        << budget_ << " at most): its faces keep shrinking, e.g. near (" << c.x() << ", " << c.y() << ", " << c.z()
        << "); a coarser or smoother surface mesh there may help";
      throw Error(ErrorCode::MeshingFailed, s.str());
    }
    // by faces taken, not tets made: a front whose faces keep failing makes none
    if (++taken_ % 256 == 0) progress_.check_cancel("volume meshing (advancing front)");
  }

  [[noreturn]] void throw_too_large() const {
    throw Error(ErrorCode::TooLarge, "the volume mesh exceeds " + std::to_string(params_.max_tets) + " tets");
  }

  [[noreturn]] void fail_unclosed() const {
    const Vec3 c = centroid(front_.any_alive());
    std::ostringstream s;
    s << "the volume mesh could not be closed: " << front_.size() << " front faces remain, e.g. near (" << c.x() << ", "
      << c.y() << ", " << c.z() << "); a finer or smoother surface mesh there may help";
    throw Error(ErrorCode::MeshingFailed, s.str());
  }

  Vec3 centroid(int f) const {
    const Tri& t = front_.face(f);
    return (P_[t[0]] + P_[t[1]] + P_[t[2]]) / 3.0;
  }
  double face_size(int id) const {  ///< the face's perimeter
    const Tri& f = front_.face(id);
    return (P_[f[0]] - P_[f[1]]).norm() + (P_[f[1]] - P_[f[2]]).norm() + (P_[f[2]] - P_[f[0]]).norm();
  }
  void requeue() {  ///< every live face into the queue (again)
    for (int id : front_.alive_faces()) queue_.push({face_size(id), id});
  }

  std::vector<Vec3>& P_;
  const MatX3i& F_;
  const MatX4i& T0_;
  const VolumeFillParams& params_;
  const long budget_;
  const Progress& progress_;
  TetFront front_;
  std::vector<Tet> tets_;
  long bulk_tets_ = 0;
  long remeshed_ = 0;  ///< tets removed by the rounds re-meshing around stuck regions
  long taken_ = 0;  ///< faces taken from the queue (cancellation checks)
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue_;
  std::vector<int> near_nodes_;
  std::vector<std::pair<double, int>> candidates_;        ///< (score, node; -1 - k = new_points_[k])
  std::vector<std::pair<double, int>> near_by_distance_;  ///< (distance to the ideal point, node)
  std::vector<Vec3> new_points_;
};

/// `progress` whose cancelled() also answers yes once this thread has used `seconds` of CPU
/// from now (<= 0: never); `expired` is set when that is why.
Progress within_cpu_budget(const Progress& progress, double seconds, std::shared_ptr<bool> expired) {
  if (seconds <= 0) return progress;
  Progress timed = progress;
  const double end = thread_cpu_seconds() + seconds;
  timed.cancelled = [progress, end, expired] {
    if (progress.cancelled && progress.cancelled()) return true;
    if (thread_cpu_seconds() > end) *expired = true;
    return *expired;
  };
  return timed;
}

/// The fill itself on nodes P (the input nodes, to which it appends): fill_volume retries
/// without the bulk when this fails with it. `budget`: the front stops with a named error
/// past this many tets, 0 for none.
std::vector<Tet> fill_tets(std::vector<Vec3>& P, const MatX3i& F, const MatX4i& T0, const VolumeFillParams& params,
                           long budget, const Progress& progress) {
  if (F.rows() == 0) throw Error(ErrorCode::MeshingFailed, "nothing to fill: the boundary has no triangles");
  double cell;
  Vec3 origin;
  front_grid(P, F, cell, origin);
  return FrontFill(P, F, T0, params, budget, progress, cell, origin).run();
}

/// The graded size when none is given: from the boundary's (and the existing tets') edge
/// lengths up to the longest of them, so that the front does not fill the whole region at
/// its finest edge.
std::function<double(const double*)> default_size(const MatX3d& V, const MatX3i& F, const MatX4i& T0) {
  MatX3i faces(F.rows() + 4 * T0.rows(), 3);
  faces.topRows(F.rows()) = F;
  for (long t = 0; t < T0.rows(); ++t)
    for (int k = 0; k < 4; ++k)
      faces.row(F.rows() + 4 * t + k) << T0(t, kTetFace[k][0]), T0(t, kTetFace[k][1]), T0(t, kTetFace[k][2]);
  const std::vector<double> spacing = node_spacing(V, faces);
  const double h = *std::max_element(spacing.begin(), spacing.end());
  auto background = std::make_shared<BackgroundSize>(V, faces, h, kDefaultGrowth);
  return [background](const double* x) { return background->at(x); };
}

/// No flat tet leaves the fill: the tets exactly flat or inverted (orient3d; the kernels make
/// none) or below kFlatRadiusRatio are taken out with their cavities re-filled
/// (remove_tets_below); throws Error(MeshingFailed) naming where one is left.
void remove_flat_tets(std::vector<Vec3>& P, std::vector<Tet>& tets, const Progress& progress) {
  auto flat = [&P](const Tet& t) {
    return orient3d(P[t[0]].data(), P[t[1]].data(), P[t[2]].data(), P[t[3]].data()) <= 0 ||
           radius_ratio(P[t[0]], P[t[1]], P[t[2]], P[t[3]]) < kFlatRadiusRatio;
  };
  if (std::none_of(tets.begin(), tets.end(), flat)) return;
  remove_tets_below(P, tets, kFlatRadiusRatio, 4, progress);
  const auto left = std::find_if(tets.begin(), tets.end(), flat);
  if (left == tets.end()) return;
  const Vec3 c = (P[(*left)[0]] + P[(*left)[1]] + P[(*left)[2]] + P[(*left)[3]]) / 4;
  std::ostringstream s;
  s << "the volume mesh holds a flat tet near (" << c.x() << ", " << c.y() << ", " << c.z()
    << ") that re-filling its cavity could not remove (" << std::count_if(tets.begin(), tets.end(), flat)
    << " such tets); a finer or smoother surface mesh there may help";
  throw Error(ErrorCode::MeshingFailed, s.str());
}

/// The input nodes as they were, then only the new nodes some tet uses (tets removed by the
/// re-meshing rounds leave theirs behind, and a later point may land on one), renumbered in
/// the order the tets first use them.
VolumeFillResult compact(long inputs, const std::vector<Vec3>& P, const std::vector<Tet>& tets) {
  std::vector<int> renum(P.size(), -1);
  int kept = static_cast<int>(inputs);
  for (int i = 0; i < kept; ++i) renum[i] = i;
  for (const Tet& t : tets)
    for (int x : t)
      if (renum[x] < 0) renum[x] = kept++;
  VolumeFillResult out;
  out.V.resize(kept, 3);
  for (size_t i = 0; i < P.size(); ++i)
    if (renum[i] >= 0) out.V.row(renum[i]) = P[i].transpose();
  out.T.resize(tets.size(), 4);
  for (size_t t = 0; t < tets.size(); ++t)
    out.T.row(t) << renum[tets[t][0]], renum[tets[t][1]], renum[tets[t][2]], renum[tets[t][3]];
  return out;
}

/// The warning of the retry by the front alone: why, and the budget it runs within (the
/// fill's own, `seconds` of CPU of which `used` are gone, and `budget` tets; <= 0: none).
std::string front_alone_warning(const std::string& why, double seconds, double used, long budget) {
  std::ostringstream s;
  s << "volume: the front could not finish the Delaunay bulk's fill (" << why
    << "); the region is filled again by the front alone, which is slower, within what is left of the fill's budget (";
  if (seconds > 0)
    s << static_cast<long>(std::ceil(std::max(0.0, seconds - used))) << " of " << static_cast<long>(std::ceil(seconds))
      << " s of computing";
  else
    s << "no time limit";
  s << ", " << (budget > 0 ? "at most " + std::to_string(budget) + " tets" : std::string("no tet budget")) << ")";
  return s.str();
}

/// The fill's steps within the budget of `timed` (within_cpu_budget, `seconds` of CPU from
/// now): the front (retried by the front alone, with a warning, when the front could not
/// finish the Delaunay bulk's fill), the improvement, the flat-tet removal. Returns the tets.
std::vector<Tet> fill_and_improve(std::vector<Vec3>& P, const MatX3d& V, const MatX3i& F, const MatX4i& T0,
                                  VolumeFillParams& params, long budget, double seconds, const Progress& progress) {
  const double cpu0 = thread_cpu_seconds();
  std::vector<Tet> tets;
  try {
    tets = fill_tets(P, F, T0, params, budget, progress);
  } catch (const BulkFillFailed& e) {
    // the bulk's holes left the front a region it could not close: the front alone, from
    // the boundary, is the method this engine was built on; the same budgets bound it
    progress.warn(front_alone_warning(e.what(), seconds, thread_cpu_seconds() - cpu0, budget));
    params.delaunay_bulk = false;
    P.resize(V.rows());
    tets = fill_tets(P, F, T0, params, budget, progress);
  }
  TetImproveParams ip;
  ip.flip_below = params.flip_below;
  ip.smoothing_iterations = params.smoothing_iterations;
  ip.quality_rounds = params.quality_rounds;
  ip.sliver_below = params.sliver_below;
  ip.sliver_floor = params.sliver_floor;
  improve_tets(P, tets, static_cast<int>(V.rows()), ip, progress);
  remove_flat_tets(P, tets, progress);
  return tets;
}

}  // namespace

double volume_fill_seconds(long tet_budget) { return 10.0 + static_cast<double>(tet_budget) / 4000.0; }

VolumeFillResult fill_volume(const MatX3d& V, const MatX3i& F, const MatX4i& T0, const VolumeFillParams& given,
                             const Progress& progress) {
  VolumeFillParams params = given;
  if (!params.size && F.rows() > 0) params.size = default_size(V, F, T0);
  // the front's budget: many times the tets its size asks for, and room for a fine boundary
  // (the grid resolves the region about as finely as its boundary: 8 cells per triangle, at
  // least 100 k, at most 1 M)
  const long cells = std::clamp(8 * static_cast<long>(F.rows()), 100'000L, 1'000'000L);
  const double expected = params.size ? expected_tets(V, F, params.size, cells) : 0.0;
  const long budget = expected > 0 ? static_cast<long>(kBudgetFactor * expected) + 30 * F.rows() + 100'000 : 0;
  progress.info("volume: the size asks for about " + std::to_string(static_cast<long>(expected)) + " tets");
  // one copy of the nodes in, one out: a fill only appends to them, so a retry starts from
  // the input nodes by dropping what the failed attempt appended
  std::vector<Vec3> P(V.rows());
  for (long i = 0; i < V.rows(); ++i) P[i] = V.row(i).transpose();
  const double seconds =
      params.cpu_seconds != 0 ? params.cpu_seconds : volume_fill_seconds(budget > 0 ? budget : 30 * F.rows() + 100'000);
  auto expired = std::make_shared<bool>(false);
  const Progress timed = within_cpu_budget(progress, seconds, expired);
  try {
    const std::vector<Tet> tets = fill_and_improve(P, V, F, T0, params, budget, seconds, timed);
    return compact(V.rows(), P, tets);
  } catch (const Error& e) {
    if (e.code() != ErrorCode::Cancelled || !*expired) throw;
    const std::string what = e.what();  // "cancelled during <stage>" (Progress::check_cancel)
    const size_t at = what.find("during ");
    std::ostringstream s;
    s << "the volume mesh did not finish within its budget of " << static_cast<long>(std::ceil(seconds))
      << " s of computing (for about " << static_cast<long>(expected) << " tets); it was stopped while "
      << (at == std::string::npos ? what : what.substr(at + 7))
      << (given.delaunay_bulk && !params.delaunay_bulk
              ? " (by the front alone, after the front could not finish the Delaunay bulk's fill)"
              : "")
      << "; a coarser or smoother surface mesh, or a larger size, may help";
    throw Error(ErrorCode::Timeout, s.str());
  }
}

}  // namespace topopt::mesh
