// Python bindings of the fem stage: a linear static solve on arrays.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings/arguments.h"
#include "bindings/bindings.h"
#include "common/error.h"
#include "pipeline/job.h"
#include "pipeline/solve_job.h"

namespace topopt::py {

void bind_fem(pybind11::module_& m) {
  m.def(
      "solve",
      [](const pybind11::object& nodes_arg, const pybind11::object& tets_arg, const pybind11::object& tris_arg,
         const pybind11::object& tri_face_arg, const pybind11::object& domain_arg, const pybind11::object& job_arg) {
        TetMesh mesh;
        mesh.V = points_arg(nodes_arg, "nodes", "#V");
        mesh.T = index_arg<4>(tets_arg, "tets", mesh.V.rows(), "nodes");
        mesh.F = index_arg<3>(tris_arg, "tris", mesh.V.rows(), "nodes");
        mesh.face = tags_arg(tri_face_arg, "tri_face", mesh.F.rows(), "triangle", 0);
        mesh.domain = tags_arg(domain_arg, "domain", mesh.T.rows(), "tet", 0, true);
        if (mesh.domain.size() == 0) mesh.domain = VecXi::Zero(mesh.T.rows());
        const std::string job_json = text_arg(job_arg, "job_json");
        const MatX3d& nodes = mesh.V;
        pipeline::SolveResult r;
        {
          pybind11::gil_scoped_release release;
          const pipeline::Job job = pipeline::parse_job(job_json, "");
          r = pipeline::solve_job(job, mesh);
        }
        pybind11::dict out;
        pybind11::list disp, vm;
        for (size_t c = 0; c < r.case_names.size(); ++c) {
          MatX3d U = Eigen::Map<const MatX3d>(r.U.col(c).data(), nodes.rows(), 3);
          disp.append(U);
          vm.append(r.von_mises[c]);
        }
        out["case_names"] = r.case_names;
        out["displacement"] = disp;
        out["von_mises"] = vm;
        out["compliance"] = r.compliance;
        return out;
      },
      pybind11::arg("nodes"), pybind11::arg("tets"), pybind11::arg("tris"), pybind11::arg("tri_face"),
      pybind11::arg("domain"), pybind11::arg("job_json"),
      R"doc(Linear static analysis on a tet mesh.

nodes #V x 3 (mm), tets #T x 4 (0-based), tris #F x 3 boundary triangles with tri_face #F
(FreeCAD face numbers, 1-based), domain #T (0 design, i non-design solid i); job_json: the
job file text (material, supports, load_cases; see docs/job-format.md). Returns a dict:
case_names, displacement (one #V x 3 array per case), von_mises (#T per case), compliance.
Raises TopOptError (.code "NoSupport", "FaceNotFound", ...) naming what to fix.)doc");
  m.def(
      "check_job",
      [](const pybind11::object& job_arg) {
        const std::string job_json = text_arg(job_arg, "job_json");
        pybind11::gil_scoped_release release;
        pipeline::parse_job(job_json, "");
      },
      pybind11::arg("job_json"),
      R"doc(Checks a job as `topopt optimize` does before it starts (parse_job: every key and
value, no shapes read, nothing run). job_json: the job file text. Returns None; raises
TopOptError (.code "InvalidParameter", ...) naming the key and what to give instead.)doc");
}

}  // namespace topopt::py
