// Python bindings of the mesh stage: the conformal tagged mesh of a job's shapes.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <limits>

#include "bindings/arguments.h"
#include "bindings/bindings.h"
#include "brep/occt_guard.h"
#include "brep/shape_io.h"
#include "brep/solid_check.h"
#include "brep/topology_index.h"
#include "common/error.h"
#include "mesh/core/conformity.h"
#include "mesh/surface/surface_check.h"
#include "mesh/surface/surface_mesher.h"
#include "mesh/volume/volume_front.h"

#include <chrono>
#include <cmath>
#include "mesh/core/tet_quality.h"
#include "pipeline/job_mesh.h"
#include "pipeline/mesh_settings.h"
#include "pipeline/surface_job.h"

namespace topopt::py {

void bind_mesh(pybind11::module_& m) {
  m.def(
      "mesh_shapes",
      [](const pybind11::object& job_arg, const pybind11::object& part_arg, const pybind11::object& nd_arg) {
        const std::string part_brep = text_arg(part_arg, "part_brep"), nd_brep = text_arg(nd_arg, "nondesign_brep");
        const pipeline::Job job = pipeline::parse_job(text_arg(job_arg, "job_json"), "");
        TetMesh mesh;
        mesh::QualityReport q;
        std::vector<std::string> warnings;  // e.g. the mesher fell back to Gmsh
        Progress progress;
        keep_warnings(progress, warnings);
        {
          pybind11::gil_scoped_release release;
          pipeline::JobShapes shapes;
          shapes.part = brep::read_brep_string(part_brep, "part", {}, progress);  // cancellable
          if (!nd_brep.empty()) shapes.nondesign = brep::read_brep_string(nd_brep, "non-design solids", {}, progress);
          mesh = pipeline::job_mesh(job, shapes, progress);
          q = mesh::tet_quality(mesh);
        }
        pybind11::dict out;
        put_tet_mesh(out, mesh);
        out["min_radius_ratio"] = q.min_radius_ratio;
        out["mean_radius_ratio"] = q.mean_radius_ratio;
        out["warnings"] = warnings;
        return out;
      },
      pybind11::arg("job_json"), pybind11::arg("part_brep"), pybind11::arg("nondesign_brep") = "",
      R"doc(The conformal tagged tet mesh of a job's shapes (BREP strings) at the job's mesh size.
Returns a dict: nodes #V x 3, tets #T x 4, domain #T (0 design, i non-design solid i),
boundary_triangles #F x 3 with boundary_faces #F (FreeCAD face numbers of the part) and
boundary_nondesign_faces #F (the non-design compound's face a triangle also lies on, 0: none),
quality figures. The job's "mesh": {"mesher": ...} picks the mesher (default "auto").)doc");

  m.def(
      "surface_mesh",
      [](const pybind11::object& brep_arg, const pybind11::object& size_arg, const pybind11::object& layers_arg) {
        const std::string brep = text_arg(brep_arg, "brep");
        const double size = number_arg(size_arg, "size (mm, 0: the default)", 0, std::numeric_limits<double>::max());
        const double any = std::numeric_limits<double>::max();
        const int wall_layers = mesh::wall_layers_option(number_arg(layers_arg, "wall_layers", -any, any));
        pipeline::SurfaceJobResult r;
        {
          pybind11::gil_scoped_release release;
          std::vector<std::string> notes;  // a healed shape is meshed as healed
          const brep::TopologyIndex topo =
              pipeline::checked_topology(brep::read_brep_string(brep, "shape"), "shape", notes);
          pipeline::MeshSettings settings;  // the sizes, clamp and element budget of every mesher
          settings.size = size;
          settings.wall_layers = wall_layers;
          r = pipeline::surface_job(topo, settings);
        }
        const mesh::SurfaceMesh& sm = r.mesh;
        pybind11::dict out;
        out["nodes"] = sm.V;
        out["triangles"] = sm.F;
        out["faces"] = sm.face;
        out["failed_faces"] = sm.failed_faces;
        out["failure_reasons"] = sm.reasons;
        out["open_edges_per_solid"] = r.open_edges_per_solid;
        out["self_intersecting_pairs"] = r.crossings.size();
        out["min_angle"] = r.quality.min_angle;
        out["share_below_20deg"] = r.quality.share_below_20;
        return out;
      },
      pybind11::arg("brep"), pybind11::arg("size") = 0.0, pybind11::arg("wall_layers") = 0,
      R"doc(The native surface mesh of one model (a BREP string) at `size` mm (0: diagonal / 50);
wall_layers > 0 refines walls thinner than two sizes to about that many layers across.
Returns a dict: nodes #V x 3, triangles #F x 3 (outward), faces #F (FreeCAD face numbers),
failed_faces with failure_reasons, open_edges_per_solid (0 = closed and oriented),
self_intersecting_pairs (within each solid, at most 100 counted), min_angle (degrees) and
share_below_20deg.)doc");

  m.def(
      "volume_mesh",
      [](const pybind11::object& nodes_arg, const pybind11::object& triangles_arg, const pybind11::object& size_arg,
         bool delaunay_bulk) {
        const MatX3d nodes = points_arg(nodes_arg, "nodes", "#V");
        const MatX3i triangles = index_arg<3>(triangles_arg, "triangles", nodes.rows(), "nodes");
        const double size =
            number_arg(size_arg, "size (mm, 0: from the boundary)", 0, std::numeric_limits<double>::max());
        mesh::VolumeFillResult r;
        double seconds = 0;
        {
          pybind11::gil_scoped_release release;
          mesh::VolumeFillParams p;
          if (size > 0) p.size = [size](const double*) { return size; };
          p.delaunay_bulk = delaunay_bulk;
          const auto t0 = std::chrono::steady_clock::now();
          r = mesh::fill_volume(nodes, triangles, MatX4i(), p);
          seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        }
        pybind11::dict out;
        out["nodes"] = r.V;
        out["tets"] = r.T;
        out["seconds"] = seconds;
        return out;
      },
      pybind11::arg("nodes"), pybind11::arg("triangles"), pybind11::arg("size") = 0.0,
      pybind11::arg("delaunay_bulk") = true,
      R"doc(Fills the closed surface (nodes #V x 3, triangles #F x 3 oriented outwards) with tets by
a Delaunay bulk finished by the 3D advancing front (delaunay_bulk=False: the front alone), target
size `size` inside (0: from the boundary). Returns a dict:
nodes (the input nodes first, unchanged), tets #T x 4 (positive), seconds (the fill alone).)doc");
}

}  // namespace topopt::py
