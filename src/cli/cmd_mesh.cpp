// topopt mesh: one conformal, tagged tet mesh of the part and its non-design solids.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "brep/shape_io.h"
#include "brep/two_breps.h"
#include "cli/commands.h"
#include "common/error.h"
#include "io/inp.h"
#include "io/msh.h"
#include "io/vtu.h"
#include "mesh/core/conformity.h"
#include "mesh/core/reorder.h"
#include "mesh/core/tet_quality.h"
#include "mesh/two_brep/gmsh_fragments.h"
#include "mesh/two_brep/native_mesher.h"

namespace topopt::cli {

int cmd_mesh(const Args& args) {
  ArgReader a(
      args,
      "usage: topopt mesh --part PART [--non-design ND] [--size H] [--min-size H0] [--wall-layers N] --out FILE\n"
      "                   [--stats STATS.json] [--mesher auto|native|gmsh] [--volume gmsh|native]\n"
      "                   [--time-budget S]\n"
      "  Meshes the part and the non-design solids into one conformal tet mesh: domain 1 =\n"
      "  design, 2.. = non-design solids in input order; boundary triangles tagged with the\n"
      "  part's face numbers (FreeCAD's FaceN).\n"
      "  --out    FILE.msh (Gmsh MSH 4.1), FILE.vtu (ParaView) or FILE.inp (CalculiX mesh)\n"
      "  --size   target element size in mm (default: part diagonal / 50)\n"
      "  --wall-layers N  (native) walls thinner than two sizes get about N layers across\n"
      "  --stats  counts per domain, volumes, quality, conformity and time per stage (JSON)\n"
      "  --mesher native: the two-B-Rep advancing front (the 14 steps: no boolean of the part\n"
      "           with the non-design solids); gmsh: OCC fragments of both, meshed by Gmsh;\n"
      "           auto (default): native, and gmsh with a warning where native fails\n"
      "  --volume native with --mesher gmsh: Gmsh's surfaces filled by our 3D front\n"
      "           (a comparison aid)\n"
      "  --time-budget S  seconds allowed for reading, or checking and healing, each input\n"
      "           (default: 30 s + 15 s per MB of file)");
  if (a.print_help()) return 0;
  std::string part = a.option("part"), nd = a.option("non-design"), out = a.option("out"), stats = a.option("stats");
  mesh::FragmentMeshParams mp;
  mp.size = a.number("size", 0);
  mp.min_size = a.number("min-size", 0);
  const int wall_layers = mesh::wall_layers_option(a.number("wall-layers", 0));
  const brep::ForeignParams budget = a.time_budget();
  std::string volume = a.option("volume", "gmsh"), mesher = a.option("mesher", "auto");
  if (mesher != "auto" && mesher != "gmsh" && mesher != "native")
    throw Error(ErrorCode::InvalidParameter, "--mesher takes auto, native or gmsh");
  if (volume != "gmsh" && volume != "native") throw Error(ErrorCode::InvalidParameter, "--volume takes gmsh or native");
  mp.native_volume = volume == "native";
  if (!a.positionals().empty() || part.empty() || out.empty())
    throw Error(ErrorCode::InvalidParameter, "give --part and --out\n" + a.usage());
  if (mp.size < 0 || mp.min_size < 0) throw Error(ErrorCode::InvalidParameter, "mesh sizes must be positive (mm)");
  std::string ext = std::filesystem::path(out).extension().string();
  if (ext != ".msh" && ext != ".vtu" && ext != ".inp")
    throw Error(ErrorCode::InvalidParameter, "--out must end in .msh, .vtu or .inp");
  using clock = std::chrono::steady_clock;
  auto t0 = clock::now();
  TopoDS_Shape p = brep::read_shape_file(part, "part", budget);
  TopoDS_Shape n = nd.empty() ? TopoDS_Shape() : brep::read_shape_file(nd, "non-design input", budget);
  brep::TwoBReps model = brep::load_two_breps(p, n, {}, {}, budget);
  auto t1 = clock::now();
  Progress progress;
  progress.report = [](const std::string& stage, double, const std::string& msg) {
    std::cerr << "[" << stage << "] " << msg << "\n";
  };
  const bool verbose = getenv("TOPOPT_VERBOSE") != nullptr;
  progress.log = [verbose](LogLevel level, const std::string& msg) {
    if (verbose || level == LogLevel::Warning)
      std::cerr << (level != LogLevel::Warning ? "  " : "warning: ") << msg << "\n";
  };
  TetMesh m;
  if (mesher != "gmsh" && mp.native_volume)
    throw Error(ErrorCode::InvalidParameter,
                "--volume native goes with --mesher gmsh (the native mesher fills its volumes itself)");
  mesh::MeshRun run;
  if (mp.native_volume)
    m = mesh::mesh_with_gmsh_fragments(model, mp, progress), run.mesher = "gmsh surfaces + native volumes";
  else
    m = mesh::mesh_two_breps(model, mesher, mp.size, mp.min_size, progress, &run, wall_layers);
  mesh::reorder_for_locality(m);  // node numbers that follow space (faster solves downstream)
  auto t2 = clock::now();
  if (ext == ".msh")
    io::write_msh(out, m);
  else if (ext == ".vtu")
    io::write_vtu(out, m, {}, {});
  else
    io::write_inp(out, m, fem::Material{}, fem::Supports{}, Eigen::MatrixXd(), 0);
  auto t3 = clock::now();
  mesh::ConformityReport conf = mesh::check_conformity(m, &model);
  mesh::QualityReport q = mesh::tet_quality(m);
  std::vector<long> per_domain(m.domain.size() ? m.domain.maxCoeff() + 1 : 1, 0);
  for (long t = 0; t < m.domain.size(); ++t) per_domain[m.domain[t]]++;
  std::cout << "mesh: " << m.V.rows() << " nodes, " << m.T.rows() << " tets (";
  for (size_t d = 0; d < per_domain.size(); ++d)
    std::cout << (d ? ", " : "") << (d ? "non-design " + std::to_string(d) : std::string("design")) << " "
              << per_domain[d];
  std::cout << "), " << m.F.rows() << " boundary triangles\n"
            << "quality: radius ratio min " << q.min_radius_ratio << " mean " << q.mean_radius_ratio
            << ", dihedral min " << q.min_dihedral << " deg\n"
            << "conformity: " << (conf.ok() ? "ok" : "DEFECTS (see --stats)") << ", largest volume error "
            << 100 * conf.max_volume_error << " %\n"
            << "wrote " << out << "\n";
  if (!stats.empty()) {
    auto sec = [](clock::time_point a, clock::time_point b) { return std::chrono::duration<double>(b - a).count(); };
    nlohmann::json j;
    j["nodes"] = m.V.rows();
    j["tets"] = m.T.rows();
    j["tets_per_domain"] = per_domain;
    j["boundary_triangles"] = m.F.rows();
    j["quality"] = q.to_json();
    j["conformity"] = conf.to_json();
    j["seconds"] = {{"read_and_classify", sec(t0, t1)}, {"mesh", sec(t1, t2)}, {"write", sec(t2, t3)}};
    j["mesher"] = run.mesher;
    if (!run.fallback_reason.empty()) j["native_failed"] = run.fallback_reason;
    for (const auto& [stage, t] : run.seconds) j["seconds_per_stage"][stage] = t;
    std::ofstream f(stats);
    f << j.dump(2) << "\n";
    if (!f) throw Error(ErrorCode::Io, "cannot write " + stats);
    std::cout << "wrote " << stats << "\n";
  }
  return conf.ok() ? 0 : 1;
}

}  // namespace topopt::cli
