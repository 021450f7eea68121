// Linear elasticity on 4-node tetrahedra (see elasticity.h).
//
// Layout, chosen for SIMP's inner loop:
//  - per element only the shape-function gradients (4 by 3) and the volume are stored
//    (13 doubles); K0_e is rebuilt on the fly from them, which costs less than reading 78
//    stored doubles back from memory on large meshes;
//  - the reduced matrix (free dofs only, lower triangle, CSC) has its pattern built once from
//    the node graph, and every element entry knows its slot (`slot_`, 78 ints a tet), so a new
//    set of element factors refills the values without any search or sort;
//  - assembly runs on threads over element colours (no two elements of a colour share a
//    node), so there are no write races and no atomics.
//
// Solvers (measured in bench/fem and bench/simp, see BENCHMARKS.md):
//  - Direct: CHOLMOD's supernodal Cholesky (METIS ordering, symbolic analysis once per mesh);
//    in SIMP the previous factor preconditions CG until that gets slow.
//  - Iterative: CG preconditioned by our smoothed-aggregation multigrid (fem/amg.h) on a full
//    CSR copy of K, warm-started from the previous solution; in SIMP the hierarchy is kept
//    (only its finest smoother refreshed) until the iteration count grows.
// Auto takes the direct solver for small systems (exact, and cheap to factorise) and the
// multigrid above `kDirectDofLimit` unknowns: on the rocker (83 k unknowns) the multigrid
// solve takes 1.6 s against 2.4-2.9 s for analysis + factorisation, and its memory grows
// linearly where the factor's grows much faster (5.2 GB at 560 k unknowns).
#include "fem/elasticity.h"

#include "fem/amg.h"

#include <xmmintrin.h>
#include <Eigen/CholmodSupport>
#include <Eigen/Eigenvalues>
#include <Eigen/Sparse>
#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <numeric>
#include <sstream>

#include "common/blas_threads.h"
#include "common/error.h"
#include "common/parallel.h"

namespace topopt::fem {
namespace {

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

/// Above this many free dofs, Auto uses multigrid CG instead of the direct solver.
constexpr int kDirectDofLimit = 40'000;

/// Local entry p of the 78 upper-triangle entries (i <= j) of a 12 by 12 element matrix.
struct LocalPair {
  int i, j;
};
constexpr int kPairs = 78;

std::array<LocalPair, kPairs> make_pairs() {
  std::array<LocalPair, kPairs> p{};
  int k = 0;
  for (int i = 0; i < 12; ++i)
    for (int j = i; j < 12; ++j) p[k++] = {i, j};
  return p;
}
const std::array<LocalPair, kPairs> kLocalPairs = make_pairs();

/// Lamé parameters from E and ν.
void lame(const Material& m, double& lambda, double& mu) {
  lambda = m.young * m.poisson / ((1 + m.poisson) * (1 - 2 * m.poisson));
  mu = m.young / (2 * (1 + m.poisson));
}

/// The 12 by 12 element stiffness of a linear tet with gradients g (4 by 3, row-major) and
/// volume vol: K_ab,ij = vol (λ g_a,i g_b,j + μ g_a,j g_b,i + μ δ_ij g_a·g_b).
inline void element_matrix(const double* g, double vol, double lambda, double mu, double* K) {
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b) {
      const double* ga = g + 3 * a;
      const double* gb = g + 3 * b;
      double dot = ga[0] * gb[0] + ga[1] * gb[1] + ga[2] * gb[2];
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          K[(3 * a + i) * 12 + 3 * b + j] =
              vol * (lambda * ga[i] * gb[j] + mu * ga[j] * gb[i] + (i == j ? mu * dot : 0.0));
    }
}

}  // namespace

struct Elasticity::Impl {
  TetMesh mesh;
  Material material;
  Supports supports;
  SolverParams params;
  double lambda = 0, mu = 0;
  int threads = 1;

  std::vector<double> grad;  // #T * 12
  std::vector<double> vol;   // #T
  VecXd scale;               // #T

  std::vector<int> free_index;     // 3#V: index among free dofs, or -1 if prescribed
  std::vector<int> free_dofs;      // inverse map
  std::vector<double> prescribed;  // 3#V: prescribed value (0 where free)
  bool nonzero_prescribed = false;

  SpMat K;                                // free-free, lower triangle
  std::vector<int> slot;                  // #T * 78: index into K's values, or -1
  std::vector<std::vector<int>> colours;  // element ids per colour

  std::string singular_reason;  // non-empty: the supports do not hold the structure
  bool dirty = true;            // values need re-assembly / re-factorisation
  Eigen::CholmodSupernodalLLT<SpMat, Eigen::Lower> direct;
  bool analysed = false;
  // Iterative solver: K in full compressed rows (refilled from K's lower triangle through
  // full_pos: two positions per lower entry, the second -1 on the diagonal), the nodes'
  // dof ranges and rigid-body modes that the multigrid aggregates, and its hierarchy.
  CsrMatrix full;
  std::vector<int> full_pos;
  std::vector<int> node_ptr;
  std::vector<double> modes;
  SmoothedAggregationAmg amg;
  bool amg_built = false;    // the hierarchy exists (perhaps of an earlier matrix)
  bool amg_rebuild = false;  // the last solve was slow: rebuild at the next new matrix
  int amg_baseline = -1;     // CG iterations of the first solve after the last full setup
  bool amg_kept = false;     // the hierarchy in use was built for an earlier matrix
  Eigen::MatrixXd last;      // previous free solution, for warm starts
  bool use_direct = true;
  bool factor_valid = false;    // the factor exists (perhaps of an earlier matrix)
  bool factor_current = false;  // the factor is of the current matrix
  int skip_recycle = 0;         // solves to factorise directly after a failed recycling

  void compute_geometry();
  void build_dof_maps();
  void build_pattern();
  void build_colours();
  void check_rigid_body_modes();
  void assemble();
  void build_full();
  template <class Lap>
  void setup_amg(const Progress& progress, Lap& lap) {
    AmgParams ap;
    ap.threads = threads;
    amg.setup(full, node_ptr, modes, ap);
    amg_built = true;
    amg_rebuild = amg_kept = false;
    amg_baseline = -1;
    std::ostringstream s;
    s << "multigrid setup " << lap() << ", " << amg.levels() << " levels (";
    const std::vector<int> sizes = amg.level_sizes();
    for (size_t l = 0; l < sizes.size(); ++l) s << (l ? ", " : "") << sizes[l];
    s << " unknowns), operator complexity " << amg.complexity();
    progress.info(s.str());
  }
  void refill_full();
};

void Elasticity::Impl::build_full() {
  const int nf = static_cast<int>(K.rows());
  const int* op = K.outerIndexPtr();
  const int* ip = K.innerIndexPtr();
  full.rows = full.cols = nf;
  full.ptr.assign(nf + 1, 0);
  for (int c = 0; c < nf; ++c)
    for (int k = op[c]; k < op[c + 1]; ++k) {
      ++full.ptr[ip[k] + 1];
      if (ip[k] != c) ++full.ptr[c + 1];
    }
  for (int i = 0; i < nf; ++i) full.ptr[i + 1] += full.ptr[i];
  full.col.assign(full.ptr[nf], 0);
  full.val.assign(full.ptr[nf], 0.0);
  full_pos.assign(2 * static_cast<size_t>(K.nonZeros()), -1);
  std::vector<int> fill(full.ptr.begin(), full.ptr.end() - 1);
  for (int c = 0; c < nf; ++c)
    for (int k = op[c]; k < op[c + 1]; ++k) {
      const int r = ip[k];
      full_pos[2 * k] = fill[r];
      full.col[fill[r]++] = c;
      if (r != c) {
        full_pos[2 * k + 1] = fill[c];
        full.col[fill[c]++] = r;
      }
    }
  // Dof ranges of the nodes (free dofs are numbered node by node) and the rigid-body modes
  // about the centre of the mesh, lengths scaled by its size.
  node_ptr.assign(1, 0);
  for (int k = 0; k < nf; ++k)
    if (k > 0 && free_dofs[k] / 3 != free_dofs[k - 1] / 3) node_ptr.push_back(k);
  if (nf > 0) node_ptr.push_back(nf);
  full.blocks = node_ptr;  // a node's rows share their columns (the pattern is per node pair)
  const Eigen::RowVector3d lo = mesh.V.colwise().minCoeff(), hi = mesh.V.colwise().maxCoeff();
  const Eigen::RowVector3d centre = 0.5 * (lo + hi);
  const double size = std::max(1e-300, (hi - lo).norm());
  modes.assign(6 * static_cast<size_t>(nf), 0.0);
  for (int k = 0; k < nf; ++k) {
    const int n = free_dofs[k] / 3, c = free_dofs[k] % 3;
    const Eigen::RowVector3d x = (mesh.V.row(n) - centre) / size;
    double* row = &modes[6 * k];
    row[c] = 1;
    // rotations about x, y, z: e_a × x, component c
    const double rot[3][3] = {{0, -x[2], x[1]}, {x[2], 0, -x[0]}, {-x[1], x[0], 0}};
    for (int a = 0; a < 3; ++a) row[3 + a] = rot[a][c];
  }
}

void Elasticity::Impl::refill_full() {
  const double* v = K.valuePtr();
  parallel_for(
      K.nonZeros(), threads,
      [&](long b, long e) {
        for (long k = b; k < e; ++k) {
          full.val[full_pos[2 * k]] = v[k];
          if (full_pos[2 * k + 1] >= 0) full.val[full_pos[2 * k + 1]] = v[k];
        }
      },
      1 << 16);
}

void Elasticity::Impl::compute_geometry() {
  const long nt = mesh.T.rows();
  grad.assign(12 * nt, 0.0);
  vol.assign(nt, 0.0);
  std::string bad;
  for (long e = 0; e < nt; ++e) {
    Eigen::Matrix3d J;
    for (int k = 0; k < 3; ++k) J.col(k) = (mesh.V.row(mesh.T(e, k + 1)) - mesh.V.row(mesh.T(e, 0))).transpose();
    double det = J.determinant();
    if (!(det > 0)) {
      std::ostringstream s;
      s << "tet " << e << " has " << (det == 0 ? "zero" : "negative") << " volume (" << det / 6
        << " mm^3); the mesh must have positively oriented tets";
      throw Error(ErrorCode::InvalidParameter, s.str());
    }
    Eigen::Matrix3d Ji = J.inverse();  // row k: gradient of reference coordinate ξ_k
    double* g = &grad[12 * e];
    for (int c = 0; c < 3; ++c) {
      g[c] = -(Ji(0, c) + Ji(1, c) + Ji(2, c));
      for (int k = 0; k < 3; ++k) g[3 * (k + 1) + c] = Ji(k, c);
    }
    vol[e] = det / 6.0;
  }
}

void Elasticity::Impl::build_dof_maps() {
  const int ndof = 3 * static_cast<int>(mesh.V.rows());
  std::vector<char> fixed(ndof, 0);
  prescribed.assign(ndof, 0.0);
  if (supports.dofs.size() != supports.values.size())
    throw Error(ErrorCode::Internal, "Supports: dofs and values differ in length");
  for (size_t k = 0; k < supports.dofs.size(); ++k) {
    int d = supports.dofs[k];
    if (d < 0 || d >= ndof) throw Error(ErrorCode::Internal, "Supports: dof out of range");
    fixed[d] = 1;
    prescribed[d] = supports.values[k];
    if (supports.values[k] != 0) nonzero_prescribed = true;
  }
  // Nodes used by no tet carry no stiffness: hold them where they are.
  std::vector<char> used(mesh.V.rows(), 0);
  for (long e = 0; e < mesh.T.rows(); ++e)
    for (int a = 0; a < 4; ++a) used[mesh.T(e, a)] = 1;
  for (long n = 0; n < mesh.V.rows(); ++n)
    if (!used[n]) fixed[3 * n] = fixed[3 * n + 1] = fixed[3 * n + 2] = 1;
  free_index.assign(ndof, -1);
  free_dofs.clear();
  for (int d = 0; d < ndof; ++d)
    if (!fixed[d]) {
      free_index[d] = static_cast<int>(free_dofs.size());
      free_dofs.push_back(d);
    }
}

void Elasticity::Impl::build_pattern() {
  const int nv = static_cast<int>(mesh.V.rows());
  const long nt = mesh.T.rows();
  // Node graph (CSR, each node's neighbours including itself, sorted).
  std::vector<int> deg(nv + 1, 0);
  for (long e = 0; e < nt; ++e)
    for (int a = 0; a < 4; ++a) deg[mesh.T(e, a) + 1] += 4;
  for (int n = 0; n < nv; ++n) deg[n + 1] += deg[n];
  std::vector<int> nbr(deg[nv]);
  std::vector<int> fill(deg.begin(), deg.end() - 1);
  for (long e = 0; e < nt; ++e)
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) nbr[fill[mesh.T(e, a)]++] = mesh.T(e, b);
  std::vector<int> start(nv + 1, 0), list;
  list.reserve(nbr.size() / 3);
  for (int n = 0; n < nv; ++n) {
    auto b = nbr.begin() + deg[n], e = nbr.begin() + deg[n + 1];
    std::sort(b, e);
    auto last = std::unique(b, e);
    list.insert(list.end(), b, last);
    start[n + 1] = static_cast<int>(list.size());
  }
  // Column c = free dof (node nb, comp j); rows: free dofs (na, i), na a neighbour, row >= c.
  const int nf = static_cast<int>(free_dofs.size());
  std::vector<int> outer(nf + 1, 0);
  std::vector<int> inner;
  for (int c = 0; c < nf; ++c) {
    int nb = free_dofs[c] / 3;
    for (int k = start[nb]; k < start[nb + 1]; ++k)
      for (int i = 0; i < 3; ++i) {
        int r = free_index[3 * list[k] + i];
        if (r >= c) inner.push_back(r);
      }
    // rows of a column come out sorted because neighbours are sorted and the free numbering
    // follows the dof numbering
    outer[c + 1] = static_cast<int>(inner.size());
  }
  const long nnz = static_cast<long>(inner.size());
  std::vector<double> zeros(nnz, 0.0);
  K = Eigen::Map<const SpMat>(nf, nf, nnz, outer.data(), inner.data(), zeros.data());
  K.makeCompressed();
  // Slots of the element entries.
  slot.assign(kPairs * nt, -1);
  const int* op = K.outerIndexPtr();
  const int* ip = K.innerIndexPtr();
  parallel_for(nt, threads, [&](long b, long e) {
    for (long t = b; t < e; ++t)
      for (int p = 0; p < kPairs; ++p) {
        int di = 3 * mesh.T(t, kLocalPairs[p].i / 3) + kLocalPairs[p].i % 3;
        int dj = 3 * mesh.T(t, kLocalPairs[p].j / 3) + kLocalPairs[p].j % 3;
        int r = free_index[di], c = free_index[dj];
        if (r < 0 || c < 0) continue;
        if (r < c) std::swap(r, c);
        const int* hit = std::lower_bound(ip + op[c], ip + op[c + 1], r);
        assert(hit != ip + op[c + 1] && *hit == r);
        slot[kPairs * t + p] = static_cast<int>(hit - ip);
      }
  });
}

void Elasticity::Impl::build_colours() {
  const int nv = static_cast<int>(mesh.V.rows());
  const long nt = mesh.T.rows();
  // Greedy colouring: an element takes the smallest colour none of its nodes has seen yet.
  // Each node keeps a 64-bit mask of colours used around it; beyond 64 colours a slow path.
  std::vector<uint64_t> mask(nv, 0);
  std::vector<int> colour(nt, -1);
  int ncol = 0;
  std::vector<std::vector<int>> overflow_nodes;  // rarely used
  for (long e = 0; e < nt; ++e) {
    uint64_t m = 0;
    for (int a = 0; a < 4; ++a) m |= mask[mesh.T(e, a)];
    int c = (~m == 0) ? -1 : __builtin_ctzll(~m);
    if (c < 0) {
      // all 64 taken: linear search in the overflow colours
      c = 64;
      for (;; ++c) {
        if (c - 64 >= static_cast<int>(overflow_nodes.size())) overflow_nodes.emplace_back();
        auto& used = overflow_nodes[c - 64];
        bool clash = false;
        for (int a = 0; a < 4 && !clash; ++a) clash = std::binary_search(used.begin(), used.end(), mesh.T(e, a));
        if (!clash) {
          for (int a = 0; a < 4; ++a)
            used.insert(std::lower_bound(used.begin(), used.end(), mesh.T(e, a)), mesh.T(e, a));
          break;
        }
      }
    } else {
      for (int a = 0; a < 4; ++a) mask[mesh.T(e, a)] |= (uint64_t(1) << c);
    }
    colour[e] = c;
    ncol = std::max(ncol, c + 1);
  }
  colours.assign(ncol, {});
  for (long e = 0; e < nt; ++e) colours[colour[e]].push_back(static_cast<int>(e));
}

void Elasticity::Impl::check_rigid_body_modes() {
  // Each connected piece of the mesh must have its six rigid-body motions held by the fixed
  // dofs: with r_k the rigid modes sampled at the fixed dofs of the piece, Σ r r^T must have
  // full rank. This is exact where a "tiny pivot" test would depend on round-off.
  const int nv = static_cast<int>(mesh.V.rows());
  std::vector<int> parent(nv);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (long e = 0; e < mesh.T.rows(); ++e)
    for (int a = 1; a < 4; ++a) {
      int r0 = find(mesh.T(e, 0)), r1 = find(mesh.T(e, a));
      if (r0 != r1) parent[r1] = r0;
    }
  std::vector<char> used(nv, 0);
  for (long e = 0; e < mesh.T.rows(); ++e)
    for (int a = 0; a < 4; ++a) used[mesh.T(e, a)] = 1;
  // piece -> centroid, extent, fixed-dof moment matrix
  struct Piece {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero(), lo = Eigen::Vector3d::Constant(1e300),
                    hi = Eigen::Vector3d::Constant(-1e300);
    int nodes = 0;
    Eigen::Matrix<double, 6, 6> M = Eigen::Matrix<double, 6, 6>::Zero();
  };
  std::vector<int> piece_of(nv, -1);
  std::vector<Piece> pieces;
  std::vector<int> root_piece(nv, -1);
  for (int n = 0; n < nv; ++n) {
    if (!used[n]) continue;
    int r = find(n);
    if (root_piece[r] < 0) root_piece[r] = static_cast<int>(pieces.size()), pieces.emplace_back();
    Piece& p = pieces[root_piece[r]];
    piece_of[n] = root_piece[r];
    Eigen::Vector3d x = mesh.V.row(n).transpose();
    p.sum += x, p.nodes++, p.lo = p.lo.cwiseMin(x), p.hi = p.hi.cwiseMax(x);
  }
  for (size_t d = 0; d < free_index.size(); ++d) {
    int n = static_cast<int>(d / 3), c = static_cast<int>(d % 3);
    if (free_index[d] >= 0 || piece_of[n] < 0) continue;
    Piece& p = pieces[piece_of[n]];
    double L = std::max(1e-300, (p.hi - p.lo).norm());
    Eigen::Vector3d x = (mesh.V.row(n).transpose() - p.sum / p.nodes) / L;
    Eigen::Matrix<double, 6, 1> r = Eigen::Matrix<double, 6, 1>::Zero();
    r(c) = 1;  // translation along c
    // rotation about axis a: (e_a × x)_c
    for (int a = 0; a < 3; ++a) {
      Eigen::Vector3d ea = Eigen::Vector3d::Unit(a);
      r(3 + a) = ea.cross(x)(c);
    }
    p.M += r * r.transpose();
  }
  const char* names[6] = {"translation along x", "translation along y", "translation along z",
                          "rotation about x",    "rotation about y",    "rotation about z"};
  int unheld = 0;
  std::ostringstream why;
  for (size_t k = 0; k < pieces.size(); ++k) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> es(pieces[k].M);
    Eigen::VectorXd ev = es.eigenvalues();
    double tol = 1e-9 * std::max(1.0, ev.maxCoeff());
    int free_modes = 0;
    int example = -1;
    for (int i = 0; i < 6; ++i)
      if (ev(i) <= tol) {
        ++free_modes;
        if (example < 0) {
          Eigen::Matrix<double, 6, 1> v = es.eigenvectors().col(i);
          v.cwiseAbs().maxCoeff(&example);
        }
      }
    if (free_modes == 0) continue;
    ++unheld;
    Eigen::Vector3d c = pieces[k].sum / pieces[k].nodes;
    if (unheld <= 3) {
      why << "\n  piece " << k + 1 << " of " << pieces.size() << " (" << pieces[k].nodes << " nodes, around (" << c.x()
          << ", " << c.y() << ", " << c.z() << ")): "
          << (free_modes == 6 ? std::string("no support at all")
                              : std::to_string(free_modes) + " rigid-body motion(s) not held, e.g. " + names[example]);
    }
  }
  if (unheld) {
    std::ostringstream s;
    s << "the supports do not hold the structure, so the stiffness matrix is singular:" << why.str()
      << "\nAdd a fixed support (or fix more components) on a face of each piece.";
    singular_reason = s.str();
  }
}

void Elasticity::Impl::assemble() {
  double* val = K.valuePtr();
  std::fill(val, val + K.nonZeros(), 0.0);
  for (const auto& list : colours) {
    parallel_for(
        static_cast<long>(list.size()), threads,
        [&](long b, long e) {
          double Ke[144];
          for (long k = b; k < e; ++k) {
            int t = list[k];
            element_matrix(&grad[12 * t], vol[t] * scale[t], lambda, mu, Ke);
            const int* s = &slot[kPairs * static_cast<long>(t)];
            for (int p = 0; p < kPairs; ++p)
              if (s[p] >= 0) {
                // a diagonal block pair (i,j) and (j,i) of different dofs map to one lower slot only
                // once, because the 78 pairs are the element's upper triangle
                val[s[p]] += Ke[kLocalPairs[p].i * 12 + kLocalPairs[p].j];
              }
          }
        },
        512);
  }
}

Elasticity::Elasticity(const TetMesh& mesh, const Material& material, const Supports& supports,
                       const SolverParams& params)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  if (!(material.young > 0)) throw Error(ErrorCode::InvalidParameter, "Young's modulus must be positive (MPa)");
  if (!(material.poisson > -1 && material.poisson < 0.5))
    throw Error(ErrorCode::InvalidParameter, "Poisson's ratio must lie in (-1, 0.5)");
  if (mesh.T.rows() == 0) throw Error(ErrorCode::InvalidParameter, "the mesh has no tetrahedra");
  m.mesh = mesh;
  m.material = material;
  m.supports = supports;
  m.params = params;
  m.threads = thread_count(params.threads);
  lame(material, m.lambda, m.mu);
  m.scale = VecXd::Ones(mesh.T.rows());
  m.compute_geometry();
  m.build_dof_maps();
  m.build_pattern();
  m.build_colours();
  m.check_rigid_body_modes();
  const int nf = static_cast<int>(m.free_dofs.size());
  m.use_direct = params.kind == SolverKind::Direct || (params.kind == SolverKind::Auto && nf <= kDirectDofLimit);
}

Elasticity::~Elasticity() = default;
Elasticity::Elasticity(Elasticity&&) noexcept = default;
Elasticity& Elasticity::operator=(Elasticity&&) noexcept = default;

void Elasticity::set_scale(const VecXd& scale) {
  if (scale.size() != impl_->mesh.T.rows()) throw Error(ErrorCode::Internal, "set_scale: one factor per tet expected");
  if (!(scale.minCoeff() > 0)) throw Error(ErrorCode::InvalidParameter, "element stiffness factors must be positive");
  impl_->scale = scale;
  impl_->dirty = true;
}

Eigen::MatrixXd Elasticity::solve(const Eigen::MatrixXd& loads, const Progress& progress) {
  Impl& m = *impl_;
  const int ndof = num_dofs();
  if (loads.rows() != ndof) throw Error(ErrorCode::Internal, "solve: loads must have 3*#V rows");
  if (!m.singular_reason.empty()) throw Error(ErrorCode::NoSupport, m.singular_reason);
  progress.check_cancel("the FE solve");
  const int nf = static_cast<int>(m.free_dofs.size());

  auto t0 = std::chrono::steady_clock::now();
  auto lap = [&t0]() {
    auto t1 = std::chrono::steady_clock::now();
    double s = std::chrono::duration<double>(t1 - t0).count();
    t0 = t1;
    return std::to_string(s) + " s";
  };
  auto factorise = [&]() {
    if (!m.analysed) {
      // Nested dissection (METIS) only: on 3D meshes it gives far less fill than AMD, and
      // trying several orderings (CHOLMOD's default) costs more than it saves.
      cholmod_common& c = m.direct.cholmod();
      c.nmethods = 1;
      c.method[0].ordering = CHOLMOD_METIS;
      c.postorder = 1;
      m.direct.analyzePattern(m.K);
      m.analysed = true;
      progress.info("symbolic analysis " + lap());
    }
    // Flush denormals to zero while factorising: with SIMP's 1e-9 void stiffness, fill
    // entries decay through void regions into the subnormal range, where every operation
    // costs ~100 times more (the factorisation slowed 4x over a run without this).
    const unsigned csr = _mm_getcsr();
    _mm_setcsr(csr | 0x8040);  // FTZ | DAZ
    m.direct.factorize(m.K);
    _mm_setcsr(csr);
    if (m.direct.info() != Eigen::Success)
      throw Error(ErrorCode::NoSupport,
                  "the stiffness matrix is not positive definite (a part of the structure is "
                  "not held, or elements are degenerate); check the supports");
    m.factor_valid = m.factor_current = true;
    progress.info("factorisation " + lap() + ", " + std::to_string(m.K.rows()) + " unknowns");
  };
  if (m.dirty) {
    m.assemble();
    progress.info("assembly " + lap());
    m.factor_current = false;
    if (m.use_direct) {
      if (!m.factor_valid || !m.params.recycle_factor) factorise();
    } else {
      if (m.full.rows != m.K.rows()) m.build_full();
      m.refill_full();
      m.amg_kept = m.amg_built && !m.amg_rebuild && m.params.recycle_factor;
      if (m.amg_kept) {
        // SIMP's next matrix: keep the hierarchy, refresh the finest smoother only.
        m.amg.refresh_finest();
        progress.info("multigrid kept, finest level refreshed " + lap());
      } else {
        m.setup_amg(progress, lap);
      }
    }
    m.dirty = false;
  }
  // Right-hand sides on the free dofs, minus the prescribed displacements' reactions.
  Eigen::MatrixXd b(nf, loads.cols());
  for (int k = 0; k < nf; ++k) b.row(k) = loads.row(m.free_dofs[k]);
  if (m.nonzero_prescribed) {
    double Ke[144];
    for (long t = 0; t < m.mesh.T.rows(); ++t) {
      double up[12];
      bool any = false;
      for (int i = 0; i < 12; ++i) {
        up[i] = m.prescribed[3 * m.mesh.T(t, i / 3) + i % 3];
        any |= up[i] != 0;
      }
      if (!any) continue;
      element_matrix(&m.grad[12 * t], m.vol[t] * m.scale[t], m.lambda, m.mu, Ke);
      for (int i = 0; i < 12; ++i) {
        int r = m.free_index[3 * m.mesh.T(t, i / 3) + i % 3];
        if (r < 0) continue;
        double s = 0;
        for (int j = 0; j < 12; ++j) s += Ke[i * 12 + j] * up[j];
        b.row(r).array() -= s;
      }
    }
  }
  Eigen::MatrixXd x(nf, loads.cols());
  if (m.use_direct && !m.factor_current && m.skip_recycle > 0) {
    --m.skip_recycle;
    factorise();
  }
  if (m.use_direct && !m.factor_current) {
    // Conjugate gradients preconditioned by the factor of an earlier matrix, warm-started.
    // Abandoned as soon as the convergence rate says it would need more than
    // recycle_iterations; after a failure the next two solves refactorise directly.
    bool ok = m.last.rows() == nf && m.last.cols() == b.cols();
    int worst = 0;
    for (int c = 0; ok && c < b.cols(); ++c) {
      Eigen::VectorXd xc = m.last.col(c), r = b.col(c) - m.K.selfadjointView<Eigen::Lower>() * xc;
      const double bnorm = b.col(c).norm(), goal = m.params.recycle_tolerance * bnorm;
      Eigen::VectorXd z = m.direct.solve(r), p = z, Kp(nf);
      double rz = r.dot(z);
      int k = 0;
      const double r0 = r.norm();
      for (; r.norm() > goal && bnorm > 0; ++k) {
        const int limit = m.params.recycle_iterations;
        if (k >= limit || (k == 6 && std::pow(r.norm() / r0, static_cast<double>(limit) / 6) > goal / r0)) {
          ok = false;
          break;
        }
        Kp.noalias() = m.K.selfadjointView<Eigen::Lower>() * p;
        double alpha = rz / p.dot(Kp);
        xc += alpha * p;
        r -= alpha * Kp;
        z = m.direct.solve(r);
        double rz_new = r.dot(z);
        p = z + (rz_new / rz) * p;
        rz = rz_new;
      }
      worst = std::max(worst, k);
      x.col(c) = xc;
    }
    if (ok) {
      progress.info("recycled factor: " + std::to_string(worst) + " CG iterations, " + lap());
    } else {
      progress.info("recycling abandoned after " + lap());
      m.skip_recycle = 2;
      factorise();
    }
  }
  if (m.use_direct && m.factor_current) {
    x = m.direct.solve(b);
  } else if (!m.use_direct) {
    int worst = 0;
    // The V-cycle's BLAS work (coarse triangular solves) is small: one BLAS thread, so that
    // OpenBLAS's spinning workers leave the cores to our sparse products.
    BlasThreadLimit blas_limit(1);
    for (int c = 0; c < b.cols(); ++c) {
      Eigen::VectorXd xc =
          (m.last.rows() == nf && c < m.last.cols()) ? Eigen::VectorXd(m.last.col(c)) : Eigen::VectorXd::Zero(nf);
      Eigen::VectorXd bc = b.col(c);
      PcgResult r = amg_pcg(m.full, m.amg, bc.data(), xc.data(), m.params.tolerance, m.params.max_iterations, m.threads,
                            progress);
      if (!r.converged && m.amg_kept) {
        // the kept hierarchy no longer fits this matrix: rebuild it and solve again
        progress.info("multigrid CG stalled with the kept hierarchy; rebuilding it");
        m.setup_amg(progress, lap);
        r = amg_pcg(m.full, m.amg, bc.data(), xc.data(), m.params.tolerance, m.params.max_iterations, m.threads,
                    progress);
      }
      if (!r.converged) {
        std::ostringstream s;
        s << "the iterative solver did not converge in " << r.iterations << " iterations (relative residual "
          << r.relative_residual << "); try the direct solver (\"solver\": \"direct\")";
        throw Error(ErrorCode::Internal, s.str());
      }
      worst = std::max(worst, r.iterations);
      x.col(c) = xc;
    }
    progress.info("multigrid CG: " + std::to_string(worst) + " iterations, " + lap());
    // A kept hierarchy that now needs clearly more iterations than right after its setup
    // is rebuilt for the next matrix.
    if (m.amg_baseline < 0)
      m.amg_baseline = worst;
    else if (worst > 1.5 * m.amg_baseline + 4)
      m.amg_rebuild = true;
    m.last = x;
  }
  if (m.use_direct) m.last = x;
  if (!x.allFinite()) throw Error(ErrorCode::NoSupport, "the solution is not finite: the structure is not held");
  Eigen::MatrixXd U(ndof, loads.cols());
  for (int d = 0; d < ndof; ++d) {
    int k = m.free_index[d];
    if (k >= 0)
      U.row(d) = x.row(k);
    else
      U.row(d).setConstant(m.prescribed[d]);
  }
  return U;
}

namespace {
/// Strain ε = sym(∇u) of element t, with ∇u = Σ_a u_a ⊗ g_a over its four nodes.
Eigen::Matrix3d element_strain(const TetMesh& mesh, const std::vector<double>& grad, long t, const VecXd& u) {
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (int a = 0; a < 4; ++a) {
    const double* g = &grad[12 * t + 3 * a];
    int n = mesh.T(t, a);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) H(i, j) += u[3 * n + i] * g[j];
  }
  return 0.5 * (H + H.transpose());
}
}  // namespace

VecXd Elasticity::element_energy(const VecXd& u) const {
  const Impl& m = *impl_;
  const long nt = m.mesh.T.rows();
  VecXd out(nt);
  parallel_for(nt, m.threads, [&](long b, long e) {
    for (long t = b; t < e; ++t) {
      // u^T K0 u = vol (λ (tr ε)² + 2μ ε:ε)
      Eigen::Matrix3d eps = element_strain(m.mesh, m.grad, t, u);
      double tr = eps.trace();
      out[t] = m.vol[t] * (m.lambda * tr * tr + 2 * m.mu * eps.cwiseAbs2().sum());
    }
  });
  return out;
}

VecXd Elasticity::von_mises(const VecXd& u) const {
  const Impl& m = *impl_;
  const long nt = m.mesh.T.rows();
  VecXd out(nt);
  parallel_for(nt, m.threads, [&](long b, long e) {
    for (long t = b; t < e; ++t) {
      Eigen::Matrix3d eps = element_strain(m.mesh, m.grad, t, u);
      Eigen::Matrix3d s = m.scale[t] * (m.lambda * eps.trace() * Eigen::Matrix3d::Identity() + 2 * m.mu * eps);
      double d = 0.5 * ((s(0, 0) - s(1, 1)) * (s(0, 0) - s(1, 1)) + (s(1, 1) - s(2, 2)) * (s(1, 1) - s(2, 2)) +
                        (s(2, 2) - s(0, 0)) * (s(2, 2) - s(0, 0))) +
                 3 * (s(0, 1) * s(0, 1) + s(1, 2) * s(1, 2) + s(0, 2) * s(0, 2));
      out[t] = std::sqrt(d);
    }
  });
  return out;
}

int Elasticity::num_dofs() const { return 3 * static_cast<int>(impl_->mesh.V.rows()); }
const TetMesh& Elasticity::mesh() const { return impl_->mesh; }

}  // namespace topopt::fem
