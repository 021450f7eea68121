// How a part is meshed, decided once: the mesher (auto, native, Gmsh), the element size and
// its defaults, the smallest size, the growth of sizes away from fine regions, the curvature
// rule and the element budget. The job's "mesh" section, `topopt mesh` and `topopt surface`
// fill a MeshSettings; resolve_mesh_sizes() meets it with the part; the meshers receive the
// result as their Params structs and decide nothing themselves.
#pragma once
#include <string>

#include "common/progress.h"
#include "mesh/two_brep/gmsh_fragments.h"
#include "mesh/two_brep/native_mesher.h"

namespace topopt::pipeline {

enum class Mesher {
  Auto,    ///< native; where it cannot close a mesh, Gmsh with a warning
  Native,  ///< the two-B-Rep advancing front (the 14 steps)
  Gmsh     ///< OCC fragments of the part with the non-design solids, meshed by Gmsh
};

/// "auto", "native", "gmsh".
const char* mesher_name(Mesher m);
/// The mesher of that name; Error(InvalidParameter) listing the three for any other.
Mesher mesher_from_name(const std::string& name);

/// The defaults and limits every mesher is given (one place: docs/job-format.md quotes them).
struct MeshDefaults {
  static constexpr double kDiagonalDivisions = 50;  ///< automatic size = the part's diagonal / 50
  static constexpr double kMinSizeDivisions = 10;   ///< automatic smallest size = size / 10
  /// Sizes grow by at most 30 % per element away from finer regions (surface and volume).
  static constexpr double kGrowth = 0.3;
  /// Curved faces get 40 elements per turn: the faceting error of a bore, about (2π/N)²/6 of
  /// a ring's volume, stays under the 0.5 % the volumes are held to.
  static constexpr double kElementsPerTurn = 40;
  /// Memory per estimated tet that a mesh may ask of the machine: optimize held 1.63–1.75 kB
  /// per tet of the mesh at 1–2.4 M tets (serial, bench/scale/largest.py), a solve less, and the
  /// estimate below counts about 1.4 tets for each the mesher makes (the cantilever), so a mesh
  /// refused at physical memory / kBytesPerTet would have needed about 2.1 kB per real tet.
  static constexpr double kBytesPerTet = 1500;
  /// The limit where the machine's memory cannot be read.
  static constexpr double kMaxTetsUnknownMemory = 6e6;
  /// The Gmsh fallback's time budget: this many seconds, plus one per this many estimated tets.
  static constexpr double kGmshBaseSeconds = 120, kGmshTetsPerSecond = 2000;
  /// The native mesher's budget in CPU seconds of the process, the same way. The estimate
  /// misses the surface's refinement: on the shared parts the native mesh has 0.7 to 160
  /// times the estimated tets (NIST 3 at its default size: 207 k for 1.3 k), and took up to
  /// 171 s (NIST 2 at 0.6x, 1.8 M tets, 118 k estimated); this budget is over four times that
  /// on every shared part at the default size and at 0.6x.
  static constexpr double kNativeBaseSeconds = 300, kNativeTetsPerSecond = 250;
};

/// What the user decides about meshing, before it meets a part.
struct MeshSettings {
  Mesher mesher = Mesher::Auto;
  double size = 0;      ///< target element size (mm); 0: the part's diagonal / 50
  double min_size = 0;  ///< smallest element size (mm); 0: size / 10
  int wall_layers = 0;  ///< native: layers across walls thinner than two sizes (0..4; 0: off)
  std::string file;     ///< a ready MSH 4.1 mesh used instead of meshing ("": mesh the part)
  /// Seconds the Gmsh fallback may run before it is stopped; 0: from the estimated tet count
  /// (MeshDefaults::kGmshBaseSeconds + estimate / kGmshTetsPerSecond).
  double gmsh_seconds = 0;
  /// CPU seconds the native mesher may use before it is stopped with Error(Timeout) (under
  /// "auto": then Gmsh); 0: from the estimated tet count (MeshDefaults::kNativeBaseSeconds +
  /// estimate / kNativeTetsPerSecond).
  double native_seconds = 0;
  /// Gmsh's surfaces filled by our 3D front (topopt mesh --volume native: a comparison aid).
  bool gmsh_volume_by_front = false;
};

/// Throws Error(InvalidParameter) for a size, smallest size or time limits that are negative
/// or not finite, a smallest size above the size when both are given, or Gmsh's surfaces
/// filled by the front with another mesher than Gmsh. `size_name`,
/// `min_size_name`: how the caller's user writes them ("'mesh.size'", "--size").
void check_mesh_settings(const MeshSettings& s, const std::string& size_name = "the mesh size",
                         const std::string& min_size_name = "the smallest mesh size");

/// The settings resolved for one part.
struct MeshSizes {
  double size = 0;            ///< mm
  double min_size = 0;        ///< mm
  double growth = 0;          ///< per element (MeshDefaults::kGrowth)
  double estimated_tets = 0;  ///< about 6 tets per size³ over the part's volume
  double max_tets = 0;        ///< the largest estimate this machine's memory takes (max_tets())
};

/// The largest estimated tet count a machine with `memory_bytes` of memory takes
/// (MeshDefaults::kBytesPerTet each; MeshDefaults::kMaxTetsUnknownMemory when 0: unknown).
double max_tets(double memory_bytes);

/// Meets the settings with a part of bounding-box diagonal `diagonal` (mm) and volume
/// `volume` (mm³): the automatic size and smallest size, a size above the diagonal clamped
/// to the diagonal with a warning through `progress`. Throws Error(TooLarge) naming the
/// size to use when the estimated mesh exceeds what `memory_bytes` takes (max_tets; < 0: this
/// machine's physical memory), and
/// Error(InvalidParameter) when a given smallest size exceeds the automatic size.
MeshSizes resolve_mesh_sizes(const MeshSettings& s, double diagonal, double volume, const Progress& progress = {},
                             double memory_bytes = -1);

/// The native mesher's parameters for those sizes (the surface at 40 elements per turn,
/// the fills bounded at twice the budget).
mesh::NativeMeshParams native_mesh_params(const MeshSettings& s, const MeshSizes& sizes);

/// The Gmsh fallback's parameters for those sizes.
mesh::FragmentMeshParams gmsh_mesh_params(const MeshSettings& s, const MeshSizes& sizes);

/// The Gmsh fallback's time budget in seconds (MeshSettings::gmsh_seconds, or from the estimate).
double gmsh_time_budget(const MeshSettings& s, const MeshSizes& sizes);

/// The native mesher's time budget in seconds (MeshSettings::native_seconds, or from the estimate).
double native_time_budget(const MeshSettings& s, const MeshSizes& sizes);

}  // namespace topopt::pipeline
