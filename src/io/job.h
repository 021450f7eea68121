// Job files (JSON): what to mesh, the material, supports and loads by face name, the
// optimisation settings and the outputs. The format is documented in docs/job-format.md; a
// job written by the workbench and one written by hand are the same thing.
#pragma once
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "fem/boundary_conditions.h"

namespace topopt::io {

/// A parsed job. Paths are absolute (resolved against the job file's folder). `raw` keeps
/// the whole document for the stages that read their own section ("optimization").
struct Job {
  nlohmann::json raw;
  std::string base_dir;      ///< folder of the job file ("" for a job given as text)
  std::string part;          ///< Ω: STEP/IGES/BREP path ("" if a mesh file is given, or the
                             ///< shapes come separately, as from the workbench)
  std::string nondesign;     ///< Ω̄: path, or "" for none
  std::string mesh_file;     ///< a ready MSH 4.1 mesh, or ""
  double mesh_size = 0;      ///< target element size (mm); 0 = automatic
  int mesh_wall_layers = 0;  ///< layers across thin walls (native mesher; 0 = no refinement)
  double mesh_min_size = 0;  ///< smallest size (mm); 0 = automatic
  /// "native": the two-B-Rep advancing front (14 steps); "gmsh": OCC fragments + Gmsh;
  /// "auto": native, falling back to gmsh with a warning where native cannot close a mesh.
  std::string mesher = "auto";
  fem::Material material;
  std::vector<fem::SupportSpec> supports;
  std::vector<fem::LoadCase> load_cases;
  std::string output_dir;  ///< absolute; default "<job folder>/out"
  bool write_vtu = true;
  bool write_inp = false;
};

/// Parses "Face7" → 7 and "NonDesign:Face3" → (nd) 3. Throws Error(FaceNotFound) for any
/// other spelling, naming it.
void parse_face_name(const std::string& name, std::vector<int>& faces, std::vector<int>& nd_faces);

/// Reads and validates a job file. Throws Error(Io) for a missing or malformed file and
/// Error(InvalidParameter) naming the offending key for a wrong value.
Job read_job(const std::string& path);

/// The same from JSON text; relative paths are resolved against `base_dir`.
Job parse_job(const std::string& text, const std::string& base_dir);

/// Throws Error(FaceNotFound) if a support or load names a face above `num_faces` (the
/// part's face count), or a non-design face above `num_nd_faces` (skipped if < 0).
void check_faces(const Job& job, int num_faces, int num_nd_faces);

}  // namespace topopt::io
