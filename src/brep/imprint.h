// Partial contact: the non-design model Ω̄ imprinted with the part's boundary and with itself,
// so that every face of Ω̄ is wholly on one face of Ω, or wholly inside Ω, and two non-design
// solids that touch do so on identical faces. A boss standing out of a plate has an outer
// cylinder that is partly on Ω's boundary (where it stands out) and partly inside Ω (the
// interface with the design domain); after the imprint it is three faces, each one of the
// cases the 14 steps transfer (DESIGN.md, docs/two-brep-steps.md). Ω itself is never changed:
// its faces keep the numbers the user's job names.
#pragma once
#include <vector>

#include "brep/classify.h"
#include "brep/topology_index.h"
#include "common/progress.h"

namespace topopt::brep {

/// The non-design model the native mesher meshes.
struct MeshedNonDesign {
  TopologyIndex topo;            ///< Ω̄ (imprinted when `imprinted`), one solid per input solid, input order
  Classification on_part;        ///< where each of topo's vertices, edges and faces lies on Ω
  ContainmentReport relations;   ///< contacts among topo's solids (identical faces after an imprint)
  std::vector<int> face_origin;  ///< #faces of topo: the 0-based face of the input Ω̄ each is part of
  bool imprinted = false;        ///< true when some face or edge of Ω̄ was split
};

/// Splits the faces and edges of every solid of `nondesign` along the boundary of the single
/// solid of `part` and along the other non-design solids (OCCT's General Fuse, through
/// BOPAlgo_Splitter: it finds coincident and partly coincident faces and edges, which a
/// sampling classifier cannot split). `nondesign`: a compound of N solids lying inside `part`
/// (check_containment passed). `fuzzy`: the distance below which two entities coincide (model
/// units). Returns a compound of N solids in input order, each with faces of its own (a face
/// where two solids touch is copied into each), and in `face_origin` (resized to the result's
/// face count, TopExp numbering) the input face each face comes from. `seconds`: the CPU time
/// (of the calling thread) the split may take; OCCT is asked to stop past it, or when
/// `progress` says cancelled. Throws Error(InvalidShape) when the split fails or cuts a solid
/// into pieces, naming the solid; Error(Timeout) past `seconds`, Error(Cancelled) on a cancel.
TopoDS_Shape split_nondesign(const TopologyIndex& part, const TopologyIndex& nondesign, double fuzzy,
                             std::vector<int>& face_origin, double seconds = 120, const Progress& progress = {});

/// `nondesign` as it is, with its classification and relations (no imprint; face_origin the
/// identity).
MeshedNonDesign without_imprint(const TopologyIndex& nondesign, const Classification& on_part,
                                const ContainmentReport& relations);

/// The model to mesh: `nondesign` itself (with `on_part` and `relations`) when no face or edge
/// of it lies partly on Ω's boundary or on another non-design solid, else its imprint
/// (split_nondesign) classified afresh. The test is the imprint itself: a split that leaves
/// every solid's face and edge counts unchanged changes nothing, and the input is kept (so
/// meshes of parts without partial contact do not change). The split runs within
/// params.imprint_seconds of CPU time: past it, Error(Timeout) naming the stage and what to do.
MeshedNonDesign meshed_nondesign(const TopologyIndex& part, const TopologyIndex& nondesign,
                                 const Classification& on_part, const ContainmentReport& relations,
                                 const ClassifyParams& params = {}, const Progress& progress = {});

}  // namespace topopt::brep
