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
#include "mesh/surface/surface_mesher.h"
#include "pipeline/mesh_model.h"
#include "pipeline/output_files.h"

namespace topopt::cli {
namespace {

using clock = std::chrono::steady_clock;

const char* kUsage =
    "usage: topopt mesh --part PART [--non-design ND] [--size H] [--min-size H0] [--wall-layers N] --out FILE\n"
    "                   [--stats STATS.json] [--mesher auto|native|gmsh] [--volume gmsh|native]\n"
    "                   [--time-budget S]\n"
    "  Meshes the part and the non-design solids into one conformal tet mesh: domain 1 =\n"
    "  design, 2.. = non-design solids in input order; boundary triangles tagged with the\n"
    "  part's face numbers (FreeCAD's FaceN).\n"
    "  --out    FILE.msh (Gmsh MSH 4.1), FILE.vtu (ParaView) or FILE.inp (CalculiX mesh)\n"
    "  --size   target element size in mm (default: part diagonal / 50; above the diagonal:\n"
    "           the diagonal, with a warning; a size asking for too many elements is refused)\n"
    "  --min-size  smallest element size in mm (default: size / 10)\n"
    "  --wall-layers N  (native) walls thinner than two sizes get about N layers across\n"
    "  --stats  counts per domain, volumes, quality, conformity, time per stage (JSON) and, native,\n"
    "           per face of the part its finest size and the rule that sets it (face_sizes)\n"
    "  --mesher native: the two-B-Rep advancing front (the 14 steps: no boolean of the part\n"
    "           with the non-design solids); gmsh: OCC fragments of both, meshed by Gmsh in a\n"
    "           separate process; auto (default): native, and gmsh with a warning where native fails\n"
    "  --volume native with --mesher gmsh: Gmsh's surfaces filled by our 3D front\n"
    "           (a comparison aid)\n"
    "  --time-budget S  seconds allowed for reading, or checking and healing, each input\n"
    "           (default: 30 s + 15 s per MB of file)";

pipeline::MeshSettings settings_from(ArgReader& a) {
  pipeline::MeshSettings s;
  s.size = a.number("size", 0);
  s.min_size = a.number("min-size", 0);
  s.wall_layers = mesh::wall_layers_option(a.number("wall-layers", 0));
  s.mesher = pipeline::mesher_from_name(a.option("mesher", "auto"));
  const std::string volume = a.option("volume", "gmsh");
  if (volume != "gmsh" && volume != "native") throw Error(ErrorCode::InvalidParameter, "--volume takes gmsh or native");
  s.gmsh_volume_by_front = volume == "native";
  pipeline::check_mesh_settings(s, "--size", "--min-size");
  return s;
}

Progress stderr_progress() {
  Progress progress;
  progress.report = [](const std::string& stage, double, const std::string& msg) {
    std::cerr << "[" << stage << "] " << msg << "\n";
  };
  const bool verbose = getenv("TOPOPT_VERBOSE") != nullptr;
  progress.log = [verbose](LogLevel level, const std::string& msg) {
    if (verbose || level == LogLevel::Warning)
      std::cerr << (level != LogLevel::Warning ? "  " : "warning: ") << msg << "\n";
  };
  return progress;
}

void write_mesh(const std::string& out, const TetMesh& m) {
  const std::string ext = std::filesystem::path(out).extension().string();
  pipeline::write_replacing(out, [&](const std::string& p) {
    if (ext == ".msh")
      io::write_msh(p, m);
    else if (ext == ".vtu")
      io::write_vtu(p, m, {}, {});
    else
      io::write_inp(p, m, fem::Material{}, fem::Supports{}, Eigen::MatrixXd(), 0);
  });
}

std::vector<long> tets_per_domain(const TetMesh& m) {
  std::vector<long> per_domain(m.domain.size() ? m.domain.maxCoeff() + 1 : 1, 0);
  for (long t = 0; t < m.domain.size(); ++t) per_domain[m.domain[t]]++;
  return per_domain;
}

void print_summary(const TetMesh& m, const mesh::QualityReport& q, const mesh::ConformityReport& conf,
                   const std::string& out) {
  const std::vector<long> per_domain = tets_per_domain(m);
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
}

/// Seconds between marks: read and classify, mesh, write.
struct Times {
  clock::time_point start, read, meshed, written;
};

void write_stats(const std::string& stats, const TetMesh& m, const mesh::QualityReport& q,
                 const mesh::ConformityReport& conf, const Times& t, const mesh::MeshRun& run) {
  auto sec = [](clock::time_point a, clock::time_point b) { return std::chrono::duration<double>(b - a).count(); };
  nlohmann::json j;
  j["nodes"] = m.V.rows();
  j["tets"] = m.T.rows();
  j["tets_per_domain"] = tets_per_domain(m);
  j["boundary_triangles"] = m.F.rows();
  j["quality"] = q.to_json();
  j["conformity"] = conf.to_json();
  j["seconds"] = {{"read_and_classify", sec(t.start, t.read)},
                  {"mesh", sec(t.read, t.meshed)},
                  {"write", sec(t.meshed, t.written)}};
  j["mesher"] = run.mesher;
  if (!run.fallback_reason.empty()) j["native_failed"] = run.fallback_reason;
  for (const auto& [stage, s] : run.seconds) j["seconds_per_stage"][stage] = s;
  for (const mesh::FaceSize& f : run.face_sizes)
    j["face_sizes"].push_back({{"face", "Face" + std::to_string(f.face)},
                               {"size", f.size},
                               {"face_size", f.face_size},
                               {"reason", mesh::size_reason_name(f.reason)}});
  pipeline::write_replacing(stats, [&](const std::string& p) {
    std::ofstream f(p);
    f << j.dump(2) << "\n";
    if (!f) throw Error(ErrorCode::Io, "cannot write " + stats);
  });
  std::cout << "wrote " << stats << "\n";
}

}  // namespace

int cmd_mesh(const Args& args) {
  ArgReader a(args, kUsage);
  if (a.print_help()) return 0;
  const std::string part = a.option("part"), nondesign = a.option("non-design"), out = a.option("out"),
                    stats = a.option("stats");
  const pipeline::MeshSettings settings = settings_from(a);
  const brep::ForeignParams budget = a.time_budget();
  if (!a.positionals().empty() || part.empty() || out.empty())
    throw Error(ErrorCode::InvalidParameter, "give --part and --out\n" + a.usage());
  const std::string ext = std::filesystem::path(out).extension().string();
  if (ext != ".msh" && ext != ".vtu" && ext != ".inp")
    throw Error(ErrorCode::InvalidParameter, "--out must end in .msh, .vtu or .inp");
  for (const auto& [file, option] : {std::pair{out, "--out"}, std::pair{stats, "--stats"}})
    if (!file.empty()) pipeline::prepare_output_folder(std::filesystem::absolute(file).parent_path().string(), option);
  Times t;
  t.start = clock::now();
  const brep::TwoBReps model = brep::load_two_breps(
      brep::read_shape_file(part, "part", budget),
      nondesign.empty() ? TopoDS_Shape() : brep::read_shape_file(nondesign, "non-design input", budget), {}, {},
      budget);
  t.read = clock::now();
  mesh::MeshRun run;
  TetMesh m = pipeline::mesh_model(model, settings, stderr_progress(), &run);
  mesh::reorder_for_locality(m);  // node numbers that follow space (faster solves downstream)
  t.meshed = clock::now();
  write_mesh(out, m);
  t.written = clock::now();
  const mesh::ConformityReport conf = mesh::check_conformity(m, &model);
  const mesh::QualityReport q = mesh::tet_quality(m);
  print_summary(m, q, conf, out);
  if (!stats.empty()) write_stats(stats, m, q, conf, t, run);
  return conf.ok() ? 0 : 1;
}

}  // namespace topopt::cli
