// The geometry controls of SIMP (issue 22): symmetry planes, cyclic and linear-pattern
// repetition and extrusion, as options for DesignMap (design_map.h), and the draw direction
// (draw_filter.h), the overhang of additive manufacturing (overhang_filter.h), and the minimum
// and maximum member size (member_size.h).
#pragma once
#include <Eigen/Core>
#include <vector>

namespace topopt::simp {

/// A mirror plane of the design: any plane through the part, given by a point on it and its
/// normal (need not be unit length, must not be zero).
struct MirrorPlane {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();
};

/// Cyclic repetition: the design repeats `sectors` times about the axis through `point`
/// along `axis` (rotation by 360°/sectors maps the design onto itself).
struct CyclicRepetition {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  int sectors = 0;  ///< >= 2
};

/// Linear pattern: `count` copies of the design, `pitch` mm apart along `direction`, the first
/// starting where the design domain starts along the direction. Beyond count × pitch the
/// design is free.
struct LinearPattern {
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
  double pitch = 0;  ///< mm, > 0
  int count = 0;     ///< >= 2
};

/// Draw direction for casting, forging or milling: every line along `direction` meets the
/// material in one stretch that the die can release. One-sided: the die is drawn along
/// `direction`, so the design is visible from that side (the density never rises along
/// `direction`). Split: a parting plane through `parting_point` normal to `direction`; above it
/// the upper die is drawn along `direction`, below it the lower die against it.
struct DrawDirection {
  bool enabled = false;
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  ///< need not be unit length, not zero
  bool split = false;                                    ///< two dies and a parting plane
  /// a point of the parting plane (split); in both cases a corner of the grid's cells
  Eigen::Vector3d parting_point = Eigen::Vector3d::Zero();
  /// mm: the side of the intermediate grid's cells; <= 0: ControlsParams::tolerance resolved
  double cell = 0;
  /// ε of the smooth maximum (a + b + √((a−b)² + ε) − √ε)/2 along each column; in (0, 0.01]
  double smoothness = 1e-4;
};

/// Overhang control for additive manufacturing (Langelaar's AM filter, overhang_filter.h): the
/// design prints without supports when built along `direction` from a base plate. A surface
/// facing down is self-supporting when it rises at least `angle` from the base plate.
struct OverhangControl {
  bool enabled = false;
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  ///< build direction, plate upwards; not zero
  /// degrees in [10, 80]: the smallest angle between a downward-facing surface and the base
  /// plate that prints without supports (45 for most metal and polymer processes)
  double angle = 45;
  /// degrees in [0, 20]: the filter prints for angle + margin (its layers are
  /// cell·tan(angle + margin) apart), so that walls the optimiser settles at the filter's limit
  /// and the result surface's facets scattered around them stay steeper than `angle`: the
  /// trilinear field between two layers of a one-cell step rises locally at only
  /// atan(tan(angle + margin)/2) (35° at 45 + 10, 47° at 45 + 20); the job parser lowers the
  /// default to 85 − angle for angles above 65 (docs/optimization.md: on the test beam 3.0 %
  /// overhang at 20° against 7.7 % at 10°, at the same compliance)
  double margin = 20;
  /// Ω's face (FreeCAD's FaceN number) the part stands on: flat, facing against `direction`.
  /// 0: the base plate touches the lowest point of Ω along `direction`.
  int base_face = 0;
  /// mm: the lattice spacing across the build direction (layers are cell·tan(angle) apart);
  /// <= 0: ControlsParams::tolerance resolved
  double cell = 0;
  double exponent = 40;      ///< P of the smooth maximum (Σ ξᵢ^P)^(1/Q) of the supports, >= 1
  double xi0 = 0.5;          ///< ξ₀ in (0, 1): Q = P + ln 5 / ln ξ₀, exact when all 5 supports equal ξ₀
  double smoothness = 1e-4;  ///< ε of the smooth minimum with the density; in (0, 0.01]
};

/// Minimum and maximum member size (member_size.h). Both sizes are diameters in mm; <= 0: off.
struct MemberSizeParams {
  /// Smallest member and gap of the design: the robust formulation (eroded, intermediate and
  /// dilated projections) with the filter radius robust_filter_radius(min_size, ...).
  double min_size = 0;
  double eta_shift = 0.25;  ///< Δη: η_e = η + Δη, η_d = η − Δη; in (0.05, 0.45)
  /// With a minimum size: pad the part's free faces with void in the filter (FilterParams::
  /// pad_free_faces), so that a member along such a face is held to the size too. On by default:
  /// normalised over the part, the filter sees a member along a face as if mirrored there and
  /// lets it be half the size (the 10 mm test beam's robust design at 4 mm: flanges along its
  /// faces, smallest member 1.25 mm). The padded test beam that came apart at volume fraction 0.2
  /// was infeasible, not broken: no member whose eroded design carries a load fits in 20 mm² of
  /// its 10 × 10 mm section once the faces are padded (a square bar must be 5.3 mm wide to
  /// survive erosion at a 4 mm size, 28 mm²); at 0.4 it converges (docs/optimization.md).
  bool pad_faces = true;
  /// κ of the padding (FilterParams::pad_weight): how much of the void beyond a free face the
  /// filter sees; a full design reads 1/(1 + κ) at the face.
  double pad_weight = 1.0;
  /// With padding: a free face is padded only where the part behind it is at least this many
  /// minimum sizes thick (thin_part_nodes). Padded on both faces, a member spanning a part of
  /// thickness s reads 1 − e^(−s/2ℓ) at most; on the bracket (10 mm plates, 9 mm, ℓ = 3.42 mm) that
  /// is 0.77, so a member must be about 21 mm wide in the plane to survive erosion (η_e = 0.75)
  /// and the eroded design came apart at volume 0.3 and 0.45 (docs/optimization.md, branch
  /// member9). Below two sizes a part holds no two members across its thickness with a gap of the
  /// size between them, so what the padding guards against there — a member along a face read
  /// as its mirror image, twice as thick — is a flange the size's gap leaves no room to pair;
  /// padded, a member spanning 1.67 sizes (the cantilever, 10 mm at 6 mm) must be 1.33 sizes wide
  /// to survive erosion, and the cantilever's eroded design came apart at volume 0.45 (branch
  /// member10). A member spanning the part's thickness is the part's, not the design's, as the
  /// member measure counts it (PartFaces::Clipped). <= 0: every free face padded.
  double pad_thickness = 2.0;
  /// Largest member: no solid ball of this diameter (the local volume constraint, with MMA).
  double max_size = 0;
  double max_solid = 0.9;  ///< 1 − ε: the largest solid share of an element's ball; in (0.5, 1)
  double pnorm = 16;       ///< P of the aggregation, in [4, 64]
  bool any() const { return min_size > 0 || max_size > 0; }
};

/// Geometry controls, combinable. Defaults: none.
struct ControlsParams {
  std::vector<MirrorPlane> mirrors;      ///< several planes allowed
  std::vector<CyclicRepetition> cyclic;  ///< usually one
  std::vector<LinearPattern> patterns;
  bool extrude = false;                                  ///< constant cross-section along extrusion
  Eigen::Vector3d extrusion = Eigen::Vector3d::UnitZ();  ///< the extrusion direction
  /// mm: how far a mirrored/rotated/shifted centroid may lie from the design element that
  /// takes it, and twice the node spacing of the extrusion's section grid (section_grid.h);
  /// <= 0: the mesh's mean edge length.
  double tolerance = 0;
  DrawDirection draw;        ///< after the density filter, before the projection (draw_filter.h)
  OverhangControl overhang;  ///< after the draw direction, before the projection (overhang_filter.h)
  MemberSizeParams member;   ///< minimum and maximum member size (member_size.h)

  /// True when a control ties design elements (symmetry, repetition, extrusion: DesignMap).
  bool ties() const { return !mirrors.empty() || !cyclic.empty() || !patterns.empty() || extrude; }
  /// True when any control is set.
  bool any() const { return ties() || draw.enabled || overhang.enabled || member.any(); }
};

}  // namespace topopt::simp
