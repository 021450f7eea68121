// Graded size fields over a face's parameters (see graded_size.h).
#include "mesh/surface/graded_size.h"

#include <algorithm>
#include <cmath>

namespace topopt::mesh {

// ============================================================================ PointSizeField

namespace {

/// (h − the smallest size) / grade: beyond it from every point the field is h.
double reach_of(const std::vector<std::array<double, 3>>& pts, double h, double grade) {
  if (pts.empty()) return 0;
  double smin = h;
  for (const auto& p : pts) smin = std::min(smin, p[2]);
  return (h - smin) / grade;
}

}  // namespace

PointSizeField::PointSizeField(std::vector<std::array<double, 3>> pts, double h, double grade)
    : pts_(std::move(pts)), grade_(grade), reach_(reach_of(pts_, h, grade)), grid_(index(pts_, reach_)) {}

// The points in a grid with cells as large as the reach (at most 512 across the points' box),
// so that a query visits 3 x 3 cells.
SpatialGrid<2> PointSizeField::index(const std::vector<std::array<double, 3>>& pts, double reach) {
  double lo[2] = {0, 0}, hi[2] = {0, 0};
  if (!pts.empty()) lo[0] = hi[0] = pts[0][0], lo[1] = hi[1] = pts[0][1];
  for (const auto& p : pts) {
    lo[0] = std::min(lo[0], p[0]), hi[0] = std::max(hi[0], p[0]);
    lo[1] = std::min(lo[1], p[1]), hi[1] = std::max(hi[1], p[1]);
  }
  SpatialGrid<2> grid(lo, std::max({reach, (hi[0] - lo[0]) / 512, (hi[1] - lo[1]) / 512, 1e-300}));
  for (size_t i = 0; i < pts.size(); ++i) grid.insert(static_cast<int>(i), pts[i].data(), pts[i].data());
  return grid;
}

double PointSizeField::size_at(const double* q, double h) const {
  if (pts_.empty()) return h;
  double s = h;
  const double lo[2] = {q[0] - reach_, q[1] - reach_}, hi[2] = {q[0] + reach_, q[1] + reach_};
  grid_.for_each(lo, hi, [&](int i) {
    const auto& p = pts_[i];
    s = std::min(s, p[2] + grade_ * std::hypot(q[0] - p[0], q[1] - p[1]));
  });
  return s;
}

// ============================================================================ SizeRaster

SizeRaster::SizeRaster(const std::vector<std::array<double, 3>>& pts, double cap, double grade)
    : cap_(cap), smallest_(cap) {
  if (pts.empty()) return;
  double smin = cap, lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
  for (const auto& p : pts) {
    smin = std::min(smin, p[2]);
    for (int k = 0; k < 2; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  }
  smallest_ = smin;
  const double reach = (cap - smin) / grade;  // beyond it every point's size has grown to cap
  for (int k = 0; k < 2; ++k) lo_[k] = lo[k] - reach, hi[k] += reach;
  cell_ = std::max({0.5 * smin, (hi[0] - lo_[0]) / 511, (hi[1] - lo_[1]) / 511, 1e-12});
  nx_ = static_cast<long>((hi[0] - lo_[0]) / cell_) + 2, ny_ = static_cast<long>((hi[1] - lo_[1]) / cell_) + 2;
  v_.assign(nx_ * ny_, static_cast<float>(cap));
  for (const auto& p : pts) {  // the cells around each point, exactly
    const long ci = static_cast<long>((p[0] - lo_[0]) / cell_), cj = static_cast<long>((p[1] - lo_[1]) / cell_);
    for (long i = std::max(0L, ci - 1); i <= std::min(nx_ - 1, ci + 2); ++i)
      for (long j = std::max(0L, cj - 1); j <= std::min(ny_ - 1, cj + 2); ++j) {
        const double d = std::hypot(lo_[0] + i * cell_ - p[0], lo_[1] + j * cell_ - p[1]);
        v_[i * ny_ + j] = std::min(v_[i * ny_ + j], static_cast<float>(p[2] + grade * d));
      }
  }
  chamfer(static_cast<float>(grade * cell_), static_cast<float>(grade * cell_ * std::sqrt(2.0)));
}

// Spreads the cells' values to their 8 neighbours, adding `straight` across a side and
// `diagonal` across a corner: one sweep forwards, one backwards.
void SizeRaster::chamfer(float straight, float diagonal) {
  const float a = straight, b = diagonal;
  auto at = [&](long i, long j) -> float& { return v_[i * ny_ + j]; };
  for (long i = 0; i < nx_; ++i)
    for (long j = 0; j < ny_; ++j) {
      float& x = at(i, j);
      if (i > 0)
        x = std::min({x, at(i - 1, j) + a, j > 0 ? at(i - 1, j - 1) + b : x, j + 1 < ny_ ? at(i - 1, j + 1) + b : x});
      if (j > 0) x = std::min(x, at(i, j - 1) + a);
    }
  for (long i = nx_ - 1; i >= 0; --i)
    for (long j = ny_ - 1; j >= 0; --j) {
      float& x = at(i, j);
      if (i + 1 < nx_)
        x = std::min({x, at(i + 1, j) + a, j + 1 < ny_ ? at(i + 1, j + 1) + b : x, j > 0 ? at(i + 1, j - 1) + b : x});
      if (j + 1 < ny_) x = std::min(x, at(i, j + 1) + a);
    }
}

double SizeRaster::size_at(const double* q, double h) const {
  if (v_.empty()) return h;
  const double x = (q[0] - lo_[0]) / cell_, y = (q[1] - lo_[1]) / cell_;
  if (!(x >= 0 && y >= 0 && x < nx_ - 1 && y < ny_ - 1)) return std::min(h, cap_);
  const long i = static_cast<long>(x), j = static_cast<long>(y);
  const double fx = x - i, fy = y - j;
  const double s = (1 - fx) * ((1 - fy) * v_[i * ny_ + j] + fy * v_[i * ny_ + j + 1]) +
                   fx * ((1 - fy) * v_[(i + 1) * ny_ + j] + fy * v_[(i + 1) * ny_ + j + 1]);
  return std::min(h, s);
}

// ============================================================================ fine points

std::vector<std::array<double, 3>> fine_points(const std::vector<std::array<double, 2>>& uv,
                                               const std::vector<std::array<int, 2>>& segs, double h) {
  std::vector<double> spacing(uv.size(), 0.0);
  std::vector<int> count(uv.size(), 0);
  for (const auto& sg : segs) {
    const double l = std::hypot(uv[sg[1]][0] - uv[sg[0]][0], uv[sg[1]][1] - uv[sg[0]][1]);
    for (int k : sg) spacing[k] += l, ++count[k];
  }
  std::vector<std::array<double, 3>> fine;
  for (size_t i = 0; i < uv.size(); ++i)
    if (count[i] && spacing[i] / count[i] < 0.7 * h) fine.push_back({uv[i][0], uv[i][1], spacing[i] / count[i]});
  return fine;
}

}  // namespace topopt::mesh
