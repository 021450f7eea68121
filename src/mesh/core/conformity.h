// The conformity checker: the measures of DESIGN.md ("Measures everyone uses the same way")
// applied to one tagged tet mesh. Used by the tests, reported by `topopt mesh --stats`.
#pragma once
#include <nlohmann/json.hpp>
#include <vector>

#include "brep/two_breps.h"
#include "common/types.h"

namespace topopt::mesh {

struct ConformityParams {
  /// Nodes closer than this are duplicates; <= 0 means 1e-9 times the mesh's bbox diagonal.
  double duplicate_tolerance = -1;
  /// Allowed relative error of each tagged volume against the B-Rep volume.
  double volume_tolerance = 0.005;
  /// Interface triangles tested against Ω̄'s faces (every one when the mesh is smaller;
  /// evenly spread samples otherwise, to bound the time of the B-Rep projections).
  int max_interface_samples = 2000;
};

struct ConformityReport {
  int nodes = 0, tets = 0, boundary_triangles = 0;
  int inverted_tets = 0;            ///< signed volume <= 0
  int duplicate_nodes = 0;          ///< nodes within tolerance of another node
  int overshared_faces = 0;         ///< tet faces used by more than two tets
  int boundary_not_in_F = 0;        ///< faces used by one tet that F does not list
  int F_not_boundary = 0;           ///< triangles of F that are not a single tet's face
  int open_boundary_edges = 0;      ///< edges of the boundary not used by exactly two of its triangles
  int interface_triangles = 0;      ///< faces between tets of different domains
  int interface_off_nondesign = 0;  ///< of the sampled ones, those not on any face of Ω̄
  int interface_sampled = 0;
  std::vector<double> domain_volume;    ///< mesh volume per domain (0 design, 1.. Ωi)
  std::vector<double> expected_volume;  ///< B-Rep volume per domain (Ω − Ω̄, Ωi), if known
  double max_volume_error = 0;          ///< largest relative error among domains
  bool volumes_ok = true;

  /// True when every count of defects is zero and the volumes agree.
  bool ok() const;
  nlohmann::json to_json() const;
};

/// Checks `mesh` on its own and, when `geometry` is given, against the two B-Reps: tagged
/// volumes against Ω − Ω̄ and each Ωi, interface triangles (faces between domains) lying on
/// Ω̄'s faces. Never throws for a bad mesh: it reports.
ConformityReport check_conformity(const TetMesh& mesh, const brep::TwoBReps* geometry = nullptr,
                                  const ConformityParams& params = {});

}  // namespace topopt::mesh
