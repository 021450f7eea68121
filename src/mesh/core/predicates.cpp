// Filtered exact predicates (see predicates.h). The exact path represents numbers as
// expansions: sums of non-overlapping doubles, combined with error-free transformations
// (two_sum; two_product by FMA), as in Shewchuk's "Adaptive Precision Floating-Point
// Arithmetic and Fast Robust Geometric Predicates" (1997). It is only reached for nearly
// degenerate inputs (though on meshes of planar faces that is often: collinear boundary
// nodes, coplanar triangles), so its components live in an inline buffer and only very long
// expansions (in-sphere of nearly cospherical points) reach the heap.
#include "mesh/core/predicates.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace topopt::mesh::predicates {
namespace {

thread_local long fallbacks = 0;

constexpr double kEps = 1.1102230246251565e-16;  // 2^-53
// Static error bounds of the floating-point determinants (Shewchuk's "A" bounds).
constexpr double kOrient2dBound = (3.0 + 16.0 * kEps) * kEps;
constexpr double kOrient3dBound = (7.0 + 56.0 * kEps) * kEps;
constexpr double kIncircleBound = (10.0 + 96.0 * kEps) * kEps;
constexpr double kInsphereBound = (16.0 + 224.0 * kEps) * kEps;

/// Storage of an expansion's components: inline up to 32, on the heap beyond.
class Components {
 public:
  size_t size() const { return n_; }
  bool empty() const { return n_ == 0; }
  double* begin() { return data(); }
  double* end() { return data() + n_; }
  const double* begin() const { return data(); }
  const double* end() const { return data() + n_; }
  double& operator[](size_t i) { return data()[i]; }
  double back() const { return data()[n_ - 1]; }
  void push_back(double x) {
    if (n_ < kInline) {
      buf_[n_++] = x;
      return;
    }
    if (n_ == kInline) heap_.assign(buf_, buf_ + kInline);
    heap_.push_back(x);
    ++n_;
  }
  void resize_down(size_t n) {  // n <= size()
    if (n_ > kInline && n <= kInline)
      std::copy(heap_.begin(), heap_.begin() + n, buf_), heap_.clear();
    else if (n_ > kInline)
      heap_.resize(n);
    n_ = n;
  }

 private:
  static constexpr size_t kInline = 32;
  double* data() { return n_ > kInline ? heap_.data() : buf_; }
  const double* data() const { return n_ > kInline ? heap_.data() : buf_; }
  double buf_[kInline];
  std::vector<double> heap_;
  size_t n_ = 0;
};

/// A number as an exact sum of doubles (components in increasing magnitude, no zeros).
class Expansion {
 public:
  Expansion() = default;
  explicit Expansion(double x) {
    if (x != 0) c_.push_back(x);
  }
  /// a − b exactly.
  static Expansion diff(double a, double b) {
    double x = a - b, bv = a - x, av = x + bv, br = bv - b, ar = a - av;
    Expansion e;
    double y = ar + br;
    if (y != 0) e.c_.push_back(y);
    if (x != 0) e.c_.push_back(x);
    return e;
  }
  /// Sum in linear time: the components of both merged by increasing magnitude, then one
  /// chain of error-free additions (Shewchuk's FAST-EXPANSION-SUM with zero elimination).
  Expansion operator+(const Expansion& o) const {
    if (c_.empty()) return o;
    if (o.c_.empty()) return *this;
    Expansion r;
    size_t i = 0, j = 0;
    const size_t n = c_.size(), m = o.c_.size();
    auto next = [&]() {  // the smaller-magnitude head of the two sequences
      if (j >= m || (i < n && std::abs(c_.begin()[i]) < std::abs(o.c_.begin()[j]))) return c_.begin()[i++];
      return o.c_.begin()[j++];
    };
    double q = next();
    while (i < n || j < m) {
      double x, y;
      two_sum(q, next(), x, y);
      if (y != 0) r.c_.push_back(y);
      q = x;
    }
    if (q != 0) r.c_.push_back(q);
    return r;
  }
  Expansion operator-() const {
    Expansion r = *this;
    for (double& x : r.c_) x = -x;
    return r;
  }
  Expansion operator-(const Expansion& o) const { return *this + (-o); }
  Expansion operator*(const Expansion& o) const {
    Expansion r;
    for (double b : o.c_) r = r + scaled(b);
    return r;
  }
  int sign() const { return c_.empty() ? 0 : (c_.back() > 0 ? 1 : -1); }

 private:
  Components c_;

  static void two_sum(double a, double b, double& x, double& y) {
    x = a + b;
    double bv = x - a, av = x - bv, br = b - bv, ar = a - av;
    y = ar + br;
  }
  /// Adds one double (Shewchuk's GROW-EXPANSION with zero elimination).
  void grow(double b) {
    // in place: the k-th output is written after the k-th input has been read
    double q = b;
    size_t k = 0;
    const size_t n = c_.size();
    for (size_t i = 0; i < n; ++i) {
      double x, y;
      two_sum(q, c_[i], x, y);
      if (y != 0) c_[k++] = y;
      q = x;
    }
    c_.resize_down(k);
    if (q != 0) c_.push_back(q);
    // keep components increasing and non-overlapping: grow preserves both
  }
  /// This expansion times one double in linear time (SCALE-EXPANSION with zero
  /// elimination; exact products by FMA): each component's product is folded into a running
  /// high part, emitting the low parts in increasing order.
  Expansion scaled(double b) const {
    Expansion r;
    if (c_.empty() || b == 0) return r;
    const double* e = c_.begin();
    double q = e[0] * b, low = std::fma(e[0], b, -q);
    if (low != 0) r.c_.push_back(low);
    for (size_t i = 1; i < c_.size(); ++i) {
      const double hi = e[i] * b, lo = std::fma(e[i], b, -hi);
      double sum, err;
      two_sum(q, lo, sum, err);
      if (err != 0) r.c_.push_back(err);
      // |hi| dominates |sum| here, so the fast two-sum is exact
      const double x = hi + sum;
      err = sum - (x - hi);
      if (err != 0) r.c_.push_back(err);
      q = x;
    }
    if (q != 0) r.c_.push_back(q);
    return r;
  }
};

Expansion det2(const Expansion& a, const Expansion& b, const Expansion& c, const Expansion& d) { return a * d - b * c; }

Expansion det3(const Expansion m[3][3]) {
  return m[0][0] * det2(m[1][1], m[1][2], m[2][1], m[2][2]) - m[0][1] * det2(m[1][0], m[1][2], m[2][0], m[2][2]) +
         m[0][2] * det2(m[1][0], m[1][1], m[2][0], m[2][1]);
}

}  // namespace

long exact_fallbacks() { return fallbacks; }

bool segments_meet(const double* a, const double* b, const double* c, const double* d) {
  const int o1 = orient2d(a, b, c), o2 = orient2d(a, b, d), o3 = orient2d(c, d, a), o4 = orient2d(c, d, b);
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;
  auto within = [](const double* s, const double* t, const double* x) {  // x collinear with st: within its box?
    return std::min(s[0], t[0]) <= x[0] && x[0] <= std::max(s[0], t[0]) && std::min(s[1], t[1]) <= x[1] &&
           x[1] <= std::max(s[1], t[1]);
  };
  return (o1 == 0 && within(a, b, c)) || (o2 == 0 && within(a, b, d)) || (o3 == 0 && within(c, d, a)) ||
         (o4 == 0 && within(c, d, b));
}

int orient2d(const double* a, const double* b, const double* c) {
  double l = (a[0] - c[0]) * (b[1] - c[1]), r = (a[1] - c[1]) * (b[0] - c[0]);
  double det = l - r, bound = kOrient2dBound * (std::abs(l) + std::abs(r));
  if (det > bound) return 1;
  if (-det > bound) return -1;
  // on a line x = const or y = const: exactly collinear (see orient3d)
  if ((a[0] == c[0] && b[0] == c[0]) || (a[1] == c[1] && b[1] == c[1])) return 0;
  ++fallbacks;
  Expansion ax = Expansion::diff(a[0], c[0]), ay = Expansion::diff(a[1], c[1]);
  Expansion bx = Expansion::diff(b[0], c[0]), by = Expansion::diff(b[1], c[1]);
  return det2(ax, ay, bx, by).sign();
}

int orient3d(const double* a, const double* b, const double* c, const double* d) {
  // det[b−a, c−a, d−a] = −det[a−d, b−d, c−d]; evaluated in the second form (Shewchuk's).
  double adx = a[0] - d[0], bdx = b[0] - d[0], cdx = c[0] - d[0];
  double ady = a[1] - d[1], bdy = b[1] - d[1], cdy = c[1] - d[1];
  double adz = a[2] - d[2], bdz = b[2] - d[2], cdz = c[2] - d[2];
  double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy, cdxady = cdx * ady, adxcdy = adx * cdy;
  double adxbdy = adx * bdy, bdxady = bdx * ady;
  double det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
  double perm = (std::abs(bdxcdy) + std::abs(cdxbdy)) * std::abs(adz) +
                (std::abs(cdxady) + std::abs(adxcdy)) * std::abs(bdz) +
                (std::abs(adxbdy) + std::abs(bdxady)) * std::abs(cdz);
  double bound = kOrient3dBound * perm;
  if (det > bound) return -1;
  if (-det > bound) return 1;
  // A zero column (all four points on a plane x, y or z = const, the common case on
  // axis-aligned planar faces) makes the determinant exactly zero: a rounded difference of
  // doubles is zero only when they are equal.
  if ((adx == 0 && bdx == 0 && cdx == 0) || (ady == 0 && bdy == 0 && cdy == 0) || (adz == 0 && bdz == 0 && cdz == 0))
    return 0;
  // two equal points (a zero row, or two equal rows): the meshers ask this often, e.g. for a
  // segment against a triangle that shares one of its nodes
  auto same = [](const double* p, const double* q) { return p[0] == q[0] && p[1] == q[1] && p[2] == q[2]; };
  if (same(a, d) || same(b, d) || same(c, d) || same(a, b) || same(a, c) || same(b, c)) return 0;
  ++fallbacks;
  Expansion m[3][3];
  const double* p[3] = {a, b, c};
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) m[i][k] = Expansion::diff(p[i][k], d[k]);
  return -det3(m).sign();
}

int incircle(const double* a, const double* b, const double* c, const double* d) {
  double adx = a[0] - d[0], ady = a[1] - d[1], bdx = b[0] - d[0], bdy = b[1] - d[1];
  double cdx = c[0] - d[0], cdy = c[1] - d[1];
  double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy, alift = adx * adx + ady * ady;
  double cdxady = cdx * ady, adxcdy = adx * cdy, blift = bdx * bdx + bdy * bdy;
  double adxbdy = adx * bdy, bdxady = bdx * ady, clift = cdx * cdx + cdy * cdy;
  double det = alift * (bdxcdy - cdxbdy) + blift * (cdxady - adxcdy) + clift * (adxbdy - bdxady);
  double perm = (std::abs(bdxcdy) + std::abs(cdxbdy)) * alift + (std::abs(cdxady) + std::abs(adxcdy)) * blift +
                (std::abs(adxbdy) + std::abs(bdxady)) * clift;
  double bound = kIncircleBound * perm;
  if (det > bound) return 1;
  if (-det > bound) return -1;
  ++fallbacks;
  const double* p[3] = {a, b, c};
  Expansion m[3][3];
  for (int i = 0; i < 3; ++i) {
    Expansion x = Expansion::diff(p[i][0], d[0]), y = Expansion::diff(p[i][1], d[1]);
    m[i][0] = x, m[i][1] = y, m[i][2] = x * x + y * y;
  }
  return det3(m).sign();
}

int insphere(const double* a, const double* b, const double* c, const double* d, const double* e) {
  const double* p[4] = {a, b, c, d};
  double m[4][4];
  for (int i = 0; i < 4; ++i) {
    for (int k = 0; k < 3; ++k) m[i][k] = p[i][k] - e[k];
    m[i][3] = m[i][0] * m[i][0] + m[i][1] * m[i][1] + m[i][2] * m[i][2];
  }
  // Laplace expansion along the lift column, with the permanent for the error bound.
  auto minor3 = [&](int skip, bool absval) {
    int r[3], k = 0;
    for (int i = 0; i < 4; ++i)
      if (i != skip) r[k++] = i;
    auto v = [&](int i, int j) { return absval ? std::abs(m[r[i]][j]) : m[r[i]][j]; };
    double s0 = v(1, 1) * v(2, 2), s1 = v(2, 1) * v(1, 2), s2 = v(1, 0) * v(2, 2), s3 = v(2, 0) * v(1, 2);
    double s4 = v(1, 0) * v(2, 1), s5 = v(2, 0) * v(1, 1);
    if (absval) return v(0, 0) * (s0 + s1) + v(0, 1) * (s2 + s3) + v(0, 2) * (s4 + s5);
    return v(0, 0) * (s0 - s1) - v(0, 1) * (s2 - s3) + v(0, 2) * (s4 - s5);
  };
  double det = 0, perm = 0;
  for (int i = 0; i < 4; ++i) {
    double sign = (i % 2 == 0) ? -1.0 : 1.0;  // cofactor sign of (i, 3)
    det += sign * m[i][3] * minor3(i, false);
    perm += m[i][3] * minor3(i, true);
  }
  // With rows (p − e, |p − e|²) the determinant is negative when e is inside the sphere of
  // a positively oriented (a, b, c, d) in our convention; hence the flipped signs.
  double bound = kInsphereBound * perm;
  if (det > bound) return -1;
  if (-det > bound) return 1;
  ++fallbacks;
  Expansion x[4][3], lift[4];
  for (int i = 0; i < 4; ++i) {
    for (int k = 0; k < 3; ++k) x[i][k] = Expansion::diff(p[i][k], e[k]);
    lift[i] = x[i][0] * x[i][0] + x[i][1] * x[i][1] + x[i][2] * x[i][2];
  }
  Expansion total;
  for (int i = 0; i < 4; ++i) {
    Expansion mm[3][3];
    int k = 0;
    for (int r = 0; r < 4; ++r)
      if (r != i) {
        for (int j = 0; j < 3; ++j) mm[k][j] = x[r][j];
        ++k;
      }
    Expansion term = lift[i] * det3(mm);
    total = (i % 2 == 0) ? total - term : total + term;
  }
  return -total.sign();
}

}  // namespace topopt::mesh::predicates
