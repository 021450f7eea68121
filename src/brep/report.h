// A machine-readable description of the two models: counts, volumes and the classification.
// `topopt info --json` prints it; the Python module returns it as a dict.
#pragma once
#include <nlohmann/json.hpp>

#include "brep/two_breps.h"

namespace topopt::brep {

/// JSON report of `m`. Entity names follow FreeCAD ("Face7", "Edge3", "Vertex1"), 1-based.
/// Layout:
///   part:       {solids, shells, faces, edges, vertices, volume, bbox, faces_detail: [...]}
///   nondesign:  {solids: [{index, volume, faces: [{name, surface, area, on, on_entity}], ...}],
///                edges: [{name, on, on_entity}], vertices: [...]}
///   contacts:   [{solids: [i, j], faces: [[FaceA, FaceB], ...]}]
///   imprint:    [{face: FaceN, pieces: [{on, on_entity, area}, ...]}]: the non-design faces
///               split where they lie partly on the part's boundary (imprint.h)
///   notes, warnings: [strings]
nlohmann::json two_breps_report(const TwoBReps& m);

/// A short human-readable summary of the same (a few lines per solid).
std::string two_breps_summary(const TwoBReps& m);

}  // namespace topopt::brep
