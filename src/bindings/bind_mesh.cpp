// Python bindings of the mesh stage: the conformal tagged mesh of a job's shapes.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings/bindings.h"
#include "brep/shape_io.h"
#include "common/error.h"
#include "io/job.h"
#include "mesh/conformity.h"
#include "mesh/tet_quality.h"
#include "pipeline/solve_job.h"

namespace topopt::py {

void bind_mesh(pybind11::module_& m) {
  m.def(
      "mesh_shapes",
      [](const std::string& job_json, const std::string& part_brep, const std::string& nd_brep) {
        io::Job job = io::parse_job(job_json, "");
        TetMesh mesh;
        mesh::QualityReport q;
        {
          pybind11::gil_scoped_release release;
          TopoDS_Shape part = brep::read_brep_string(part_brep, "part");
          TopoDS_Shape nd = nd_brep.empty() ? TopoDS_Shape() : brep::read_brep_string(nd_brep, "non-design solids");
          mesh = pipeline::mesh_job_shapes(job, part, nd);
          q = mesh::tet_quality(mesh);
        }
        pybind11::dict out;
        out["nodes"] = mesh.V;
        out["tets"] = mesh.T;
        out["domain"] = mesh.domain;
        out["boundary_triangles"] = mesh.F;
        out["boundary_faces"] = mesh.face;
        out["min_radius_ratio"] = q.min_radius_ratio;
        out["mean_radius_ratio"] = q.mean_radius_ratio;
        return out;
      },
      pybind11::arg("job_json"), pybind11::arg("part_brep"), pybind11::arg("nondesign_brep") = "",
      R"doc(The conformal tagged tet mesh of a job's shapes (BREP strings) at the job's mesh size.
Returns a dict: nodes #V x 3, tets #T x 4, domain #T (0 design, i non-design solid i),
boundary_triangles #F x 3 with boundary_faces #F (FreeCAD face numbers), quality figures.)doc");
}

}  // namespace topopt::py
