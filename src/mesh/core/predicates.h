// Exact geometric predicates: every orientation and in-sphere decision of the meshers goes
// through here (DESIGN.md). Each first evaluates the determinant in floating point with a
// rigorous error bound (Shewchuk's static filter); only when the sign is uncertain does it
// recompute the determinant exactly with floating-point expansions (error-free sums and
// FMA-based products), so the answer is always the sign of the exact determinant of the
// given doubles.
#pragma once

namespace topopt::mesh::predicates {

/// Sign of det[b−a, c−a] for 2D points (x, y): > 0 when a, b, c turn counter-clockwise,
/// 0 when collinear. Returns −1, 0 or 1.
int orient2d(const double* a, const double* b, const double* c);

/// Sign of det[b−a, c−a, d−a] for 3D points: > 0 when d lies on the side of plane (a, b, c)
/// that makes (a, b, c, d) a positively oriented tet (TetMesh's convention). −1, 0 or 1.
int orient3d(const double* a, const double* b, const double* c, const double* d);

/// Whether the closed 2D segments ab and cd have a point in common: they cross, one touches
/// the other, or they are collinear and overlap (collinear and apart: false). By orient2d alone.
bool segments_meet(const double* a, const double* b, const double* c, const double* d);

/// > 0 when d lies inside the circle through a, b, c (counter-clockwise), 0 on it, < 0 outside.
int incircle(const double* a, const double* b, const double* c, const double* d);

/// > 0 when e lies inside the sphere through a, b, c, d (with orient3d(a, b, c, d) > 0),
/// 0 on it, < 0 outside.
int insphere(const double* a, const double* b, const double* c, const double* d, const double* e);

/// How many calls fell through to exact arithmetic (for tests and benchmarks); counted per
/// thread, never shared.
long exact_fallbacks();

}  // namespace topopt::mesh::predicates
