// Design hygiene: what the density field hands over, cleaned before the result surface is
// cut from it. On the result shape (the region where the node densities reach the threshold,
// cut out as the iso-surface will cut it) it removes the solid pieces that no support or load
// reaches and names the non-design solids that end up apart from the rest; it fills closed
// internal voids (unless allowed), those of the crisp design (non-design tets, and design tets
// whose node densities reach the threshold on average) and those of the result shape, and
// measures the thinnest member of the crisp design. The finished surface's pieces are checked
// by the same rule (clean_surface_pieces). Before all that, the non-design solids the design
// leaves apart are joined to the rest by bridges through the design (join_bridges.h), unless
// join_non_design is off.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "common/types.h"
#include "mesh/core/tet_components.h"
#include "result/iso_surface.h"
#include "result/member_enforce.h"

namespace topopt::result {

/// Anchor node flags (bits): a support acts there, a load (force or pressure) acts there.
inline constexpr char kAnchorSupport = 1, kAnchorLoad = 2;

struct HygieneParams {
  bool fill_voids = true;  ///< fill closed internal voids; false keeps them (printed lattices)
  /// Join every non-design solid the design leaves apart from the load-carrying piece to it by
  /// a bridge of solid design tets (join_bridges.h; the job's "result": "join_non_design").
  /// false: such a solid stays apart, named in a warning.
  bool join_non_design = true;
  /// The bridges' diameter (mm): the job's minimum member size if set, else the filter's
  /// diameter (pipeline::hygiene_params); <= 0: 3 × the mean edge length of the design tets
  /// (the diameter of the automatic filter).
  double bridge_size = 0;
  /// The job's minimum member size (mm, controls.min_member_size; pipeline::hygiene_params): after
  /// the cleaning, the crisp design's members thinner than it are thickened (member_enforce.h).
  /// <= 0: not.
  double min_member_size = 0;
  /// The build direction of an overhang control (unit, from the plate up; zero: none): a bridge
  /// is then carried down by a wall along the build to the first material below it, or where Ω ends
  /// (join_bridges.h), so that its underside is not a ceiling the overhang pass cannot lift.
  Eigen::Vector3d build_direction = Eigen::Vector3d::Zero();
};

/// A bridge that joins a non-design solid apart to the load-carrying piece (join_bridges.h).
struct Bridge {
  std::vector<int> nondesign;  ///< the non-design solids of the piece it joins (domain tags)
  double volume = 0;           ///< material added (mm³): Σ volume × (1 − density) of the tets set solid
  double length = 0;           ///< along its path, from the piece to the load-carrying one (mm)
  double size = 0;             ///< its diameter (mm)
  bool joined = false;         ///< the piece is one with the load-carrying one afterwards
};

/// A solid piece of the result shape apart from the ones that carry the loads.
struct DesignPiece {
  double volume = 0;           ///< mm³
  std::vector<int> nondesign;  ///< non-design solids in it (domain tags, ascending)
  bool removed = false;        ///< design material only, so taken out of the design
};

/// What clean_design found and did.
struct HygieneReport {
  int pieces = 0;                  ///< solid pieces (level_components) before cleaning
  int anchored_pieces = 0;         ///< ... of them touching a support or load node (or the largest, without anchors)
  std::vector<DesignPiece> apart;  ///< the other pieces
  int voids_filled = 0;            ///< closed internal voids filled
  double void_volume_filled = 0;   ///< mm³
  int voids_kept = 0;              ///< closed internal voids kept (fill_voids false)
  double void_volume_kept = 0;     ///< mm³
  std::vector<Bridge> bridges;     ///< bridges made (join_non_design), before the rest of the cleaning
  MemberEnforcement members;       ///< the minimum member size held (params.min_member_size)
  double min_feature = 0;          ///< thinnest member of the design (mm), 0 if none measured
  std::array<double, 3> min_feature_at{0, 0, 0};  ///< where (the centre of a design tet)
  std::vector<std::string> warnings;              ///< one sentence each, in the user's terms
};

/// "non-design solid 2", "non-design solids 2 and 3", "non-design solids 1, 2 and 4".
std::string solids_named(const std::vector<int>& tags);

/// Face neighbours of tets T (#T by 4, positively oriented): #T by 4, entry k the tet across
/// the face opposite vertex k, -1 on the mesh boundary.
MatX4i tet_neighbours(const MatX4i& T);

/// The crisp design's tets (#T, 1 = solid): non-design tets, and design tets whose four node
/// densities (#V) average at least `threshold`.
std::vector<char> crisp_tets(const TetMesh& mesh, const VecXd& node_density, double threshold);

// the pieces of a set of tets, by shared faces or shared nodes (mesh/core/tet_components.h)
using mesh::node_components;
using mesh::tet_components;

/// Pieces of the result shape: the region where the interpolated node densities (#V) reach
/// `threshold` (nodes at or above it are inside, as extract_iso_surface decides) in the design
/// tets, plus the non-design tets whole. Its pieces: the nodes inside joined by the design
/// tets' edges with both ends inside (a linear field's region in one tet is convex, so nothing
/// else joins them: two tets sharing only a node below the threshold, or a node above it whose
/// tets all average below it, are apart, as on the iso-surface) and by the non-design tets.
/// Returns #T labels: the piece of a non-design tet, or of the nodes inside a design tet (all
/// of one piece), -1 for design tets with none inside; `count` gets the number of pieces.
VecXi level_components(const TetMesh& mesh, const VecXd& node_density, double threshold, int& count);

/// The centroid of tet t of `mesh`, and its (unsigned) volume in mm³: the hygiene's and the
/// bridges' measures of a tet.
Eigen::Vector3d tet_centre(const TetMesh& mesh, long t);
double tet_volume(const TetMesh& mesh, long t);

/// What the rule looks at of a piece.
struct PieceFacts {
  char touch = 0;          ///< kAnchorSupport | kAnchorLoad of the anchors it reaches
  bool nondesign = false;  ///< holds non-design material
  double volume = 0;       ///< mm³
};

/// The facts of the pieces of the result shape (labels #T and `count` of level_components at
/// `threshold` of the node densities nd, #V): the anchors (#V flags; empty when unknown) of its
/// nodes inside the level and of its non-design tets, whether it holds non-design tets, its
/// volume (kept_tet_volume). Returns `count` facts.
std::vector<PieceFacts> level_piece_facts(const TetMesh& mesh, const VecXd& nd, double threshold, const VecXi& label,
                                          int count, const std::vector<char>& anchors);

/// What becomes of a piece of the result (PieceFate): the one rule, applied to the density
/// field (clean_design) and to the finished surface (clean_surface_pieces).
enum class PieceFate : char {
  Carries,  ///< carries the loads: kept
  Removed,  ///< design material only, no load on it: taken out
  Named     ///< apart but kept (non-design solids in it, or a load): named in a warning
};

/// The rule: the pieces that hold both a support and a load carry the loads (failing those,
/// the pieces holding either; failing those, the largest piece); every other piece is removed
/// when it is design material with no load on it, named otherwise. Returns one fate per piece.
std::vector<PieceFate> piece_fates(const std::vector<PieceFacts>& pieces);

/// The thinnest member of the solid tets (mask #T): every solid tet's centre gets its nearest
/// point on the solid's boundary faces (the faces tried are propagated through the mesh from
/// neighbour to neighbour, Danielsson's way); where two face-neighbouring tets, one of them a design tet, see their
/// nearest points on opposite sides (more than 120° apart), the member between is as thick as those points are apart.
/// Returns the smallest such thickness (mm; 0 if none), accurate to about one element size; `at` gets where.
double min_feature_size(const TetMesh& mesh, const MatX4i& neighbours, const std::vector<char>& solid,
                        std::array<double, 3>& at);

/// Cleans element densities (#T) at the threshold of the result shape. First, with
/// params.join_non_design, every non-design solid apart from the load-carrying piece is joined
/// to it (join_non_design_solids; report.bridges, a warning for each naming the solid, the
/// material added, the bridge's length and the key that turns it off). anchors: #V flags
/// (kAnchorSupport | kAnchorLoad) of the nodes where supports and loads act; empty when
/// unknown. The pieces of the result shape (level_components; a piece reaches the anchors of
/// its nodes inside the level) go by piece_fates: a removed piece's tets are set to density 0,
/// a named one is warned about (its non-design solids, or a loaded piece of the design).
/// Piece volumes are the result shape's (kept_tet_volume). Closed voids are filled (set to 1
/// with the design tets around them) when params.fill_voids: the crisp design's (void tets
/// face-connected to no boundary face of the mesh), then the result shape's that it misses (the
/// nodes below the threshold joined by design-tet edges with both ends below it, none on the
/// mesh boundary: a node below the threshold whose tets all average above it).
/// Cleaning is repeated on the cleaned densities' own crisp design until a round changes
/// nothing (at most 4 rounds), so that cleaning the result again finds nothing. Fills `report`
/// (pieces counted before cleaning; a warning for every removal, every piece apart, several
/// load-carrying pieces, filled or kept voids) and returns the cleaned densities (#T).
VecXd clean_design(const TetMesh& mesh, const VecXd& density, double threshold, const std::vector<char>& anchors,
                   const HygieneParams& params, HygieneReport& report);

/// The finished result surface s checked by the hygiene's rule (piece_fates): its pieces
/// (triangles sharing points) enclosing a positive volume, each reaching the anchors of the
/// Ω faces it holds triangles of (face_anchors, indexed by Ω face number: kAnchorSupport |
/// kAnchorLoad of the face; empty when unknown) and holding non-design material when it has
/// a non-design face or point. Removed pieces are taken out of s (points renumbered) and
/// added to report.apart with a warning naming their volume; a named piece whose non-design
/// solids the report does not name yet is named. Closed inner shells (negative volume: voids)
/// are left alone. Returns the number of the warnings added (the last ones of
/// report.warnings).
int clean_surface_pieces(TriSurface& s, const std::vector<char>& face_anchors, HygieneReport& report);

}  // namespace topopt::result
