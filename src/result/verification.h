// Verification of the result shape by analysis: the closed result surface filled with tets by
// the code's own volume mesher (mesh/volume/volume_front.h) and solved with the study's
// supports and loads, next to the crisp design on the FE mesh solved the same way. Supports and
// loads act on Ω's faces and the non-design solids' faces; both survive on the result (the
// surface's triangle tags say which Ω face a triangle lies on, and the FE mesh's boundary says
// which non-design face), so the same job applies to both meshes.
#pragma once
#include <vector>

#include "common/progress.h"
#include "common/types.h"
#include "fem/boundary_conditions.h"
#include "mesh/volume/volume_front.h"
#include "result/iso_surface.h"

namespace topopt::result {

struct VerificationParams {
  /// Wall-time backstop of meshing the result and solving (<= 0: none). The fill itself stops
  /// by name within its CPU budget (VolumeFillParams::cpu_seconds, proportional to its tets);
  /// this only catches what that cannot (a machine so loaded that the wall clock runs 20 to
  /// 30 times the CPU time, as measured on the shared 2-core machine, must not lose the result).
  double seconds = 1800;
  mesh::VolumeFillParams fill;   ///< the volume mesher's settings (default: size graded from the surface)
  fem::SolverParams solver;      ///< the linear solver (default: chosen by size)
  double void_stiffness = 1e-9;  ///< the crisp design's removed tets keep this share of E (as SIMP's void)
};

/// The study's problem: what verify_result solves on each mesh.
struct VerificationProblem {
  fem::Material material;
  std::vector<fem::SupportSpec> supports;
  std::vector<fem::LoadCase> load_cases;
  /// The study's von Mises limit (MPa, optimization.stress_limit); <= 0: none. verify_result
  /// warns when the result solid's largest stress exceeds it.
  double stress_limit = 0;
};

/// One analysis: compliance summed over the load cases with their weights (N·mm), the largest
/// displacement length (mm) and von Mises stress (MPa) over the cases, and the mesh's size.
struct AnalysisFigures {
  double compliance = 0;
  double max_displacement = 0;
  double max_von_mises = 0;
  long tets = 0;
  long nodes = 0;
  double seconds = 0;      ///< meshing (as built only) and solving, wall time
  double cpu_seconds = 0;  ///< the same in CPU time (the meshing child's and this process's, all threads)
};

struct Verification {
  AnalysisFigures as_built;  ///< the result solid, meshed by fill_volume
  AnalysisFigures crisp;     ///< the crisp design's tets on the FE mesh (void at void_stiffness)
  TetMesh mesh;              ///< the verification mesh: tets of the result, F the result surface with Ω's face tags
  Eigen::MatrixXd U;         ///< (3 #V) by #cases displacements on `mesh`
  std::vector<VecXd> von_mises;  ///< per case, #T of `mesh` (MPa)
  /// Pieces of the result solid that do not carry the loads by the hygiene's rule
  /// (piece_fates: a detached non-design solid the design does not reach, held or not): left
  /// out of `mesh` and the as-built analysis (they carry nothing, and an unheld one would make
  /// it singular), their volumes here (mm³).
  std::vector<double> unheld_volumes;
  double ratio() const { return crisp.compliance > 0 ? as_built.compliance / crisp.compliance : 0; }
  /// False when the crisp design on the FE mesh does not carry the load while the result solid
  /// does: its compliance is over kCrispCut times the as-built one, which only void-stiffness
  /// tets in the load path give (members of the result thinner than one FE tet, whose tets'
  /// mean density stays below the threshold: a design that has not converged). The ratio then
  /// compares nothing and is not to be shown as a ratio.
  bool crisp_carries_load() const {
    constexpr double kCrispCut = 1e3;
    return as_built.compliance <= 0 || crisp.compliance <= kCrispCut * as_built.compliance;
  }
};

/// The tet mesh inside the closed surface `s` (its unused points dropped; F oriented
/// outwards): tets from fill_volume, F = s.F, `face` the Ω face tags (0 where the triangle
/// lies on the iso-surface or a non-design solid inside Ω), `nd_face` taken from the FE mesh
/// `fe` boundary triangle each tagged triangle lies on. The fill runs in a child process
/// (run_isolated) stopped after `seconds` (<= 0: no limit): throws what fill_volume throws,
/// Error(Timeout) past the budget, Error(Crashed) if the child dies.
TetMesh verification_mesh(const TriSurface& s, const TetMesh& fe, const mesh::VolumeFillParams& fill, double seconds,
                          const Progress& progress = {});

/// Solves `problem` on `mesh` with element stiffness factors `scale` (#T, empty: all 1) and
/// loads built on `loaded` (the same nodes as mesh; its tets carry the weight). Returns the
/// figures over the tets whose scale is 1 and their nodes; U and von Mises when asked for.
AnalysisFigures analyse(const TetMesh& mesh, const TetMesh& loaded, const VerificationProblem& problem,
                        const VecXd& scale, const fem::SolverParams& solver, const Progress& progress = {},
                        Eigen::MatrixXd* U = nullptr, std::vector<VecXd>* von_mises = nullptr);

/// The verification: `s` meshed and solved (as built) and the crisp design of `design` (#T
/// element densities after hygiene, cut at `threshold` as the surface was) solved on `fe`.
/// The whole runs within params.seconds: past it, Error(Timeout) naming the step. Pieces of
/// the result (tets sharing nodes) go by the hygiene's rule (piece_fates): those that do not
/// carry the loads are left out (Verification::unheld_volumes, a warning through progress)
/// when no load acts on them; Error(NoSupport) naming the piece when one does, or when a piece
/// kept holds a load and no support (the design does not carry that load). With a stress limit
/// in `problem`, a warning through progress when the result solid's largest von Mises stress
/// exceeds it: the figure, its load case and place, and the crisp design's largest stress.
/// Throws Error(FaceNotFound) naming the face when the result has nothing left of a face a load
/// or support acts on (the design removed the material there: the message says to keep
/// optimization.keep_loaded_faces on), and what fill_volume and fem throw (MeshingFailed).
Verification verify_result(const TriSurface& s, const TetMesh& fe, const VecXd& design, double threshold,
                           const VerificationProblem& problem, const VerificationParams& params = {},
                           const Progress& progress = {});

}  // namespace topopt::result
