// Mesh settings decided once (see mesh_settings.h).
#include "pipeline/mesh_settings.h"

#include <cmath>

#include "common/error.h"
#include "common/number_text.h"
#include "pipeline/problem_checks.h"

namespace topopt::pipeline {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// A length as a user reads it: 4 significant digits.
std::string mm(double v) { return mm_text(v, 4); }

}  // namespace

const char* mesher_name(Mesher m) {
  switch (m) {
    case Mesher::Native:
      return "native";
    case Mesher::Gmsh:
      return "gmsh";
    case Mesher::Auto:
      break;
  }
  return "auto";
}

Mesher mesher_from_name(const std::string& name) {
  for (Mesher m : {Mesher::Auto, Mesher::Native, Mesher::Gmsh})
    if (name == mesher_name(m)) return m;
  throw Error(ErrorCode::InvalidParameter, "the mesher is \"auto\", \"native\" (the two-B-Rep advancing front) or " +
                                               std::string("\"gmsh\", not \"") + name + "\"");
}

void check_mesh_settings(const MeshSettings& s, const std::string& size_name, const std::string& min_size_name) {
  if (!(std::isfinite(s.size) && s.size >= 0))
    throw Error(ErrorCode::InvalidParameter, size_name + " must be a positive length in mm, or 0 for automatic");
  if (!(std::isfinite(s.min_size) && s.min_size >= 0))
    throw Error(ErrorCode::InvalidParameter, min_size_name + " must be a positive length in mm, or 0 for automatic");
  if (s.size > 0 && s.min_size > s.size)
    throw Error(ErrorCode::InvalidParameter, min_size_name + " (" + mm(s.min_size) + ") is larger than " + size_name +
                                                 " (" + mm(s.size) + "): give a smaller one, or 0 for size / 10");
  if (s.gmsh_volume_by_front && s.mesher != Mesher::Gmsh)
    throw Error(ErrorCode::InvalidParameter,
                "filling Gmsh's surfaces by the native front (--volume native) goes with the Gmsh mesher (--mesher "
                "gmsh): the native mesher fills its volumes itself");
  if (!(std::isfinite(s.gmsh_seconds) && s.gmsh_seconds >= 0))
    throw Error(ErrorCode::InvalidParameter, "the Gmsh time limit must be a positive number of seconds, or 0");
  if (!(std::isfinite(s.native_seconds) && s.native_seconds >= 0))
    throw Error(ErrorCode::InvalidParameter,
                "the native mesher's time limit must be a positive number of seconds, or 0 for automatic");
}

double max_tets(double memory_bytes) {
  return memory_bytes > 0 ? memory_bytes / MeshDefaults::kBytesPerTet : MeshDefaults::kMaxTetsUnknownMemory;
}

MeshSizes resolve_mesh_sizes(const MeshSettings& s, double diagonal, double volume, const Progress& progress,
                             double memory_bytes) {
  MeshSizes r;
  r.size = s.size > 0 ? s.size : diagonal / MeshDefaults::kDiagonalDivisions;
  if (diagonal > 0 && r.size > diagonal) {
    progress.warn("the mesh size " + mm(r.size) + " is larger than the part (its diagonal is " + mm(diagonal) +
                  "): meshing at " + mm(diagonal));
    r.size = diagonal;
  }
  if (s.min_size > r.size) {
    if (s.size > 0)  // both given, the size clamped above: the smallest size follows it
      r.min_size = r.size / MeshDefaults::kMinSizeDivisions;
    else
      throw Error(ErrorCode::InvalidParameter,
                  "the smallest mesh size (" + mm(s.min_size) + ") is larger than the automatic mesh size (" +
                      mm(r.size) +
                      ", the part's diagonal / 50): give a smaller smallest size, or a mesh size of at least " +
                      mm(s.min_size));
  } else {
    r.min_size = s.min_size > 0 ? s.min_size : r.size / MeshDefaults::kMinSizeDivisions;
  }
  r.growth = MeshDefaults::kGrowth;
  const double h = r.size;
  r.estimated_tets = 6.0 * std::abs(volume) / (h * h * h) * 1.2;  // ~6 tets per h³ for a good mesh
  const double memory = memory_bytes < 0 ? physical_memory_bytes() : memory_bytes;
  r.max_tets = max_tets(memory);
  if (r.estimated_tets > r.max_tets) {
    const std::string gb = memory > 0 ? " (" + std::to_string(static_cast<int>(std::lround(memory / 1e9))) + " GB)" : "";
    throw Error(ErrorCode::TooLarge,
                "a mesh size of " + std::to_string(h) + " mm would give about " +
                    std::to_string(static_cast<long>(r.estimated_tets)) + " tetrahedra, more than this machine's memory" +
                    gb + " can optimise; use a mesh size of at least " +
                    std::to_string(h * std::cbrt(r.estimated_tets / r.max_tets)) + " mm");
  }
  return r;
}

mesh::NativeMeshParams native_mesh_params(const MeshSettings& s, const MeshSizes& sizes) {
  mesh::NativeMeshParams p;
  p.surface.size = sizes.size;
  p.surface.min_size = sizes.min_size;
  p.surface.gradation = 1 + sizes.growth;
  p.surface.max_angle = 2 * kPi / MeshDefaults::kElementsPerTurn;
  p.surface.wall_layers = s.wall_layers;
  // the fills stop at twice the budget, should the estimate be off
  p.volume.max_tets = static_cast<long>(2 * (sizes.max_tets > 0 ? sizes.max_tets : max_tets(physical_memory_bytes())));
  return p;
}

mesh::FragmentMeshParams gmsh_mesh_params(const MeshSettings& s, const MeshSizes& sizes) {
  mesh::FragmentMeshParams p;
  p.size = sizes.size;
  p.min_size = sizes.min_size;
  p.elements_per_turn = MeshDefaults::kElementsPerTurn;
  p.volume_by_front = s.gmsh_volume_by_front;
  return p;
}

double gmsh_time_budget(const MeshSettings& s, const MeshSizes& sizes) {
  if (s.gmsh_seconds > 0) return s.gmsh_seconds;
  return MeshDefaults::kGmshBaseSeconds + sizes.estimated_tets / MeshDefaults::kGmshTetsPerSecond;
}

double native_time_budget(const MeshSettings& s, const MeshSizes& sizes) {
  if (s.native_seconds > 0) return s.native_seconds;
  return MeshDefaults::kNativeBaseSeconds + sizes.estimated_tets / MeshDefaults::kNativeTetsPerSecond;
}

}  // namespace topopt::pipeline
