// Points onto the input's curved faces: the remesher's splits (remesh.h) place a new point inside a
// curved kept face of Ω or on a curved face of a non-design solid on the face's true surface
// (cylinder, cone, sphere or torus of the input), not on the chord between two of its points, so
// the face stays where it was; its flips on a curved non-design face stay within one such face.
#pragma once
#include "result/iso_surface.h"
#include "result/remesh.h"

namespace topopt::result {

class SourceFaces;  // step_export_analytic.h

/// The projector onto the surfaces of the curved Ω faces that s's triangles lie on: for each tag
/// f > 0 whose triangles SourceFaces::classify finds on one of `source`'s curved analytic faces,
/// that face's untrimmed surface (the nearest point of it, OCCT's exact projection for these
/// elementary surfaces); and for the non-design triangles (tag -k) of any surface, which curved
/// face of solid k each lies on (SourceFaces::classify) with the projection onto it. `source` must
/// outlive the projector. s: the result surface as marching tetrahedra made it (its tags name Ω's
/// faces). An empty source gives a projector that knows no face (its members are empty).
FaceProjector curved_face_projector(const SourceFaces& source, const TriSurface& s);

}  // namespace topopt::result
