// Orbit tying of design elements (see tying.h).
#include "simp/controls/tying.h"

#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <numeric>
#include <sstream>
#include <unordered_map>

#include "common/error.h"
#include "common/number_text.h"

namespace topopt::simp {
namespace {

/// Union-find over the design elements.
class Classes {
 public:
  explicit Classes(long n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
  int find(int i) {
    while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
    return i;
  }
  void join(int a, int b) {
    a = find(a), b = find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }

 private:
  std::vector<int> parent_;
};

/// Integer cell of a coordinate for a grid of the given width, packed in one key.
long long cell_key(long long i, long long j, long long k) {
  return ((i + (1LL << 20)) << 42) | ((j + (1LL << 20)) << 21) | (k + (1LL << 20));
}

/// The design element whose centroid lies nearest to a point, within a distance: a hashed
/// grid of cells of that distance, searched in the 27 cells around the point.
class NearestCentroid {
 public:
  NearestCentroid(const Eigen::MatrixX3d& c, double width) : c_(c), w_(width) {
    for (long i = 0; i < c.rows(); ++i) cells_[key(c.row(i).transpose())].push_back(static_cast<int>(i));
  }
  /// The nearest element within the width of q, or -1.
  int find(const Eigen::Vector3d& q) const {
    const Eigen::Vector3d s = q / w_;
    const long long i0 = std::floor(s.x()), j0 = std::floor(s.y()), k0 = std::floor(s.z());
    int best = -1;
    double best_d2 = w_ * w_;
    for (long long i = i0 - 1; i <= i0 + 1; ++i)
      for (long long j = j0 - 1; j <= j0 + 1; ++j)
        for (long long k = k0 - 1; k <= k0 + 1; ++k) {
          const auto it = cells_.find(cell_key(i, j, k));
          if (it == cells_.end()) continue;
          for (int e : it->second) {
            const double d2 = (c_.row(e).transpose() - q).squaredNorm();
            if (d2 <= best_d2) best_d2 = d2, best = e;
          }
        }
    return best;
  }

 private:
  long long key(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d s = p / w_;
    return cell_key(std::floor(s.x()), std::floor(s.y()), std::floor(s.z()));
  }
  const Eigen::MatrixX3d& c_;
  double w_;
  std::unordered_map<long long, std::vector<int>> cells_;
};

/// Ties every element i for which `image` gives a point (true) to the element nearest that
/// point; returns the share of elements matched.
double tie_images(const Eigen::MatrixX3d& c, const NearestCentroid& nearest, Classes& classes,
                  const std::function<bool(const Eigen::Vector3d&, Eigen::Vector3d&)>& image) {
  long matched = 0;
  Eigen::Vector3d q;
  for (long i = 0; i < c.rows(); ++i) {
    if (!image(c.row(i).transpose(), q)) continue;
    const int j = nearest.find(q);
    if (j < 0) continue;
    classes.join(static_cast<int>(i), j);
    ++matched;
  }
  return c.rows() ? static_cast<double>(matched) / c.rows() : 0;
}

Eigen::Vector3d unit(const Eigen::Vector3d& v, const std::string& what) {
  const double n = v.norm();
  if (!(n > 1e-12) || !std::isfinite(n))
    throw Error(ErrorCode::InvalidParameter, what + " is zero or not finite: give a non-zero vector");
  return v / n;
}

std::string percent(double share) { return number_text(100 * share, 3) + " %"; }

/// A mirror plane or cyclic axis must map most of the design domain onto itself.
void require_symmetry(double share, const std::string& what) {
  if (share < 0.5)
    throw Error(ErrorCode::InvalidParameter,
                what + " maps only " + percent(share) +
                    " of the design domain onto itself: it is not a symmetry of the part; check its point and "
                    "direction (a plane or axis through the part, in mm of the model)");
}

}  // namespace

void cross_section_basis(const Eigen::Vector3d& d, Eigen::Vector3d& u, Eigen::Vector3d& v) {
  const Eigen::Vector3d a = std::abs(d.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  u = d.cross(a).normalized();
  v = d.cross(u);
}

Tying tie_design(const Eigen::MatrixX3d& c, const ControlsParams& params, double tolerance) {
  Classes classes(c.rows());
  const NearestCentroid nearest(c, tolerance);
  Tying out;
  std::ostringstream log;
  for (size_t m = 0; m < params.mirrors.size(); ++m) {
    const std::string what = "symmetry plane " + std::to_string(m + 1);
    const Eigen::Vector3d n = unit(params.mirrors[m].normal, what + ": its normal");
    const Eigen::Vector3d p0 = params.mirrors[m].point;
    out.matched.push_back(tie_images(c, nearest, classes, [&](const Eigen::Vector3d& p, Eigen::Vector3d& q) {
      q = p - 2 * (p - p0).dot(n) * n;
      return true;
    }));
    require_symmetry(out.matched.back(), what);
    log << what << " " << percent(out.matched.back()) << " matched; ";
  }
  for (size_t k = 0; k < params.cyclic.size(); ++k) {
    const CyclicRepetition& cy = params.cyclic[k];
    const std::string what = "cyclic repetition " + std::to_string(k + 1);
    if (cy.sectors < 2) throw Error(ErrorCode::InvalidParameter, what + ": give at least 2 sectors");
    const Eigen::Vector3d a = unit(cy.axis, what + ": its axis");
    const Eigen::Matrix3d R = Eigen::AngleAxisd(2 * M_PI / cy.sectors, a).toRotationMatrix();
    out.matched.push_back(tie_images(c, nearest, classes, [&](const Eigen::Vector3d& p, Eigen::Vector3d& q) {
      q = cy.point + R * (p - cy.point);
      return true;
    }));
    require_symmetry(out.matched.back(), what);
    log << what << " (" << cy.sectors << " sectors) " << percent(out.matched.back()) << " matched; ";
  }
  for (size_t k = 0; k < params.patterns.size(); ++k) {
    const LinearPattern& pat = params.patterns[k];
    const std::string what = "pattern " + std::to_string(k + 1);
    const Eigen::Vector3d d = unit(pat.direction, what + ": its direction");
    if (!(pat.pitch > 0) || pat.count < 2)
      throw Error(ErrorCode::InvalidParameter, what + ": give a pitch above 0 mm and a count of at least 2");
    const double start = (c * d).minCoeff();
    const double tied_end = start + (pat.count - 1) * pat.pitch;  // copies 1 … count-1 take the next one's image
    out.matched.push_back(tie_images(c, nearest, classes, [&](const Eigen::Vector3d& p, Eigen::Vector3d& q) {
      q = p + pat.pitch * d;
      return p.dot(d) < tied_end;
    }));
    if (out.matched.back() == 0)
      throw Error(ErrorCode::InvalidParameter,
                  what +
                      ": no design element has a copy one pitch further: the pitch is longer than the part along "
                      "the direction; give a shorter pitch or another direction");
    log << what << " (" << pat.count << " x " << pat.pitch << " mm) " << percent(out.matched.back()) << " tied; ";
  }
  out.variable_of.assign(c.rows(), -1);
  std::vector<int> variable_of_root(c.rows(), -1);
  for (long i = 0; i < c.rows(); ++i) {
    int& v = variable_of_root[classes.find(static_cast<int>(i))];
    if (v < 0) v = out.num_variables++;
    out.variable_of[i] = v;
  }
  log << out.num_variables << " variables for " << c.rows() << " design elements";
  out.summary = log.str();
  return out;
}

}  // namespace topopt::simp
