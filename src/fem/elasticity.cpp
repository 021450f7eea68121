// Linear elasticity on 4-node tetrahedra (see elasticity.h).
//
// Layout, chosen for SIMP's inner loop:
//  - per element only the shape-function gradients (4 by 3) and the volume are stored
//    (13 doubles); K0_e is rebuilt on the fly from them, which costs less than reading 78
//    stored doubles back from memory on large meshes;
//  - the reduced matrix (free dofs only) is held once, in full compressed rows with node
//    blocks, the form the multigrid reads (the direct solver keeps the lower triangle it
//    factorises); its pattern is built once from the node graph, and each tet knows where the
//    block of each of its 16 node pairs starts (16 ints a tet), so a new set of element factors
//    refills the values without any search or sort. Before, K was a lower triangle in
//    compressed columns with a slot per element entry (78 ints a tet) and the multigrid a full
//    copy of it with a position map: 0.5 GB more per million tets (BENCHMARKS.md, memory);
//  - assembly runs on threads over element colours (no two elements of a colour share a
//    node), so there are no write races and no atomics; on one thread in mesh order instead
//    (neighbouring elements write neighbouring values: 4-6 times faster than by colours).
//
// Solving is the LinearSolver's business (fem/linear_solver.h: direct or multigrid CG, and
// what each reuses between SIMP iterations); this file hands it the free-dof system.
#include "fem/elasticity.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <numeric>
#include <sstream>

#include "common/adjacency.h"
#include "common/error.h"
#include "common/parallel.h"
#include "common/stopwatch.h"
#include "fem/tet_element.h"

namespace topopt::fem {
namespace {

/// The 78 upper-triangle entries (I <= J) of a 12 by 12 element matrix (element_stiffness_upper).
constexpr int kPairs = 78;

/// The node graph of tets T (#T by 4) on nv nodes: each node's neighbours through the tets,
/// itself included, sorted.
Adjacency node_graph(const MatX4i& T, int nv) {
  Adjacency graph = group_pairs(nv, [&T](auto emit) {
    for (long e = 0; e < T.rows(); ++e)
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) emit(T(e, a), T(e, b));
  });
  sort_unique_rows(graph);
  return graph;
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

  CsrMatrix K;  // free-free, full compressed rows, columns increasing, node blocks
  /// #T * 16: for the tet's nodes a, b (entry 4a + b) the position in K.val of the entry (first
  /// free row of a, first free column of b), or -1 when a or b has no free dof. Row i of a's
  /// block sits one row length of a further (a's rows share their columns, blocks).
  std::vector<int> block_at;
  std::vector<std::vector<int>> colours;  // element ids per colour

  std::string singular_reason;  // non-empty: the supports do not hold the structure
  bool dirty = true;            // values need re-assembly (and the solver an update)
  std::unique_ptr<LinearSolver> solver;
  Eigen::MatrixXd last;  // previous free solution, for warm starts

  void compute_geometry();
  void build_dof_maps();
  /// The free index of node n's first free dof (its others follow it), or -1 if it has none.
  int first_free(int n) const {
    for (int i = 0; i < 3; ++i)
      if (free_index[3 * n + i] >= 0) return free_index[3 * n + i];
    return -1;
  }
  void build_pattern();
  void build_colours();
  void check_rigid_body_modes();
  void assemble();
  /// Adds tet t's upper-triangle entries Ke (78, element_stiffness_upper's order) and their mirror images
  /// into K's values (add_free_element_upper where its four nodes have all dofs free, the most).
  void add_element(long t, const double* Ke);
  /// loads (3#V by #cases) on the free dofs, minus the reactions of prescribed displacements.
  Eigen::MatrixXd free_loads(const Eigen::MatrixXd& loads) const;
  /// The free solution x (nf by #cases) with the prescribed values added: 3#V by #cases.
  Eigen::MatrixXd all_dofs(const Eigen::MatrixXd& x) const;
  /// #T: f(t, ε_t) for each element t, ε_t its strain under the displacements u (3#V).
  template <class F>
  VecXd per_element_strain(const VecXd& u, const F& f) const;
};

void Elasticity::Impl::compute_geometry() {
  const long nt = mesh.T.rows();
  grad.assign(12 * nt, 0.0);
  vol.assign(nt, 0.0);
  std::string bad;
  for (long e = 0; e < nt; ++e) {
    const double det = tet_gradients(mesh, e, &grad[12 * e]);
    if (!(det > 0)) {
      std::ostringstream s;
      s << "tet " << e << " has " << (det == 0 ? "zero" : "negative") << " volume (" << det / 6
        << " mm^3); the mesh must have positively oriented tets";
      throw Error(ErrorCode::InvalidParameter, s.str());
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
  const Adjacency graph = node_graph(mesh.T, nv);
  // The rows of node a: its free dofs; the columns of each: the free dofs of a's neighbours
  // (a included), increasing because neighbours are sorted and the free numbering follows the
  // dof numbering. Counted first so that the column array is allocated once at its size.
  auto free_of = [&](int n) {
    return (free_index[3 * n] >= 0) + (free_index[3 * n + 1] >= 0) + (free_index[3 * n + 2] >= 0);
  };
  const int nf = static_cast<int>(free_dofs.size());
  K = CsrMatrix();
  K.rows = K.cols = nf;
  K.blocks = node_blocks(free_dofs);
  K.ptr.assign(nf + 1, 0);
  for (int r = 0; r < nf; ++r) {
    int len = 0;
    for (int nb : graph.row(free_dofs[r] / 3)) len += free_of(nb);
    K.ptr[r + 1] = K.ptr[r] + len;
  }
  K.col.resize(K.ptr[nf]);
  parallel_for(nf, threads, [&](long b, long e) {
    for (long r = b; r < e; ++r) {
      int k = K.ptr[r];
      for (int nb : graph.row(free_dofs[r] / 3))
        for (int j = 0; j < 3; ++j)
          if (free_index[3 * nb + j] >= 0) K.col[k++] = free_index[3 * nb + j];
    }
  });
  K.val.assign(K.col.size(), 0.0);
  // where each node pair's block starts
  block_at.assign(16 * nt, -1);
  parallel_for(nt, threads, [&](long b, long e) {
    for (long t = b; t < e; ++t) {
      int first[4];
      for (int a = 0; a < 4; ++a) first[a] = first_free(mesh.T(t, a));
      for (int a = 0; a < 4; ++a)
        for (int c = 0; c < 4; ++c) {
          if (first[a] < 0 || first[c] < 0) continue;
          const int* cols = K.col.data();
          const int* hit = std::lower_bound(cols + K.ptr[first[a]], cols + K.ptr[first[a] + 1], first[c]);
          assert(*hit == first[c]);
          block_at[16 * t + 4 * a + c] = static_cast<int>(hit - cols);
        }
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

namespace {

/// A connected piece of a mesh: its node count, the sum and extent of its nodes' positions,
/// and the moment matrix Σ r rᵀ of the rigid modes r sampled at its fixed dofs.
struct Piece {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero(), lo = Eigen::Vector3d::Constant(1e300),
                  hi = Eigen::Vector3d::Constant(-1e300);
  int nodes = 0;
  Eigen::Matrix<double, 6, 6> M = Eigen::Matrix<double, 6, 6>::Zero();
};

/// The connected pieces of a mesh (tets joined by shared nodes), with their node counts and
/// positions (M left zero). Returns the piece of every node (-1 for a node in no tet).
std::vector<int> mesh_pieces(const TetMesh& mesh, std::vector<Piece>& pieces) {
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
  std::vector<int> piece_of(nv, -1), root_piece(nv, -1);
  pieces.clear();
  for (int n = 0; n < nv; ++n) {
    if (!used[n]) continue;
    int r = find(n);
    if (root_piece[r] < 0) root_piece[r] = static_cast<int>(pieces.size()), pieces.emplace_back();
    Piece& p = pieces[root_piece[r]];
    piece_of[n] = root_piece[r];
    Eigen::Vector3d x = mesh.V.row(n).transpose();
    p.sum += x, p.nodes++, p.lo = p.lo.cwiseMin(x), p.hi = p.hi.cwiseMax(x);
  }
  return piece_of;
}

/// The number of rigid-body motions a piece's fixed dofs leave free (the near-zero eigenvalues
/// of its moment matrix M) and, in `example`, the mode (0..5) that dominates the first of them.
int free_rigid_modes(const Eigen::Matrix<double, 6, 6>& M, int& example) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> es(M);
  Eigen::VectorXd ev = es.eigenvalues();
  double tol = 1e-9 * std::max(1.0, ev.maxCoeff());
  int free_modes = 0;
  example = -1;
  for (int i = 0; i < 6; ++i)
    if (ev(i) <= tol) {
      ++free_modes;
      if (example < 0) {
        Eigen::Matrix<double, 6, 1> v = es.eigenvectors().col(i);
        v.cwiseAbs().maxCoeff(&example);
      }
    }
  return free_modes;
}

}  // namespace

void Elasticity::Impl::check_rigid_body_modes() {
  // Each connected piece of the mesh must have its six rigid-body motions held by the fixed
  // dofs: with r_k the rigid modes sampled at the fixed dofs of the piece, Σ r r^T must have
  // full rank. This is exact where a "tiny pivot" test would depend on round-off.
  std::vector<Piece> pieces;
  const std::vector<int> piece_of = mesh_pieces(mesh, pieces);
  for (size_t d = 0; d < free_index.size(); ++d) {
    int n = static_cast<int>(d / 3), c = static_cast<int>(d % 3);
    if (free_index[d] >= 0 || piece_of[n] < 0) continue;
    Piece& p = pieces[piece_of[n]];
    double L = std::max(1e-300, (p.hi - p.lo).norm());
    Eigen::Vector3d x = (mesh.V.row(n).transpose() - p.sum / p.nodes) / L;
    Eigen::Matrix<double, 6, 1> r;
    rigid_modes_at(x, c, r.data());
    p.M += r * r.transpose();
  }
  const char* names[6] = {"translation along x", "translation along y", "translation along z",
                          "rotation about x",    "rotation about y",    "rotation about z"};
  int unheld = 0;
  std::ostringstream why;
  for (size_t k = 0; k < pieces.size(); ++k) {
    int example = -1;
    const int free_modes = free_rigid_modes(pieces[k].M, example);
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

void Elasticity::Impl::add_element(long t, const double* Ke) {
  int dof[12], first[4], len[4];  // free index of each local dof; per node its first and its row length
  bool all_free = true;
  for (int a = 0; a < 4; ++a) {
    const int n = mesh.T(t, a);
    for (int i = 0; i < 3; ++i) dof[3 * a + i] = free_index[3 * n + i];
    first[a] = first_free(n);
    len[a] = first[a] < 0 ? 0 : K.ptr[first[a] + 1] - K.ptr[first[a]];
    all_free &= dof[3 * a] >= 0 && dof[3 * a + 1] >= 0 && dof[3 * a + 2] >= 0;
  }
  if (all_free)
    add_free_element_upper(len, &block_at[16 * t], Ke, K.val.data());
  else
    add_element_upper(dof, first, len, &block_at[16 * t], Ke, K.val.data());
}

void Elasticity::Impl::assemble() {
  std::fill(K.val.begin(), K.val.end(), 0.0);
  auto add = [&](long t, double* Ke) {
    element_stiffness_upper(&grad[12 * t], vol[t] * scale[t], lambda, mu, Ke);
    add_element(t, Ke);
  };
  if (threads == 1) {
    // one thread: the elements in mesh order, whose neighbours share nodes and so K's rows and
    // cache lines; colour by colour each pass sweeps the whole of K. Cantilever, 63 k tets,
    // 1 thread: 46-69 ms an assembly in colour order, 12 ms in mesh order (BENCHMARKS.md, speed3)
    double Ke[kPairs];
    for (long t = 0; t < mesh.T.rows(); ++t) add(t, Ke);
    return;
  }
  for (const auto& list : colours) {
    parallel_for(
        static_cast<long>(list.size()), threads,
        [&](long b, long e) {
          double Ke[kPairs];  // the upper triangle, in element_stiffness_upper's order
          for (long k = b; k < e; ++k) add(list[k], Ke);
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
  m.solver = make_linear_solver({&m.K, &m.free_dofs, &m.mesh.V, m.threads}, params);
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

Eigen::MatrixXd Elasticity::Impl::free_loads(const Eigen::MatrixXd& loads) const {
  const int nf = static_cast<int>(free_dofs.size());
  Eigen::MatrixXd b(nf, loads.cols());
  for (int k = 0; k < nf; ++k) b.row(k) = loads.row(free_dofs[k]);
  if (!nonzero_prescribed) return b;
  double Ke[144];
  for (long t = 0; t < mesh.T.rows(); ++t) {
    double up[12];
    bool any = false;
    for (int i = 0; i < 12; ++i) {
      up[i] = prescribed[3 * mesh.T(t, i / 3) + i % 3];
      any |= up[i] != 0;
    }
    if (!any) continue;
    element_stiffness(&grad[12 * t], vol[t] * scale[t], lambda, mu, Ke);
    for (int i = 0; i < 12; ++i) {
      int r = free_index[3 * mesh.T(t, i / 3) + i % 3];
      if (r < 0) continue;
      double s = 0;
      for (int j = 0; j < 12; ++j) s += Ke[i * 12 + j] * up[j];
      b.row(r).array() -= s;
    }
  }
  return b;
}

Eigen::MatrixXd Elasticity::Impl::all_dofs(const Eigen::MatrixXd& x) const {
  const int ndof = static_cast<int>(free_index.size());
  Eigen::MatrixXd U(ndof, x.cols());
  for (int d = 0; d < ndof; ++d) {
    int k = free_index[d];
    if (k >= 0)
      U.row(d) = x.row(k);
    else
      U.row(d).setConstant(prescribed[d]);
  }
  return U;
}

void Elasticity::set_solver_tolerance(double tolerance) { impl_->solver->set_tolerance(tolerance); }

Eigen::MatrixXd Elasticity::solve(const Eigen::MatrixXd& loads, const Progress& progress) {
  Impl& m = *impl_;
  if (loads.rows() != num_dofs()) throw Error(ErrorCode::Internal, "solve: loads must have 3*#V rows");
  if (!m.singular_reason.empty()) throw Error(ErrorCode::NoSupport, m.singular_reason);
  progress.check_cancel("the FE solve");
  if (m.dirty) {
    Stopwatch watch;
    m.assemble();
    progress.info("assembly " + watch.lap());
    m.solver->update(progress);
    m.dirty = false;
  }
  m.solver->solve(m.free_loads(loads), m.last, progress);
  if (!m.last.allFinite()) throw Error(ErrorCode::NoSupport, "the solution is not finite: the structure is not held");
  return m.all_dofs(m.last);
}

namespace {
/// Strain ε = sym(∇u) of element t under the displacements u (3#V).
Eigen::Matrix3d strain_of(const TetMesh& mesh, const std::vector<double>& grad, long t, const VecXd& u) {
  double ue[12];
  for (int a = 0; a < 4; ++a)
    for (int c = 0; c < 3; ++c) ue[3 * a + c] = u[3 * mesh.T(t, a) + c];
  return element_strain(&grad[12 * t], ue);
}
}  // namespace

template <class F>
VecXd Elasticity::Impl::per_element_strain(const VecXd& u, const F& f) const {
  const long nt = mesh.T.rows();
  VecXd out(nt);
  parallel_for(nt, threads, [&](long b, long e) {
    for (long t = b; t < e; ++t) out[t] = f(t, strain_of(mesh, grad, t, u));
  });
  return out;
}

VecXd Elasticity::element_energy(const VecXd& u) const {
  const Impl& m = *impl_;
  return m.per_element_strain(
      u, [&m](long t, const Eigen::Matrix3d& eps) { return element_energy_of_strain(eps, m.vol[t], m.lambda, m.mu); });
}

VecXd Elasticity::von_mises(const VecXd& u) const {
  const Impl& m = *impl_;
  return m.per_element_strain(
      u, [&m](long t, const Eigen::Matrix3d& eps) { return von_mises_of_strain(eps, m.lambda, m.mu, m.scale[t]); });
}

VecXd Elasticity::solid_von_mises(const VecXd& u) const {
  const Impl& m = *impl_;
  return m.per_element_strain(
      u, [&m](long t, const Eigen::Matrix3d& eps) { return von_mises_of_strain(eps, m.lambda, m.mu, 1.0); });
}

VecXd Elasticity::solid_von_mises_gradient(const VecXd& u, const VecXd& w) const {
  const Impl& m = *impl_;
  VecXd out = VecXd::Zero(u.size());
  for (long t = 0; t < m.mesh.T.rows(); ++t) {
    if (w[t] == 0) continue;
    const Eigen::Matrix3d s = stress_of_strain(strain_of(m.mesh, m.grad, t, u), m.lambda, m.mu);
    const double vm = von_mises_of_stress(s);
    if (vm == 0) continue;
    // dvm/dσ = 3/2 dev(σ)/vm; through σ = λ tr(ε) I + 2μ ε (dev is trace-free): dvm/dε = 3μ dev(σ)/vm;
    // ε = sym(Σ_a u_a ⊗ g_a), so dvm/du_a = (dvm/dε) g_a
    const Eigen::Matrix3d G = (3 * m.mu * w[t] / vm) * (s - s.trace() / 3 * Eigen::Matrix3d::Identity());
    for (int a = 0; a < 4; ++a)
      out.segment<3>(3 * m.mesh.T(t, a)) += G * Eigen::Map<const Eigen::Vector3d>(&m.grad[12 * t + 3 * a]);
  }
  return out;
}

int Elasticity::num_dofs() const { return 3 * static_cast<int>(impl_->mesh.V.rows()); }
const TetMesh& Elasticity::mesh() const { return impl_->mesh; }

}  // namespace topopt::fem
