// The explicit density filter: neighbours by a uniform grid of cell r over the design
// centroids, weights written once in compressed rows (see density_filter.h).
#include "simp/density_filter.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

#include "common/face_key.h"
#include "common/parallel.h"
#include "common/tet_boundary.h"

namespace topopt::simp {
namespace {

/// The design centroids in cells of size r: each element's cell, and per occupied cell the
/// range of its elements in `order`.
class CentroidGrid {
 public:
  CentroidGrid(const MatX3d& centre, double r) : centre_(centre), r_(r) {
    lo_ = centre.colwise().minCoeff();
    const long n = centre.rows();
    std::vector<std::pair<std::uint64_t, int>> keyed(static_cast<size_t>(n));
    for (long i = 0; i < n; ++i) keyed[i] = {key(cell(i)), static_cast<int>(i)};
    std::sort(keyed.begin(), keyed.end());
    order_.resize(keyed.size());
    for (size_t k = 0; k < keyed.size(); ++k) {
      order_[k] = keyed[k].second;
      auto& range = cells_[keyed[k].first];
      if (k == 0 || keyed[k - 1].first != keyed[k].first) range.first = static_cast<int>(k);
      range.second = static_cast<int>(k + 1);
    }
  }

  /// Calls fn(j, d) for every element j whose centroid lies within r of element i's (i itself
  /// included, d = 0), in increasing j.
  template <class Fn>
  void for_each_neighbour(long i, std::vector<std::pair<int, double>>& scratch, Fn&& fn) const {
    for_each_near(centre_.row(i), scratch, fn);
  }

  /// Calls fn(j, d) for every element j whose centroid lies within r of the point p, in
  /// increasing j. p must lie within one cell of the centroids' bounding box or inside it.
  template <class Fn>
  void for_each_near(const Eigen::RowVector3d& p, std::vector<std::pair<int, double>>& scratch, Fn&& fn) const {
    scratch.clear();
    const std::array<long, 3> c = cell_of(p);
    for (long dx = -1; dx <= 1; ++dx)
      for (long dy = -1; dy <= 1; ++dy)
        for (long dz = -1; dz <= 1; ++dz) {
          auto it = cells_.find(key({c[0] + dx, c[1] + dy, c[2] + dz}));
          if (it == cells_.end()) continue;
          for (int k = it->second.first; k < it->second.second; ++k) {
            const int j = order_[k];
            const double d = (centre_.row(j) - p).norm();
            if (d < r_) scratch.push_back({j, d});
          }
        }
    std::sort(scratch.begin(), scratch.end());
    for (const auto& [j, d] : scratch) fn(j, d);
  }

 private:
  std::array<long, 3> cell(long i) const { return cell_of(centre_.row(i)); }
  std::array<long, 3> cell_of(const Eigen::RowVector3d& p) const {
    std::array<long, 3> c;
    for (int a = 0; a < 3; ++a) c[a] = static_cast<long>(std::floor((p[a] - lo_[a]) / r_));
    return c;
  }
  /// A cell's exact key: 21 bits an axis (cells −1 .. 2²¹−2, far beyond any mesh/radius ratio).
  static std::uint64_t key(const std::array<long, 3>& c) {
    auto bits = [](long v) { return static_cast<std::uint64_t>(v + 1) & ((1u << 21) - 1); };
    return bits(c[0]) | bits(c[1]) << 21 | bits(c[2]) << 42;
  }

  const MatX3d& centre_;
  double r_;
  Eigen::RowVector3d lo_;
  std::vector<int> order_;
  std::unordered_map<std::uint64_t, std::pair<int, int>> cells_;
};

/// The weight of a neighbour at distance d (d < r).
double weight(FilterKind kind, double r, double d) {
  const double sigma = r / 3.0;
  return kind == FilterKind::Cone ? r - d : std::exp(-d * d / (2 * sigma * sigma));
}

/// The part's free boundary faces (filter.h, FilterParams::pad_free_faces) as ghost samples of
/// the void beyond them: per face, layers of thickness h along its outward normal out to the
/// radius r, a sample at each layer's middle above the face's centroid holding the layer's
/// volume (face area × h). Returns the samples (#G by 3) and their volumes (#G).
std::pair<MatX3d, VecXd> void_ghosts(const TetMesh& mesh, const std::vector<int>& design, double r,
                                     const std::vector<char>& held) {
  std::unordered_set<FaceKey, FaceKeyHash> fixed;  // faces of non-design tets
  std::vector<char> is_design(static_cast<size_t>(mesh.T.rows()), 0);
  for (int t : design) is_design[t] = 1;
  for (long t = 0; t < mesh.T.rows(); ++t)
    if (!is_design[t])
      for (int a = 0; a < 4; ++a)
        fixed.insert(face_key(mesh.T(t, (a + 1) % 4), mesh.T(t, (a + 2) % 4), mesh.T(t, (a + 3) % 4)));
  const MatX3i faces = boundary_triangles(mesh.T);
  const int layers = std::max(2, static_cast<int>(std::ceil(2 * r / std::max(1e-12, mean_edge_length(mesh, design)))));
  const double h = r / layers;
  std::vector<Eigen::RowVector3d> at;
  std::vector<double> vol;
  for (long f = 0; f < faces.rows(); ++f) {
    const int a = faces(f, 0), b = faces(f, 1), c = faces(f, 2);
    if (fixed.count(face_key(a, b, c))) continue;
    if (!held.empty() && held[a] && held[b] && held[c]) continue;
    const Eigen::RowVector3d n = (mesh.V.row(b) - mesh.V.row(a)).cross(mesh.V.row(c) - mesh.V.row(a));
    const double area = n.norm() / 2;
    if (!(area > 0)) continue;
    const Eigen::RowVector3d centre = (mesh.V.row(a) + mesh.V.row(b) + mesh.V.row(c)) / 3;
    for (int k = 0; k < layers; ++k) at.push_back(centre + (k + 0.5) * h * n / (2 * area)), vol.push_back(area * h);
  }
  MatX3d G(static_cast<long>(at.size()), 3);
  for (size_t g = 0; g < at.size(); ++g) G.row(static_cast<long>(g)) = at[g];
  return {G, Eigen::Map<VecXd>(vol.data(), static_cast<long>(vol.size()))};
}

/// Per design element (centroids `centre`, #D by 3) the kernel mass Σ_g w(d_ig) v_g of the
/// ghost samples (G, their volumes vg) within r.
VecXd ghost_mass(const MatX3d& centre, const MatX3d& G, const VecXd& vg, FilterKind kind, double r, int threads) {
  VecXd mass = VecXd::Zero(centre.rows());
  if (G.rows() == 0) return mass;
  const CentroidGrid grid(G, r);
  parallel_for(centre.rows(), threads, [&](long b, long e) {
    std::vector<std::pair<int, double>> scratch;
    for (long i = b; i < e; ++i)
      grid.for_each_near(centre.row(i), scratch, [&](int g, double d) { mass[i] += weight(kind, r, d) * vg[g]; });
  });
  return mass;
}

}  // namespace

VecXd tet_volumes(const TetMesh& mesh) {
  VecXd v(mesh.T.rows());
  for (long t = 0; t < mesh.T.rows(); ++t) {
    Eigen::RowVector3d p0 = mesh.V.row(mesh.T(t, 0));
    Eigen::Matrix3d J;
    for (int a = 0; a < 3; ++a) J.row(a) = mesh.V.row(mesh.T(t, a + 1)) - p0;
    v[t] = J.determinant() / 6.0;
  }
  return v;
}

MatX3d tet_centroids(const TetMesh& mesh) {
  MatX3d c(mesh.T.rows(), 3);
  for (long t = 0; t < mesh.T.rows(); ++t)
    c.row(t) = 0.25 * (mesh.V.row(mesh.T(t, 0)) + mesh.V.row(mesh.T(t, 1)) + mesh.V.row(mesh.T(t, 2)) +
                       mesh.V.row(mesh.T(t, 3)));
  return c;
}

DensityFilter::DensityFilter(const TetMesh& mesh, const std::vector<int>& design, const VecXd& volume,
                             const FilterParams& params, const std::vector<char>& held)
    : threads_(thread_count(params.threads)),
      kind_(params.kind == FilterKind::Cone ? "cone" : "Gaussian"),
      radius_(params.radius) {
  const long nd = static_cast<long>(design.size());
  volume_.resize(nd);
  MatX3d centre(nd, 3);
  const MatX3d all = tet_centroids(mesh);
  for (long i = 0; i < nd; ++i) volume_[i] = volume[design[i]], centre.row(i) = all.row(design[i]);
  W_.resize(nd, nd);
  const double r = params.radius;
  if (!(r > 0) || nd == 0) {
    W_.setIdentity();
  } else {
    // two passes over the neighbours (count, then write) so that the pairs are held once, and
    // only those with j >= i (W is symmetric: w depends on the distance alone)
    const CentroidGrid grid(centre, r);
    std::vector<int> count(static_cast<size_t>(nd) + 1, 0);
    parallel_for(nd, threads_, [&](long b, long e) {
      std::vector<std::pair<int, double>> scratch;
      for (long i = b; i < e; ++i) grid.for_each_neighbour(i, scratch, [&](int j, double) { count[i + 1] += j >= i; });
    });
    for (long i = 0; i < nd; ++i) count[i + 1] += count[i];
    W_.resizeNonZeros(count[nd]);
    std::copy(count.begin(), count.end(), W_.outerIndexPtr());
    parallel_for(nd, threads_, [&](long b, long e) {
      std::vector<std::pair<int, double>> scratch;
      for (long i = b; i < e; ++i) {
        int k = count[i];
        grid.for_each_neighbour(i, scratch, [&](int j, double d) {
          if (j < i) return;
          W_.innerIndexPtr()[k] = j;
          W_.valuePtr()[k++] = weight(params.kind, r, d);
        });
      }
    });
  }
  weighted_sum_ = product(volume_);
  plain_sum_ = product(VecXd::Ones(nd));
  padded_ = params.pad_free_faces && r > 0 && nd > 0;
  pad_weight_ = params.pad_weight;
  if (padded_) {
    const auto [G, vg] = void_ghosts(mesh, design, r, held);
    weighted_sum_ += params.pad_weight * ghost_mass(centre, G, vg, params.kind, r, threads_);
  }
}

VecXd DensityFilter::product(const VecXd& z) const {
  const long n = W_.rows();
  const int* ptr = W_.outerIndexPtr();
  const int* col = W_.innerIndexPtr();
  const double* w = W_.valuePtr();
  // Row i of W is its lower part (the entries (j, i) of the rows j < i, stored there) then its
  // stored part, both in increasing j. Rows taken in increasing i, each scattering its w_ij z_i
  // into the rows j > i, leave in y_i the lower part summed in increasing j just when row i
  // comes: the full matrix's left-to-right sum, to the bit. `rows` b .. e into y, which holds
  // the partial sums of the rows before b (zero for the first range).
  auto rows = [&](long b, long e, double* y) {
    for (long i = b; i < e; ++i) {
      double s = y[i];
      const double zi = z[i];
      for (int k = ptr[i]; k < ptr[i + 1]; ++k) {
        const int j = col[k];
        s += w[k] * z[j];
        if (j != i) y[j] += w[k] * zi;
      }
      y[i] = s;
    }
  };
  VecXd y = VecXd::Zero(n);
  // the product reads 12 bytes an entry and is memory-bound: threads pay only on large filters,
  // each with its own partial sums (n doubles), added at the end
  const int parts = static_cast<int>(std::min<long>(std::min(threads_, 8), W_.nonZeros() / (1 << 20) + 1));
  if (parts == 1) {
    rows(0, n, y.data());
    return y;
  }
  std::vector<VecXd> partial(parts, VecXd::Zero(n));
  parallel_for(
      parts, parts,
      [&](long pb, long pe) {
        for (long p = pb; p < pe; ++p) rows(n * p / parts, n * (p + 1) / parts, partial[p].data());
      },
      1);
  for (const VecXd& part : partial) y += part;
  return y;
}

VecXd DensityFilter::apply(const VecXd& x) const {
  return product(volume_.cwiseProduct(x)).cwiseQuotient(weighted_sum_);
}

VecXd DensityFilter::apply_transpose(const VecXd& g) const {
  return product(g.cwiseQuotient(weighted_sum_)).cwiseProduct(volume_);
}

VecXd DensityFilter::filter_sensitivity(const VecXd& x, const VecXd& g) const {
  return product(x.cwiseProduct(g)).cwiseQuotient(plain_sum_.cwiseProduct(x.cwiseMax(1e-3)));
}

double DensityFilter::mean_neighbours() const {
  // every stored off-diagonal entry is two pairs (i, j) and (j, i)
  return W_.rows() ? static_cast<double>(2 * W_.nonZeros() - W_.rows()) / W_.rows() : 0.0;
}

std::string DensityFilter::describe() const {
  std::ostringstream s;
  s << kind_ << " filter, radius " << radius_ << " mm, " << mean_neighbours() << " neighbours per element";
  if (padded_) s << ", free faces padded with void (weight " << pad_weight_ << ")";
  return s.str();
}

}  // namespace topopt::simp
