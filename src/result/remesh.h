// Well-shaped triangles on the result surface: marching tetrahedra leaves needles and caps
// where the level passes close to a mesh node. Edge collapses and edge flips on the
// free-form region (and on Ω's planar faces, within their plane; flips on Ω's curved faces
// between triangles bent a little; flips within one plane on the non-design faces, and between
// triangles bent a little on one curved non-design face) remove
// them, and needles nothing else mends have an edge split (the new point on the face the edge
// lies on: its plane, or a curved face's true surface); no point of a non-design solid moves and
// no point of Ω's faces leaves its face.
#pragma once
#include <functional>
#include <vector>

#include "result/iso_surface.h"

namespace topopt::result {

struct RemeshParams {
  double target_angle = 15;   ///< triangles whose smallest angle is below this (degrees) are worked on
  double flat_dihedral = 25;  ///< a flip on the free-form region only across edges bent less than this (degrees)
  /// a flip on a curved Ω face (all four points on the face's surface), or between two triangles
  /// on one curved face of a non-design solid, only across edges bent less than this (degrees): the
  /// two new triangles are chords of the face as the old ones were
  double curved_dihedral = 25;
  double max_normal_turn = 30;  ///< a collapse may turn no triangle's normal by more than this (degrees)
  int passes = 20;              ///< sweeps over the surface at most (each stops the work when nothing changed)
  bool planar_faces = true;     ///< also flip and collapse on Ω's planar faces (points stay in their plane)
  /// a needle (a triangle whose smallest angle is below this, degrees) that no flip, collapse or
  /// move improves has its longest edge split at the midpoint and its other long edge flipped
  /// away (0: never split)
  double split_angle = 10;
};

/// The true surfaces of the curved faces under the result surface (curved_faces.h makes one from
/// the input's faces), so that the remesher's edits on a curved face keep its points on the face
/// rather than on chords of it. Each member may be empty (nothing known).
struct FaceProjector {
  /// Moves point p (mm) onto the true surface of Ω's face `tag` (> 0) and returns true when that
  /// face is a curved analytic face it knows; returns false and leaves p alone for any other tag.
  std::function<bool(int tag, Eigen::Vector3d& p)> onto_face;
  /// For each triangle of a surface (#Q), the id of the curved face of its non-design solid it lies
  /// on (a triangle tagged -k on a cylinder, cone, sphere or torus of solid k), or -1. A tag -k
  /// names a solid, not a face: this tells which of its curved faces a triangle is a chord of.
  std::function<std::vector<int>(const TriSurface& s)> nondesign_faces;
  /// Moves p onto the true surface of non-design face `id` (from nondesign_faces); false if unknown.
  std::function<bool(int id, Eigen::Vector3d& p)> onto_nondesign;
};

/// What remesh_surface did.
struct RemeshReport {
  long collapses = 0, flips = 0, moves = 0, splits = 0;
  std::vector<int> kept_points;  ///< for each point of the remeshed surface, its index before
};

/// Removes the badly shaped triangles of s where it can: flips an edge when that raises the
/// smallest angle of its two triangles (on the free-form region across edges bent less than
/// flat_dihedral; on Ω's planar faces within the plane; on Ω's curved faces across edges bent
/// less than curved_dihedral, the four points staying on the face; on the non-design solids'
/// faces between triangles in one plane, or of one curved face (see below); no flip moves a point); collapses a short edge into one
/// of its points when the point that goes is free (lock 0), lies inside an Ω face (every triangle
/// around it on that face; on a curved face the points that stay keep their places), lies inside one
/// plane of a non-design solid's faces with non-design neighbours only (the FE mesh's own boundary
/// triangles re-triangulated in their plane), lies on the crease where the free-form surface meets
/// a non-design face and goes into a non-design neighbour across that face (its non-design
/// triangles in one plane, or chords of one curved face that `onto` knows: they stay on the face,
/// the crease then runs through the neighbour, no point moves) or along the crease into its crease
/// neighbour (where the crease passes it once: the crease then runs straight past it, the solid's
/// face keeping its place and its border shifting within it), or slides on the cut line of an Ω face, the surface
/// stays manifold (link condition), and no remaining triangle turns by more than max_normal_turn
/// or ends with a smaller smallest angle than the worst one it replaces; else moves a point of the
/// triangle towards the mean of its neighbours when that raises their smallest angle: a free point
/// within the plane of its triangles, a point inside a planar Ω face within the face's plane, a
/// cut-line point towards its two neighbours on the line, within the face's plane; and when that
/// fails too on a needle (below split_angle), splits the needle's longest edge ab at its midpoint
/// p, flips its other long edge ac and then the edges opposite p where that helps (a halved
/// neighbour can be thin), keeping all only when the smallest angle around p beats the replaced
/// triangles' (else all undone) (a needle with a short edge bc whose points may not go: the angle at p in
/// (p, b, c) is about twice the one at a). The edge split lies on the free-form region, inside
/// a planar Ω face, on a planar face's cut line, or between two planar faces (the midpoint is on
/// the planes); inside a curved Ω face only when `onto` knows the face (the new point goes onto
/// its true surface, not the chord's midpoint); on the B-Rep edge between a curved and a planar Ω
/// face when the midpoint projected onto the curved surface stays on the plane (a straight line or
/// a circle normal to a cylinder's axis); between two triangles in one plane of which one
/// or both are non-design (a non-design face or the border of its footprint on a planar Ω face:
/// the midpoint lies in that plane, and is a fixed non-design point, lock 2); between two
/// triangles of one curved non-design face that `onto` knows (nondesign_faces), the midpoint
/// projected onto the face's true surface (a fixed non-design point, lock 2). Flips on a curved
/// non-design face: across edges bent less than curved_dihedral when both triangles are chords of
/// that one face (the four points stay where they are). Non-design points
/// and points on Ω's edges keep their positions; tags keep their meaning. Returns the counts and
/// which points stayed (a point added by a split has index -1 in kept_points). Every edit (flip,
/// collapse, move, split) is refused when its triangles would cross the surface (crossing_guard.h,
/// exact), so one crossing costs that edit only.
RemeshReport remesh_surface(TriSurface& s, const RemeshParams& params = {}, const FaceProjector& onto = {});

}  // namespace topopt::result
