// The input of the whole method: the part Ω and the non-design solids Ω̄ as two separate
// B-Rep models, checked, indexed and classified against each other.
#pragma once
#include <TopoDS_Shape.hxx>
#include <string>
#include <vector>

#include "brep/classify.h"
#include "brep/foreign.h"
#include "brep/imprint.h"
#include "brep/topology_index.h"
#include "common/progress.h"

namespace topopt::brep {

struct TwoBReps {
  TopologyIndex part;              ///< Ω: one solid, numbered as FreeCAD numbers it
  TopologyIndex nondesign;         ///< Ω̄: a compound of solids Ω1..ΩN in input order (may be empty)
  Classification nd_on_part;       ///< where each vertex, edge and face of Ω̄ lies on Ω
  ContainmentReport relations;     ///< contacts among the Ωi, warnings
  std::vector<std::string> notes;  ///< repairs made while checking the inputs
  /// What the native mesher meshes: Ω̄ itself, or Ω̄ imprinted with Ω's boundary and with
  /// itself where a face of it lies partly on Ω's boundary or on another solid (imprint.h).
  MeshedNonDesign meshed;
};

/// Checks both inputs (check_solids), indexes them, verifies that every Ωi lies inside Ω and
/// that no two overlap, classifies Ω̄ against Ω, and imprints Ω̄ where it needs it (`meshed`). `nondesign` may be a null
/// shape (no non-design solids). The checks and repairs run in a child process under `foreign`'s budget (check_solids);
/// the indexing and classification after them run here, with OCCT's failures turned into errors that name the stage
/// (guard_occt). Throws topopt::Error with a message naming what to fix.
TwoBReps load_two_breps(const TopoDS_Shape& part, const TopoDS_Shape& nondesign, const ClassifyParams& params = {},
                        const Progress& progress = {}, const ForeignParams& foreign = {});

}  // namespace topopt::brep
