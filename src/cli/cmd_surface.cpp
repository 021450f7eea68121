// topopt surface: the native surface mesh of one model (steps 1, 5 and 9 for a single B-Rep),
// with its checks: closed and oriented per solid, self-intersections, angles.
#include <chrono>
#include <cmath>
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
#include "pipeline/mesh_settings.h"
#include "pipeline/surface_job.h"
#include "pipeline/output_files.h"

namespace topopt::cli {

int cmd_surface(const Args& args) {
  ArgReader a(args,
              "usage: topopt surface --part PART [--size H] [--min-size H0] [--wall-layers N] [--out FILE.stl]\n"
              "                      [--stats STATS.json] [--time-budget S]\n"
              "  Meshes every face of PART (STEP or BREP) with the native surface mesher: a closed,\n"
              "  consistently oriented triangulation per solid, each triangle tagged with its face.\n"
              "  --size   target edge length in mm (default: part diagonal / 50; above the diagonal:\n"
              "           the diagonal, with a warning; a size asking for too many elements is refused,\n"
              "           as by topopt mesh)\n"
              "  --min-size  smallest edge length in mm (default: size / 10)\n"
              "  --wall-layers N  walls thinner than two sizes get about N element layers across\n"
              "           (sizes from the wall thickness, measured by rays; default 0: off)\n"
              "  --out    binary STL; each triangle's attribute bytes hold its face number (FaceN)\n"
              "  --stats  counts, open edges per solid, self-intersections, angles, time (JSON)\n"
              "  --time-budget S  seconds allowed for reading, or checking and healing, the part\n"
              "           (default: 30 s + 15 s per MB of file)\n"
              "  Exit code 1 if a face failed, a solid is not closed or the surface intersects itself.");
  if (a.print_help()) return 0;
  const std::string part = a.option("part"), out = a.option("out"), stats = a.option("stats");
  pipeline::MeshSettings settings;
  settings.size = a.number("size", 0);
  settings.min_size = a.number("min-size", 0);
  settings.wall_layers = mesh::wall_layers_option(a.number("wall-layers", 0));
  const brep::ForeignParams budget = a.time_budget();
  if (!a.positionals().empty() || part.empty()) throw Error(ErrorCode::InvalidParameter, "give --part\n" + a.usage());
  pipeline::check_mesh_settings(settings, "--size", "--min-size");
  if (!out.empty() && std::filesystem::path(out).extension() != ".stl")
    throw Error(ErrorCode::InvalidParameter, "--out must end in .stl");
  for (const auto& [file, option] : {std::pair{out, "--out"}, std::pair{stats, "--stats"}})
    if (!file.empty()) pipeline::prepare_output_folder(std::filesystem::absolute(file).parent_path().string(), option);
  using clock = std::chrono::steady_clock;
  auto t0 = clock::now();
  std::vector<std::string> notes;  // repairs: a healed part is meshed as healed
  const brep::TopologyIndex topo =
      pipeline::checked_topology(brep::read_shape_file(part, "part", budget), "part", notes, budget);
  for (const std::string& note : notes) std::cerr << "note: " << note << "\n";
  auto t1 = clock::now();
  // the same sizes, clamp and element budget as topopt mesh (pipeline/mesh_settings.h)
  Progress progress;
  progress.log = [](LogLevel level, const std::string& msg) {
    if (level == LogLevel::Warning) std::cerr << "warning: " << msg << "\n";
  };
  const pipeline::SurfaceJobResult r = pipeline::surface_job(topo, settings, progress);
  auto t2 = clock::now();
  const mesh::SurfaceMesh& m = r.mesh;
  const std::vector<long>& open = r.open_edges_per_solid;
  const auto& crossings = r.crossings;
  const mesh::SurfaceQuality& q = r.quality;
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
    pipeline::write_replacing(
        out, [&](const std::string& path) { io::write_stl(path, m.V, m.F, "TopOpt surface mesh", &m.face); });
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
    pipeline::write_replacing(stats, [&](const std::string& path) {
      std::ofstream f(path);
      f << j.dump(2) << "\n";
      if (!f) throw Error(ErrorCode::Io, "cannot write " + stats);
    });
  }
  return r.ok() ? 0 : 1;
}

}  // namespace topopt::cli
