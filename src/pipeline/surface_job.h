// The native surface mesh of one model with its checks — what `topopt surface`, the Python
// module's surface_mesh and the worker's surface_mesh all report, decided here once.
#pragma once
#include <utility>
#include <vector>

#include <TopoDS_Shape.hxx>

#include <string>

#include "brep/foreign.h"
#include "brep/topology_index.h"
#include "common/progress.h"
#include "mesh/surface/surface_check.h"
#include "mesh/surface/surface_mesher.h"
#include "pipeline/mesh_settings.h"

namespace topopt::pipeline {

/// A surface mesh and what was checked on it.
struct SurfaceJobResult {
  mesh::SurfaceMesh mesh;                      ///< nodes, triangles (outward), face numbers, failed faces
  std::vector<long> open_edges_per_solid;      ///< 0 = closed and consistently oriented
  std::vector<std::pair<int, int>> crossings;  ///< intersecting triangle pairs within a solid (≤ 100)
  mesh::SurfaceQuality quality;                ///< angle figures
  double seconds_mesh = 0;                     ///< meshing wall time

  /// True when every face meshed, every solid is closed and nothing intersects.
  bool ok() const;
};

/// The topology of a shape meshed on its own (`topopt surface`, surface_mesh): its solids
/// checked and healed (brep::check_solids, in a child process under `budget`), then indexed
/// with OCCT's failures named. `what` names the input in messages; repairs are appended to
/// `notes`. Throws what check_solids throws (InvalidShape, Crashed, Timeout).
brep::TopologyIndex checked_topology(const TopoDS_Shape& shape, const std::string& what,
                                     std::vector<std::string>& notes, const brep::ForeignParams& budget = {},
                                     const Progress& progress = {});

/// Meshes the faces of `topo` at the sizes `settings` resolve to (the same defaults, clamp and
/// element budget as every mesher: resolve_mesh_sizes), then checks each solid: open edges
/// and self-intersections (within a solid: solids of one model may touch on coincident faces,
/// as the bracket's clamp pads do). Throws what resolve_mesh_sizes throws (TooLarge,
/// InvalidParameter) before any meshing.
SurfaceJobResult surface_job(const brep::TopologyIndex& topo, const MeshSettings& settings,
                             const Progress& progress = {});

}  // namespace topopt::pipeline
