// Minimum and maximum member size (issue 22).
//
// Minimum size: the robust formulation of Wang, Lazarov & Sigmund (2011). The filtered field
// ρ̃ is projected three times, at η_e = η + Δη (eroded), η (intermediate, the design
// returned) and η_d = η − Δη (dilated). SIMP minimises the compliance of the eroded design
// (the weakest of the three, see docs/optimization.md) under a volume constraint on the
// dilated design whose bound is rescaled so that the intermediate design meets the volume
// fraction. A member of the intermediate design must survive erosion, so it is at least as
// thick as the filter makes the thinnest blueprint bar whose filtered peak reaches η_e; the
// same holds for the gaps (dilation) when η_d = 1 − η_e. robust_filter_radius() turns the
// size asked for into the filter radius by that relation.
//
// Maximum size: a local volume constraint in the spirit of Guest (2009). Around each design
// element the cone-weighted solid fraction of its ball of radius r_max (half the maximum
// size) must stay at most 1 − ε; a solid ball of that radius around an element would make it
// 1. The local fractions are aggregated by a p-norm whose scale follows their largest value
// (as the stress limit's, Le et al. 2010) into one constraint for MMA.
#pragma once
#include <memory>
#include <vector>

#include "common/types.h"
#include "simp/controls/controls_params.h"
#include "simp/filter.h"

namespace topopt::simp {

/// The three thresholds of the robust formulation.
struct RobustThresholds {
  double eroded = 0.75;       ///< η_e = η + Δη
  double intermediate = 0.5;  ///< η
  double dilated = 0.25;      ///< η_d = η − Δη
};

/// The thresholds for the projection threshold `eta` (the intermediate's) and the shift Δη.
RobustThresholds robust_thresholds(double eta, double eta_shift);

/// The smallest member (and gap) of the intermediate design, divided by the filter radius R,
/// for a filter of `kind` and the thresholds t: the width of {ρ̃ >= η} for the thinnest
/// blueprint plate whose filtered peak reaches η_e. A plate is the member the filter thins
/// least (a bar's cross-section loses more of its filtered mass sideways, so it must be
/// thicker to survive erosion), so this bounds every member. Computed by quadrature of the filter's
/// kernel integrated over the plate's plane. like_gaussian: the Helmholtz filter's length
/// (helmholtz_length). Returns a ratio in (0, 2).
double robust_size_ratio(FilterKind kind, const RobustThresholds& t, bool like_gaussian = false);

/// The filter radius (mm) that imposes the minimum size `min_size` (mm): min_size divided by
/// robust_size_ratio.
double robust_filter_radius(double min_size, FilterKind kind, const RobustThresholds& t, bool like_gaussian = false);

/// #V flags, nonzero at the nodes that carry a support (`supported_dofs`, 3 per node) or a load
/// (`loads`, 3#V by cases, nonzero in any case): the faces the minimum size's filter does not pad
/// with void (FilterParams::pad_free_faces), so the design keeps reaching its supports and loads.
std::vector<char> held_nodes(long num_nodes, const std::vector<int>& supported_dofs, const Eigen::MatrixXd& loads);

/// #V flags, nonzero at the nodes of the boundary triangles of `mesh` (all its tets) behind which
/// the part is thinner than `thickness` (mm): from the triangle's centre along its inward normal
/// to the part's boundary. The minimum size's filter leaves a face whose three nodes are flagged
/// unpadded (MemberSizeParams::pad_thickness), as it does the faces held_nodes flags.
std::vector<char> thin_part_nodes(const TetMesh& mesh, double thickness);

/// #V flags of the nodes whose faces the minimum size's filter leaves unpadded: held_nodes (the
/// supports and loads) and thin_part_nodes at p.pad_thickness × p.min_size (none when <= 0).
std::vector<char> unpadded_nodes(const TetMesh& mesh, const std::vector<int>& supported_dofs,
                                 const Eigen::MatrixXd& loads, const MemberSizeParams& p);

/// Throws Error(InvalidParameter), naming the job key and what to change, for member sizes
/// that cannot work on a mesh of mean edge length `mesh_size` (mm): a minimum size below two
/// mesh sizes (a member must span elements), a maximum size below three mesh sizes or not above
/// the minimum size, a shift Δη outside (0.05, 0.45) or an ε outside (0, 0.5), a p-norm outside
/// [4, 64]; and a minimum size without the Heaviside projection (`projection`: it is on). The
/// maximum size's need of MMA is check_params's (optimizer.h).
void check_member_size(const MemberSizeParams& p, double mesh_size, bool projection);

/// The maximum size's constraint: g_i = Σ_j w_ij v_j ρ̄_j / Σ_j w_ij v_j over the design
/// elements j within r_max of element i (cone weights w = r_max − d), then
/// f = c · (Σ_i v_i g_i^P / Σ_i v_i)^(1/P) / (1 − ε) − 1 <= 0 with c = max_i g_i / that p-mean,
/// averaged with the previous evaluation's and held fixed in the gradient.
class LocalVolumeConstraint {
 public:
  /// mesh: the tagged mesh; design: #D indices of the design tets in mesh.T; volume: #T
  /// element volumes; params: max_size (mm, > 0), max_solid = 1 − ε and the p-norm's P.
  LocalVolumeConstraint(const TetMesh& mesh, const std::vector<int>& design, const VecXd& volume,
                        const MemberSizeParams& params);
  ~LocalVolumeConstraint();
  /// The local solid fractions g (#D) of the physical densities rho (#D).
  VecXd local_fractions(const VecXd& rho) const;
  /// Updates the scale c with the densities rho (#D) of this iteration: max g / p-mean, averaged
  /// with the previous one. Returns the largest local fraction max g.
  double adapt(const VecXd& rho);
  /// f(ρ̄) as above for rho (#D) with the scale of the last adapt() (1 before it); grad
  /// (optional): df/dρ̄ (#D).
  double evaluate(const VecXd& rho, VecXd* grad = nullptr) const;

 private:
  std::unique_ptr<Filter> ball_;  // the cone-weighted local average over r_max
  VecXd volume_;                  // #D
  double max_solid_, pnorm_;
  double scale_ = 0;  // c of the last adapt() (0 before the first)
  VecXd clamped(const VecXd& rho) const { return local_fractions(rho).cwiseMax(1e-12); }
  double p_mean(const VecXd& g) const;
};

}  // namespace topopt::simp
