// Checks of an optimisation problem before SIMP (see problem_checks.h).
#include "pipeline/problem_checks.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "common/error.h"

namespace topopt::pipeline {
namespace {

/// Bytes per filter pair while DensityFilter is built: its neighbour lists (16), two triplet
/// lists (32), two sparse matrices (24) and a sparse matrix's temporary (12), rounded up.
constexpr double kBytesPerPair = 90;

/// A figure as a user reads it: 3 significant digits, no exponent below a million.
std::string number(double v) {
  std::ostringstream s;
  if (std::abs(v) >= 100 && std::abs(v) < 1e6)
    s << std::lround(v);
  else
    s << std::setprecision(3) << v;
  return s.str();
}

}  // namespace

void check_loads_reach_the_part(const Eigen::MatrixXd& loads, const fem::Supports& supports,
                                const std::vector<fem::LoadCase>& cases) {
  for (long c = 0; c < loads.cols(); ++c) {
    const std::string name = c < static_cast<long>(cases.size()) ? cases[c].name : std::to_string(c + 1);
    const double total = loads.col(c).cwiseAbs().sum();
    if (!(total > 0))
      throw Error(ErrorCode::InvalidParameter,
                  "load case \"" + name + "\" puts no force on the part: its loads are zero; give a force (N), a " +
                      "pressure (MPa) or a gravity (mm/s²) that is not zero");
    double held = 0;
    for (int dof : supports.dofs) held += std::abs(loads(dof, c));
    if (held >= total * (1 - 1e-12))
      throw Error(
          ErrorCode::InvalidParameter,
          "load case \"" + name + "\" acts only where the supports hold the part (every node it loads is " +
              "fixed), so nothing deforms: put the load on a face that is not supported, or support fewer faces");
  }
}

double estimated_filter_pairs(const TetMesh& mesh, double radius) {
  std::vector<Eigen::RowVector3d> centre;
  for (long t = 0; t < mesh.T.rows(); ++t)
    if (mesh.domain.size() != mesh.T.rows() || mesh.domain[t] == 0)
      centre.push_back(0.25 * (mesh.V.row(mesh.T(t, 0)) + mesh.V.row(mesh.T(t, 1)) + mesh.V.row(mesh.T(t, 2)) +
                               mesh.V.row(mesh.T(t, 3))));
  const size_t n = centre.size();
  if (n == 0) return 0;
  const size_t samples = std::min<size_t>(64, n);
  const double r2 = radius * radius;
  double neighbours = 0;
  for (size_t k = 0; k < samples; ++k) {
    const Eigen::RowVector3d& p = centre[(n * (2 * k + 1)) / (2 * samples)];
    for (const auto& q : centre) neighbours += (q - p).squaredNorm() < r2;
  }
  return neighbours / static_cast<double>(samples) * static_cast<double>(n);
}

void check_filter_radius(const TetMesh& mesh, double radius, bool given, double memory_bytes) {
  const Eigen::RowVector3d lo = mesh.V.colwise().minCoeff(), hi = mesh.V.colwise().maxCoeff();
  const double diagonal = (hi - lo).norm();
  if (given && radius > diagonal)
    throw Error(ErrorCode::InvalidParameter,
                "job file: 'optimization.filter_radius' (" + number(radius) + " mm) is larger than the part (its " +
                    "diagonal is " + number(diagonal) + " mm), so the filter would blur the whole design into one " +
                    "grey: give about twice the mesh size, or the thinnest member you want");
  if (!(memory_bytes > 0)) return;
  const double pairs = estimated_filter_pairs(mesh, radius);
  const double budget = 0.5 * memory_bytes / kBytesPerPair;
  if (pairs <= budget) return;
  const std::string need = "the density filter of radius " + number(radius) + " mm would hold about " + number(pairs) +
                           " neighbour pairs (" + number(pairs * kBytesPerPair / 1e9) +
                           " GB), more than this machine's memory allows: ";
  if (given)
    throw Error(ErrorCode::TooLarge, need + "give 'optimization.filter_radius' at most " +
                                         number(radius * std::cbrt(budget / pairs)) + " mm");
  throw Error(ErrorCode::TooLarge, need + "use a coarser mesh size (the automatic radius is 1.5 mean edges)");
}

double physical_memory_bytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? static_cast<double>(pages) * static_cast<double>(page) : 0.0;
}

}  // namespace topopt::pipeline
