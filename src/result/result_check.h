// The result surface's validity: closed, manifold and outward (common/closed_surface.h) and
// free of self-intersections, decided by the exact predicates (mesh/core/predicates through
// mesh::self_intersections); its triangle shapes by region; and the repair of crossings that
// smoothing made, by undoing the smoothing where triangles cross.
#pragma once
#include <utility>
#include <vector>

#include "result/iso_surface.h"

namespace topopt::result {

/// What the product checks on every result surface it returns.
struct ResultCheck {
  SurfaceCheck closed;                         ///< edge pairing and enclosed volume
  std::vector<std::pair<int, int>> crossings;  ///< triangle pairs that intersect improperly ((t, t): degenerate t)
  double min_angle_free = 180;                 ///< smallest triangle angle on the free-form region (tag 0), degrees
  double min_angle_faces = 180;                ///< smallest angle on Ω's faces (tag > 0), degrees
  double min_angle_nondesign = 180;            ///< smallest angle on the non-design solids' faces (tag < 0)
  /// True when closed, manifold and free of crossings (the solid is valid).
  bool valid() const { return closed.closed_manifold() && closed.volume > 0 && crossings.empty(); }
};

/// Checks s (its V, F and tag): edge pairing and volume, self-intersections (exact; at most
/// `max_crossings` pairs listed) and the smallest angle per region.
ResultCheck check_result(const TriSurface& s, long max_crossings = 1000);

/// The smallest of the three angles of triangle (a, b, c) of V, in degrees (0 if degenerate).
double min_triangle_angle(const MatX3d& V, int a, int b, int c);

struct UntangleParams {
  int rounds = 8;  ///< halvings of the smoothing displacement around crossings, then as many rounds undoing it fully
  int ring = 1;    ///< also pull back the points this many edges away from a crossing triangle
};

/// Repairs the crossings that moving points made: s.V and `before` (#P by 3, the positions
/// the crossings-free surface had, same triangles) differ by smoothing. Round by round, the
/// points of crossing triangles (and their `ring` neighbours) go halfway back to `before`
/// (params.rounds times), then all the way (as many rounds more, the region growing). Returns the crossings that remain
/// (none when repaired; the caller reports them).
std::vector<std::pair<int, int>> untangle(TriSurface& s, const MatX3d& before, const UntangleParams& params = {});

/// Undoes the smoothing around the free-form triangles it sharpened: a triangle whose smallest
/// angle fell below `floor` degrees and below what it had in `before` (a small loop of the cut
/// line shrinks towards a point under smoothing, leaving needles and caps the remesher cannot
/// collapse). Round by round as untangle: the points of such triangles (and their `ring`
/// neighbours) go halfway back, then all the way. Returns how many such triangles remain.
long unsharpen(TriSurface& s, const MatX3d& before, double floor, const UntangleParams& params = {});

}  // namespace topopt::result
