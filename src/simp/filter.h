// The density filter of SIMP as one interface (ρ̃ = F x over the design elements, Fᵀ for the
// chain rule, Sigmund's sensitivity filter) with two implementations:
// - DensityFilter (density_filter.h): explicit weights of the neighbours within the radius,
//   held as one sparse matrix; memory grows with the radius cubed (neighbours per element);
// - HelmholtzFilter (helmholtz_filter.h): the PDE filter of Lazarov & Sigmund (2011), a
//   Helmholtz equation on the design domain's nodes solved per application; memory linear
//   in the mesh whatever the radius.
// make_filter() is the one place that builds the kind the parameters name.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "common/progress.h"
#include "common/types.h"

namespace topopt::simp {

enum class FilterKind {
  Gaussian,  ///< explicit, w = exp(−d²/(2σ²)), σ = r/3, cut at d = r (the seed paper's choice)
  Cone,      ///< explicit, w = max(0, r − d) (top88's linear weights)
  Helmholtz  ///< PDE filter of length helmholtz_length(r, ...)
};

/// How the Helmholtz filter solves its equation: conjugate gradients preconditioned by Jacobi
/// or by a V-cycle of the smoothed-aggregation multigrid (fem/amg.h, scalar), or the choice of
/// helmholtz_uses_multigrid.
enum class HelmholtzSolver { Auto, Jacobi, Multigrid };

struct FilterParams {
  FilterKind kind = FilterKind::Gaussian;
  double radius = 0;  ///< mm; <= 0 means no filtering (identity)
  int threads = 0;
  /// Helmholtz only: it stands in for the Gaussian filter of the same radius ("auto"), so its
  /// length matches the Gaussian's instead of the cone's (helmholtz_length).
  bool like_gaussian = false;
  HelmholtzSolver helmholtz_solver = HelmholtzSolver::Auto;  ///< Helmholtz only
  /// Explicit kinds: the part's free faces are padded with void. Without it the weights are
  /// normalised over the part, so next to a face the filter sees a member along it as if
  /// mirrored there (twice as thick); with it an element's weights are normalised by the mass
  /// its kernel would have with the part continued as void beyond its free faces (ghost layers
  /// along each face's outward normal, out to the radius). A face is free unless it belongs to a
  /// non-design tet or all its nodes are held (make_filter's `held`: supports and loads, whose
  /// faces the design must keep reaching). The minimum member size sets it (member_size.h).
  /// Helmholtz: the same free faces get the Robin condition ℓ ∂ρ̃/∂n + ρ̃ = 0, the void half-space's
  /// (helmholtz_filter.h).
  bool pad_free_faces = false;
  /// κ in (0, 1], how much of the void beyond a padded face the filter sees: the ghost layers'
  /// kernel mass is weighed by κ (explicit kinds), the Robin condition is ℓ ∂ρ̃/∂n + κ ρ̃ = 0
  /// (Helmholtz); either way a full design reads about 1/(1 + κ) at a padded face. 1 is the void
  /// half-space; towards 0 the filter normalises over the part (the mirror). MemberSizeParams::
  /// pad_weight says which the minimum size takes, and why.
  double pad_weight = 1.0;
};

/// The length ℓ of the Helmholtz filter for a radius r (mm): r/(2√3), Lazarov & Sigmund's match
/// to the cone of radius r; or, standing in for the Gaussian (σ = r/3), r/(3√2), the kernel of
/// the same second moment (6ℓ² = 3σ²): on the cantilever (63 k tets, r = 3 mm, 10 iterations)
/// the compliance is then within 0.6 % of the Gaussian filter's, where r/(2√3) gives 9 % more.
double helmholtz_length(double radius, bool like_gaussian);

/// The mean edge length (mm) of the tets `tets` of `mesh` (empty: all tets), over a sample of
/// at most about 20 000 of them evenly spread through the list: the h of default filter radii,
/// control tolerances and the Helmholtz filter's (ℓ/h)². Returns 0 without tets.
double mean_edge_length(const TetMesh& mesh, const std::vector<int>& tets = {});

/// ρ̃ = F x over the design elements (#D); non-design elements keep ρ = 1 and neither give to
/// nor take from their neighbours. F preserves constants (F 1 = 1).
class Filter {
 public:
  virtual ~Filter() = default;
  /// ρ̃ = F x: x and the result are #D.
  virtual VecXd apply(const VecXd& x) const = 0;
  /// Chain rule of apply: given dF/dρ̃ (#D) returns dF/dx = Fᵀ g.
  virtual VecXd apply_transpose(const VecXd& g) const = 0;
  /// Sigmund's sensitivity filter: F(x ⊙ g) / max(1e-3, x), with F's unweighted rows for the
  /// explicit kinds (as the seed paper writes it).
  virtual VecXd filter_sensitivity(const VecXd& x, const VecXd& g) const = 0;
  /// One line for the log: the kind, radius and size (neighbours, or unknowns and CG iterations).
  virtual std::string describe() const = 0;
};

/// Above this many neighbours per design element "auto" takes the Helmholtz filter. Measured
/// (bench/simp/filters.py, cantilever 63 k tets, 10 iterations, 1 thread): the run's CPU time
/// explicit / Helmholtz is 0.99 at 20 neighbours, 1.10 at 66, 1.40 at 459, 2.7 at 1838, and
/// the explicit filter's peak memory grows with them (282 → 1517 MB) where Helmholtz's stays at
/// 269 MB. Below 100 the explicit Gaussian stays: the automatic radius (1.5 mean edges, about
/// 60–70 neighbours) keeps the seed paper's filter, and the gain there is under 10 %.
constexpr double kHelmholtzAboveNeighbours = 100;

/// The kind of filter to build: `requested` unless `automatic`; then the explicit Gaussian
/// filter while the mean neighbours per element (pairs / design_elements) stay at or below
/// kHelmholtzAboveNeighbours and the pairs within `pairs_budget`, else the Helmholtz filter.
FilterKind choose_filter_kind(FilterKind requested, bool automatic, double pairs, double design_elements,
                              double pairs_budget);

/// Builds the filter `params` name. mesh: the tagged mesh; design: #D indices of the design
/// tets in mesh.T (the order of the design variables); volume: #T element volumes; progress:
/// cancellation (the Helmholtz filter checks it while it solves); held: #V (or empty), nonzero
/// at the nodes whose faces params.pad_free_faces leaves unpadded.
std::unique_ptr<Filter> make_filter(const TetMesh& mesh, const std::vector<int>& design, const VecXd& volume,
                                    const FilterParams& params, const Progress& progress = {},
                                    const std::vector<char>& held = {});

}  // namespace topopt::simp
