// The job: what to mesh, the material, supports and loads by face name, the optimisation
// settings and the outputs — parsed once from JSON into typed settings and validated whole
// before any work (docs/job-format.md, docs/optimization.md). A key the format does not know
// is an error naming it and the nearest known key; a key written twice is an error; integers
// are whole; numbers finite; every range is checked here, once. A job written by the
// workbench and one written by hand are the same thing.
#pragma once
#include <string>
#include <vector>

#include "fem/boundary_conditions.h"
#include "pipeline/mesh_settings.h"
#include "result/design_hygiene.h"
#include "result/smoothing.h"
#include "simp/optimizer.h"

namespace topopt::pipeline {

/// A displacement limit of the job ("displacement_limits"): the mean displacement of faces
/// along a direction, |u| <= limit; its gauge is built on the mesh (optimize_job).
struct DisplacementSpec {
  std::string name;    ///< "displacement_limits[1] (Face7 along (0, 0, -1))"
  fem::LoadSpec unit;  ///< a force of 1 N along the unit direction, on the faces
  double limit = 0;    ///< mm, > 0
};

/// The "optimization" section (docs/optimization.md).
struct OptimizeSettings {
  simp::SimpParams simp;  ///< the solver's tolerance 1e-5 unless given; responses without gauges
  std::vector<DisplacementSpec> displacement_limits;
  bool filter_automatic = true;  ///< "filter": "auto" (the default): chosen_filter decides the kind
  double threshold = -1;         ///< iso-value of the result shape; < 0: the one that meets the volume fraction
  result::SmoothParams smooth;
  result::HygieneParams hygiene;  ///< loose pieces out, closed voids filled (fill_voids)
  /// "keep_loaded_faces": the design tets on a face a support or a force or pressure acts on
  /// stay solid (one layer; optimize_job), so the result keeps every loaded and supported face.
  bool keep_loaded_faces = true;
};

/// The "output" section.
struct OutputSettings {
  std::string directory;  ///< absolute; default "<job folder>/out"
  bool vtu = true;        ///< solve: DIR/result.vtu
  bool inp = false;       ///< solve: DIR/result.inp, the problem as a CalculiX deck
  bool step = true;       ///< optimize: DIR/result.step, the result as one CAD solid
  /// The largest result surface (triangles) written as result.step; -1: the export's own
  /// budget (result::StepExportParams::max_triangles), 0: any size.
  long step_max_triangles = -1;
  /// optimize: DIR/verification.json and .vtu, the result solid meshed by the native volume mesher
  /// and analysed (result/verification.h).
  bool verification = true;
};

/// A parsed, validated job. Paths are absolute (resolved against the job file's folder).
struct Job {
  std::string base_dir;   ///< folder of the job file ("" for a job given as text)
  std::string part;       ///< Ω: STEP/IGES/BREP path ("" when the shapes come separately or a mesh file is given)
  std::string nondesign;  ///< Ω̄: path, or "" for none
  MeshSettings mesh;      ///< its `file`, when set, is absolute
  fem::Material material;
  std::vector<fem::SupportSpec> supports;
  std::vector<fem::LoadCase> load_cases;
  OptimizeSettings optimization;
  OutputSettings output;
};

/// Loads above these magnitudes are refused: they are no unit a job can mean (N, MPa,
/// mm/s²) and would overflow the solver's products.
struct LoadLimits {
  static constexpr double kForce = 1e12;    ///< N
  static constexpr double kPressure = 1e9;  ///< MPa
  static constexpr double kGravity = 1e12;  ///< mm/s²
};

/// Parses "Face7" → 7 into `faces` and "NonDesign:Face3" → 3 into `nondesign_faces`.
/// Throws Error(FaceNotFound) for any other spelling, naming it.
void parse_face_name(const std::string& name, std::vector<int>& faces, std::vector<int>& nondesign_faces);

/// Reads and validates a job file. Throws Error(Io) for a missing file or invalid JSON,
/// Error(InvalidParameter) naming the key for an unknown, duplicated or wrong value,
/// Error(FaceNotFound) for a malformed face name.
Job read_job(const std::string& path);

/// The same from JSON text; relative paths are resolved against `base_dir` ("" for the
/// current folder).
Job parse_job(const std::string& text, const std::string& base_dir);

/// A job's "optimization" section alone, from JSON text (an object; "" for the defaults), read
/// and checked as parse_job reads it (keys named under "optimization."): what an extraction of a
/// stored result takes from its study's job (pipeline::reextraction). Throws as parse_job.
OptimizeSettings parse_optimization_text(const std::string& text);

/// Throws Error(FaceNotFound) if a support, load or the overhang's base face names a face above `num_faces` (the
/// part's face count), or a non-design face above `num_nondesign_faces` (skipped if < 0).
void check_faces(const Job& job, int num_faces, int num_nondesign_faces);

/// Throws Error(InvalidParameter) saying what to add when the job has no support or no
/// load case (what `solve` and `optimize` need; meshing alone needs neither).
void require_supports_and_loads(const Job& job);

}  // namespace topopt::pipeline
