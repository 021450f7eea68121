// topopt surface: the native surface mesh of one model (steps 1, 5 and 9 for a single B-Rep),
// with its checks: closed and oriented per solid, self-intersections, angles.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "brep/occt_guard.h"
#include "brep/shape_io.h"
#include "brep/solid_check.h"
#include "brep/topology_index.h"
#include "cli/commands.h"
#include "common/error.h"
#include "io/stl.h"
#include "mesh/surface/surface_check.h"
#include "mesh/surface/surface_mesher.h"

namespace topopt::cli {

int cmd_surface(const Args& args) {
  ArgReader a(args,
              "usage: topopt surface --part PART [--size H] [--min-size H0] [--wall-layers N] [--out FILE.stl]\n"
              "                      [--stats STATS.json] [--time-budget S]\n"
              "  Meshes every face of PART (STEP or BREP) with the native surface mesher: a closed,\n"
              "  consistently oriented triangulation per solid, each triangle tagged with its face.\n"
              "  --size   target edge length in mm (default: part diagonal / 50)\n"
              "  --wall-layers N  walls thinner than two sizes get about N element layers across\n"
              "           (sizes from the wall thickness, measured by rays; default 0: off)\n"
              "  --out    binary STL; each triangle's attribute bytes hold its face number (FaceN)\n"
              "  --stats  counts, open edges per solid, self-intersections, angles, time (JSON)\n"
              "  --time-budget S  seconds allowed for reading, or checking and healing, the part\n"
              "           (default: 30 s + 15 s per MB of file)\n"
              "  Exit code 1 if a face failed, a solid is not closed or the surface intersects itself.");
  if (a.print_help()) return 0;
  const std::string part = a.option("part"), out = a.option("out"), stats = a.option("stats");
  mesh::SurfaceMeshParams p;
  p.size = a.number("size", 0);
  p.min_size = a.number("min-size", 0);
  p.wall_layers = mesh::wall_layers_option(a.number("wall-layers", 0));
  const brep::ForeignParams budget = a.time_budget();
  if (!a.positionals().empty() || part.empty()) throw Error(ErrorCode::InvalidParameter, "give --part\n" + a.usage());
  if (p.size < 0 || p.min_size < 0) throw Error(ErrorCode::InvalidParameter, "mesh sizes must be positive (mm)");
  if (!out.empty() && std::filesystem::path(out).extension() != ".stl")
    throw Error(ErrorCode::InvalidParameter, "--out must end in .stl");
  using clock = std::chrono::steady_clock;
  auto t0 = clock::now();
  std::vector<std::string> notes;  // repairs: a healed part is meshed as healed
  const TopoDS_Shape shape = brep::check_solids(brep::read_shape_file(part, "part", budget), "part", notes, budget);
  for (const std::string& note : notes) std::cerr << "note: " << note << "\n";
  brep::TopologyIndex topo = brep::guard_occt("indexing the part", [&] { return brep::index_topology(shape); });
  auto t1 = clock::now();
  mesh::SurfaceMesh m = mesh::mesh_surface(topo, p);
  auto t2 = clock::now();
  const std::vector<long> open = mesh::open_edges_per_solid(topo, m);
  // self-intersection per solid: solids of one model may touch each other (the bracket's
  // clamp pads), where their separate faces coincide by design
  std::vector<std::pair<int, int>> crossings;
  for (int s = 0; s < topo.num_solids() && crossings.size() < 100; ++s) {
    const auto c =
        mesh::self_intersections(m.V, mesh::solid_triangles(topo, m, s), 100 - static_cast<long>(crossings.size()));
    crossings.insert(crossings.end(), c.begin(), c.end());
  }
  const mesh::SurfaceQuality q = mesh::surface_quality(m.V, m.F);
  long open_total = 0;
  for (long o : open) open_total += o;
  auto sec = [](clock::time_point x, clock::time_point y) { return std::chrono::duration<double>(y - x).count(); };
  std::cout << "surface: " << m.V.rows() << " nodes, " << m.F.rows() << " triangles on " << topo.num_faces()
            << " faces, " << sec(t1, t2) << " s\n"
            << "angles: smallest " << q.min_angle << " deg, mean smallest " << q.mean_min_angle << " deg, "
            << 100 * q.share_below_20 << " % below 20 deg\n"
            << "checks: " << m.failed_faces.size() << " failed faces, " << open_total << " open edges, "
            << crossings.size() << (crossings.size() >= 100 ? "+" : "") << " intersecting pairs (within a solid)\n";
  for (size_t k = 0; k < m.failed_faces.size(); ++k)
    std::cout << "  Face" << m.failed_faces[k] << ": " << m.reasons[k] << "\n";
  if (!out.empty()) {
    io::write_stl(out, m.V, m.F, "TopOpt surface mesh", &m.face);
    std::cout << "wrote " << out << "\n";
  }
  if (!stats.empty()) {
    nlohmann::json j;
    j["nodes"] = m.V.rows();
    j["triangles"] = m.F.rows();
    j["faces"] = topo.num_faces();
    j["failed_faces"] = m.failed_faces;
    j["open_edges_per_solid"] = open;
    j["self_intersecting_pairs"] = crossings.size();
    j["quality"] = {{"min_angle_deg", q.min_angle},
                    {"mean_min_angle_deg", q.mean_min_angle},
                    {"share_below_20deg", q.share_below_20},
                    {"mean_shape", q.mean_quality}};
    j["seconds"] = {{"read", sec(t0, t1)}, {"mesh", sec(t1, t2)}};
    std::ofstream f(stats);
    f << j.dump(2) << "\n";
    if (!f) throw Error(ErrorCode::Io, "cannot write " + stats);
  }
  return m.failed_faces.empty() && open_total == 0 && crossings.empty() ? 0 : 1;
}

}  // namespace topopt::cli
