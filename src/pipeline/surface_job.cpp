// surface_job: sizes → surface mesh → checks (see surface_job.h).
#include "pipeline/surface_job.h"

#include <chrono>
#include <cmath>

#include "brep/occt_guard.h"
#include "brep/solid_check.h"

namespace topopt::pipeline {

bool SurfaceJobResult::ok() const {
  long open = 0;
  for (long o : open_edges_per_solid) open += o;
  return mesh.failed_faces.empty() && open == 0 && crossings.empty();
}

brep::TopologyIndex checked_topology(const TopoDS_Shape& shape, const std::string& what,
                                     std::vector<std::string>& notes, const brep::ForeignParams& budget,
                                     const Progress& progress) {
  const TopoDS_Shape checked = brep::check_solids(shape, what, notes, budget, progress);
  return brep::guard_occt("indexing the " + what, [&] { return brep::index_topology(checked); });
}

SurfaceJobResult surface_job(const brep::TopologyIndex& topo, const MeshSettings& settings, const Progress& progress) {
  const MeshSizes sizes = resolve_mesh_sizes(settings, topo.diagonal(), std::abs(topo.solid_volume.sum()), progress);
  mesh::SurfaceMeshParams p;
  p.size = sizes.size;
  p.min_size = sizes.min_size;
  p.wall_layers = settings.wall_layers;
  SurfaceJobResult r;
  const auto t0 = std::chrono::steady_clock::now();
  progress.say("mesh", 0, "meshing the faces");
  r.mesh = mesh::mesh_surface(topo, p, progress);
  r.seconds_mesh = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  progress.say("mesh", 0.9, "checking the surface");
  r.open_edges_per_solid = mesh::open_edges_per_solid(topo, r.mesh);
  constexpr long kMaxCrossings = 100;
  for (int s = 0; s < topo.num_solids() && static_cast<long>(r.crossings.size()) < kMaxCrossings; ++s) {
    const auto c = mesh::self_intersections(r.mesh.V, mesh::solid_triangles(topo, r.mesh, s),
                                            kMaxCrossings - static_cast<long>(r.crossings.size()));
    r.crossings.insert(r.crossings.end(), c.begin(), c.end());
  }
  r.quality = mesh::surface_quality(r.mesh.V, r.mesh.F);
  return r;
}

}  // namespace topopt::pipeline
