// CalculiX / Abaqus .inp writer and ccx .dat reader (see inp.h).
#include "io/inp.h"

#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include "common/error.h"

namespace topopt::io {

void write_inp(const std::string& path, const TetMesh& mesh, const fem::Material& material,
               const fem::Supports& supports, const Eigen::MatrixXd& loads, int load_case, const VecXd& scale) {
  FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw Error(ErrorCode::Io, "cannot write " + path);
  const long nv = mesh.V.rows(), nt = mesh.T.rows();
  std::fprintf(f, "** Written by TopOpt: linear static analysis on C3D4 tets (units N, mm, MPa)\n*HEADING\nTopOpt\n");
  std::fprintf(f, "*NODE, NSET=NALL\n");
  for (long i = 0; i < nv; ++i)
    std::fprintf(f, "%ld, %.13g, %.13g, %.13g\n", i + 1, mesh.V(i, 0), mesh.V(i, 1), mesh.V(i, 2));
  // Elements grouped by (domain, material); a material per distinct stiffness factor.
  std::map<double, int> mat_of;
  if (scale.size() == nt)
    for (long t = 0; t < nt; ++t) mat_of.emplace(scale[t], 0);
  else
    mat_of.emplace(1.0, 0);
  int k = 0;
  for (auto& kv : mat_of) kv.second = ++k;
  std::map<std::pair<int, int>, std::vector<long>> groups;
  for (long t = 0; t < nt; ++t)
    groups[{mesh.domain.size() == nt ? mesh.domain[t] : 0, mat_of[scale.size() == nt ? scale[t] : 1.0]}].push_back(t);
  for (const auto& g : groups) {
    std::string name = g.first.first == 0 ? "DESIGN" : "NONDESIGN" + std::to_string(g.first.first);
    std::fprintf(f, "*ELEMENT, TYPE=C3D4, ELSET=%s_M%d\n", name.c_str(), g.first.second);
    for (long t : g.second)
      std::fprintf(f, "%ld, %d, %d, %d, %d\n", t + 1, mesh.T(t, 0) + 1, mesh.T(t, 1) + 1, mesh.T(t, 2) + 1,
                   mesh.T(t, 3) + 1);
  }
  for (const auto& kv : mat_of) {
    std::fprintf(f, "*MATERIAL, NAME=M%d\n*ELASTIC\n%.13g, %.13g\n", kv.second, material.young * kv.first,
                 material.poisson);
    std::fprintf(f, "*DENSITY\n%.13g\n", material.density);
  }
  for (const auto& g : groups) {
    std::string name = g.first.first == 0 ? "DESIGN" : "NONDESIGN" + std::to_string(g.first.first);
    std::fprintf(f, "*SOLID SECTION, ELSET=%s_M%d, MATERIAL=M%d\n", name.c_str(), g.first.second, g.first.second);
  }
  if (supports.dofs.empty() && loads.size() == 0) {  // a mesh only
    bool ok = std::ferror(f) == 0;
    ok &= std::fclose(f) == 0;
    if (!ok) throw Error(ErrorCode::Io, "error while writing " + path + " (disk full?)");
    return;
  }
  std::fprintf(f, "*STEP\n*STATIC\n*BOUNDARY\n");
  for (size_t i = 0; i < supports.dofs.size(); ++i) {
    int d = supports.dofs[i];
    std::fprintf(f, "%d, %d, %d, %.13g\n", d / 3 + 1, d % 3 + 1, d % 3 + 1, supports.values[i]);
  }
  std::fprintf(f, "*CLOAD\n");
  if (load_case < loads.cols())
    for (long d = 0; d < loads.rows(); ++d)
      if (loads(d, load_case) != 0) std::fprintf(f, "%ld, %ld, %.13g\n", d / 3 + 1, d % 3 + 1, loads(d, load_case));
  std::fprintf(f, "*NODE PRINT, NSET=NALL\nU\n*NODE FILE\nU\n*EL FILE\nS\n*END STEP\n");
  bool ok = std::ferror(f) == 0;
  ok &= std::fclose(f) == 0;
  if (!ok) throw Error(ErrorCode::Io, "error while writing " + path + " (disk full?)");
}

MatX3d read_ccx_displacements(const std::string& dat_path, int num_nodes) {
  std::ifstream in(dat_path);
  if (!in) throw Error(ErrorCode::Io, "cannot open " + dat_path);
  MatX3d U = MatX3d::Zero(num_nodes, 3);
  std::string line;
  bool in_table = false, found = false;
  while (std::getline(in, line)) {
    if (line.find("displacements (vx,vy,vz)") != std::string::npos) {
      in_table = found = true;
      continue;
    }
    if (!in_table) continue;
    std::istringstream ss(line);
    long node;
    double x, y, z;
    if (ss >> node >> x >> y >> z) {
      if (node >= 1 && node <= num_nodes) U.row(node - 1) << x, y, z;
    } else if (line.find_first_not_of(" \t\r") != std::string::npos) {
      in_table = false;
    }
  }
  if (!found) throw Error(ErrorCode::Io, dat_path + " has no displacement table");
  return U;
}

}  // namespace topopt::io
