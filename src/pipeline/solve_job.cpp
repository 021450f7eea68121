// The analysis path of a job (see solve_job.h).
#include "pipeline/solve_job.h"

#include <chrono>
#include <filesystem>

#include "brep/shape_io.h"
#include "brep/topology_index.h"
#include "brep/two_breps.h"
#include "common/error.h"
#include "fem/boundary_conditions.h"
#include "io/inp.h"
#include "io/msh.h"
#include "io/vtu.h"
#include "mesh/core/reorder.h"
#include "mesh/two_brep/gmsh_fragments.h"
#include "mesh/two_brep/native_mesher.h"

namespace topopt::pipeline {
namespace fs = std::filesystem;

namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

TetMesh job_mesh(const io::Job& job, const Progress& progress) {
  if (!job.mesh_file.empty()) {
    if (!job.part.empty()) {
      // Face names are checked against the part itself, so that a typo is reported as such
      // and not as "no triangles on that face".
      TopoDS_Shape part = brep::read_shape_file(job.part);
      int nd_faces = -1;
      if (!job.nondesign.empty()) nd_faces = brep::index_topology(brep::read_shape_file(job.nondesign)).num_faces();
      io::check_faces(job, brep::index_topology(part).num_faces(), nd_faces);
    }
    progress.say("mesh", -1, "reading " + job.mesh_file);
    TetMesh mesh = io::read_msh(job.mesh_file);
    mesh::reorder_for_locality(mesh);  // files from other tools number nodes arbitrarily
    return mesh;
  }
  if (job.part.empty())
    throw Error(
        ErrorCode::InvalidParameter,
        "job file: \"part\" is missing: give the part's STEP/BREP file, or a mesh with \"mesh\": {\"file\": ...}");
  TopoDS_Shape part = brep::read_shape_file(job.part);
  TopoDS_Shape nd = job.nondesign.empty() ? TopoDS_Shape() : brep::read_shape_file(job.nondesign);
  return mesh_job_shapes(job, part, nd, progress);
}

TetMesh mesh_job_shapes(const io::Job& job, const TopoDS_Shape& part, const TopoDS_Shape& nondesign,
                        const Progress& progress) {
  progress.say("mesh", -1, "checking the part and the non-design solids");
  brep::TwoBReps model = brep::load_two_breps(part, nondesign, {}, progress);
  io::check_faces(job, model.part.num_faces(), model.nondesign.num_faces());
  TetMesh mesh = mesh::mesh_two_breps(model, job.mesher, job.mesh_size, job.mesh_min_size, progress, nullptr,
                                      job.mesh_wall_layers);
  // The fronts and Gmsh number nodes in the order they make them; the solver, filter and
  // surface run faster on a numbering that follows space (bench/simp: see BENCHMARKS.md).
  mesh::reorder_for_locality(mesh);
  return mesh;
}

SolveResult solve_job(const io::Job& job, const TetMesh& mesh, const fem::SolverParams& solver, const VecXd& scale,
                      const Progress& progress) {
  if (job.load_cases.empty())
    throw Error(ErrorCode::InvalidParameter, "the job has no load case: add \"load_cases\" with at least one load");
  auto t0 = std::chrono::steady_clock::now();
  fem::Supports supports = fem::make_supports(mesh, job.supports);
  Eigen::MatrixXd F = fem::make_loads(mesh, job.material, job.load_cases);
  fem::Elasticity fe(mesh, job.material, supports, solver);
  if (scale.size()) fe.set_scale(scale);
  SolveResult r;
  r.seconds_setup = seconds_since(t0);
  progress.say("solve", -1, "solving " + std::to_string(fe.num_dofs()) + " unknowns");
  t0 = std::chrono::steady_clock::now();
  r.U = fe.solve(F, progress);
  r.seconds_solve = seconds_since(t0);
  for (size_t c = 0; c < job.load_cases.size(); ++c) {
    r.case_names.push_back(job.load_cases[c].name);
    r.compliance.push_back(F.col(c).dot(r.U.col(c)));
    r.von_mises.push_back(fe.von_mises(r.U.col(c)));
  }
  return r;
}

std::vector<std::string> write_solve_outputs(const io::Job& job, const TetMesh& mesh, const SolveResult& r,
                                             const std::string& dir, const std::string& inp_path) {
  std::vector<std::string> written;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw Error(ErrorCode::Io, "cannot create the output folder " + dir + ": " + ec.message());
  std::vector<io::VtuField> points, cells;
  for (size_t c = 0; c < r.case_names.size(); ++c) {
    io::VtuField u{"displacement_" + r.case_names[c], 3, {}};
    u.values.assign(r.U.col(c).data(), r.U.col(c).data() + r.U.rows());
    points.push_back(std::move(u));
    io::VtuField vm{"von_mises_" + r.case_names[c], 1, {}};
    vm.values.assign(r.von_mises[c].data(), r.von_mises[c].data() + r.von_mises[c].size());
    cells.push_back(std::move(vm));
  }
  if (job.write_vtu) {
    std::string p = (fs::path(dir) / "result.vtu").string();
    io::write_vtu(p, mesh, points, cells);
    written.push_back(p);
  }
  if (!inp_path.empty()) {
    fem::Supports s = fem::make_supports(mesh, job.supports);
    Eigen::MatrixXd F = fem::make_loads(mesh, job.material, job.load_cases);
    io::write_inp(inp_path, mesh, job.material, s, F, 0);
    written.push_back(inp_path);
  }
  return written;
}

}  // namespace topopt::pipeline
