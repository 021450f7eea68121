// CalculiX's *FREQUENCY on one of our meshes, for the tests that check our eigenfrequencies
// against it (fem/modal_test, simp/responses_test).
#pragma once
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "common/types.h"
#include "fem/elasticity.h"

namespace topopt::testing {

/// True when the ccx command is on the PATH.
inline bool have_ccx() { return std::system("command -v ccx > /dev/null 2>&1") == 0; }

/// The lowest `modes` eigenfrequencies (Hz) of mesh `m` (C3D4, one material) held at the dofs
/// of `s` (3 node + axis), by ccx run in `dir` (written there: modes.inp, modes.dat, ccx.log).
/// Returns fewer than `modes` values when ccx failed (see dir/ccx.log).
inline std::vector<double> ccx_frequencies(const TetMesh& m, const fem::Material& mat, const fem::Supports& s,
                                           int modes, const std::filesystem::path& dir) {
  std::ofstream f(dir / "modes.inp");
  f.precision(17);
  f << "*NODE\n";
  for (long i = 0; i < m.V.rows(); ++i)
    f << i + 1 << ", " << m.V(i, 0) << ", " << m.V(i, 1) << ", " << m.V(i, 2) << "\n";
  f << "*ELEMENT, TYPE=C3D4, ELSET=ALL\n";
  for (long t = 0; t < m.T.rows(); ++t)
    f << t + 1 << ", " << m.T(t, 0) + 1 << ", " << m.T(t, 1) + 1 << ", " << m.T(t, 2) + 1 << ", " << m.T(t, 3) + 1
      << "\n";
  f.precision(10);  // ccx reads a material card's numbers in fields of 20 characters
  f << "*MATERIAL, NAME=M\n*ELASTIC\n" << mat.young << ", " << mat.poisson << "\n*DENSITY\n" << mat.density << "\n";
  f << "*SOLID SECTION, ELSET=ALL, MATERIAL=M\n*BOUNDARY\n";
  for (int d : s.dofs) f << d / 3 + 1 << ", " << d % 3 + 1 << ", " << d % 3 + 1 << ", 0\n";
  f << "*STEP\n*FREQUENCY, SOLVER=SPOOLES\n" << modes << "\n*END STEP\n";
  f.close();
  const std::string cmd = "cd '" + dir.string() + "' && OMP_NUM_THREADS=1 ccx modes > ccx.log 2>&1";
  if (std::system(cmd.c_str()) != 0) return {};
  // the .dat's eigenvalue table: MODE NO, EIGENVALUE, (RAD/TIME), (CYCLES/TIME), ...
  std::ifstream dat(dir / "modes.dat");
  std::string line;
  std::vector<double> hz;
  bool table = false;
  while (std::getline(dat, line)) {
    if (line.find("E I G E N V A L U E   O U T P U T") != std::string::npos) table = true;
    std::istringstream in(line);
    int mode;
    double lambda, omega, cycles;
    if (table && (in >> mode >> lambda >> omega >> cycles) && mode == static_cast<int>(hz.size()) + 1)
      hz.push_back(cycles);
    if (static_cast<int>(hz.size()) == modes) break;
  }
  return hz;
}

}  // namespace topopt::testing
