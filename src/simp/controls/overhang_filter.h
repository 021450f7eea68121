// The overhang control for additive manufacturing (issue 22; M. Langelaar, "An additive
// manufacturing filter for topology optimization of print-ready designs", Struct. Multidisc.
// Optim. 55, 2017, and its 2D precursor, Addit. Manuf. 12, 2016). Densities ρ (#D) → a
// lattice whose layers are normal to the build direction (lattice_transfer.h) → printed
// densities layer by layer from the base plate, ξ = smin(ρ, smax(ξ of the supporting nodes in
// the layer below)) → back to the elements. The supports of a node are the node below it and
// that node's four neighbours in its layer; layers are cell·tan(angle + margin) apart, so
// material may stand out by one cell per layer: a slope of angle + margin from the plate (the
// margin keeps the result surface's facets of a wall at the filter's limit above `angle`). Nodes more than a quarter
// inside the non-design solids are printed material whatever lies below them (they are kept)
// and support what stands on them fully; the design elements in such a node's dual cell are
// printed as given only where they rest on the solid (their centroid lies more above the
// solid's than beside it), else the node hands the elements the solid's share of it alone, so
// that no sub-cell shelf hangs from a non-design wall. Sits after the density
// filter (and the draw direction), before the projection; the chain rule is the adjoint of the
// layer recursion.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "common/types.h"
#include "simp/controls/controls_params.h"
#include "simp/controls/lattice_transfer.h"

namespace topopt::simp {

class OverhangFilter {
 public:
  /// mesh: the tagged mesh (its non-design tets count as printed material, density 1);
  /// design: #D indices of the design tets in mesh.T (the order of the fields); params: the
  /// control (enabled); cell: the lattice spacing across the build direction (mm, > 0).
  /// Throws Error(InvalidParameter) naming the key of controls.overhang that is out of range
  /// or a base face that is not flat and facing against the build direction, and
  /// Error(FaceNotFound) for a base face the part does not have.
  OverhangFilter(const TetMesh& mesh, const std::vector<int>& design, const OverhangControl& params, double cell);
  /// #D: the printed field of r (#D, values in [0, 1]).
  VecXd apply(const VecXd& r) const;
  /// Chain rule: dF/dr (#D) at r (#D) given dF/d apply(r) (#D).
  VecXd apply_transpose(const VecXd& r, const VecXd& g) const;
  /// One line for the log: direction, angle, plate, lattice size.
  const std::string& describe() const { return summary_; }
  /// The unit build direction, and the base plate's height along it (mm, s = x·direction).
  const Eigen::Vector3d& direction() const { return d_; }
  double plate_height() const { return plate_; }

 private:
  OverhangControl params_;
  Eigen::Vector3d d_;
  double plate_ = 0;
  double q_ = 1;         // Q of the smooth maximum
  int base_layers_ = 1;  // layers 0 … base_layers_−1 lie on or below the plate: printed as given
  std::unique_ptr<LatticeTransfer> lattice_;
  std::vector<char> anchored_;  // #G: nodes in the non-design solids: full support
  /// #G: anchored nodes whose design share rests on the solid: printed as given; the others
  /// print the solid's share alone
  std::vector<char> carries_design_;
  std::string summary_;
  void build_lattice(const TetMesh& mesh, const std::vector<int>& design, double cell);
  /// The printed lattice values of lattice values g (#G); with adjoint != nullptr, also
  /// replaces *adjoint (d/d output, #G) by d/d g.
  VecXd print(const VecXd& g, VecXd* adjoint) const;
};

/// A setting of the overhang control out of range: its key under controls.overhang and what
/// to fix (the allowed range, the default, the value given).
struct OverhangProblem {
  std::string key;   ///< "angle", "margin", ...; empty when every setting is valid
  std::string what;  ///< "must lie in [10, 80] degrees ..., not 95"
};

/// The one place that decides whether the settings of p are valid (the filter's constructor
/// throws with it, the job parser reports it under the key's path in the job file): the first
/// setting out of range, or an empty key. The base face's existence and flatness need the mesh
/// and are checked by base_plate_height.
OverhangProblem overhang_problem(const OverhangControl& p);

/// Langelaar's smooth maximum of x[0 … n) (values >= 0): (Σ xᵢ^p)^(1/q), with
/// q = p + ln 5 / ln ξ₀ it equals ξ₀ when five values equal ξ₀. Its partial derivatives in dx
/// (n); 0 and zero derivatives when every value is 0.
double smooth_support(const double* x, int n, double p, double q, double* dx);

/// The smooth minimum (a + b − √((a−b)² + eps) + √eps)/2: equal to a when a = b, at least
/// min(a, b) and within √eps/2 of it, 0 when a = b = 0; its partial derivatives in *da, *db.
double smooth_min(double a, double b, double eps, double* da, double* db);

/// The height along the unit build direction d of the base plate: the lowest point of the
/// mesh, or with base_face > 0 the highest point of that face of Ω (mesh.F tagged base_face),
/// which must be flat and face against d. Throws as OverhangFilter's constructor does.
double base_plate_height(const TetMesh& mesh, const Eigen::Vector3d& d, int base_face);

}  // namespace topopt::simp
