// Checks of an optimisation problem before SIMP (see problem_checks.h).
#include "pipeline/problem_checks.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "common/error.h"
#include "simp/optimizer.h"
#include "simp/responses/responses.h"

namespace topopt::pipeline {
namespace {

/// Bytes per filter pair of the explicit filter: its one sparse matrix holds the upper triangle,
/// a column index and a value (12) for every two pairs (i, j) and (j, i), rounded up for the
/// per-thread scratch while it is built.
constexpr double kBytesPerPair = 8;

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

std::vector<double> filter_pairs_within(const TetMesh& mesh, double radius, int bins) {
  std::vector<Eigen::RowVector3d> centre;
  for (long t = 0; t < mesh.T.rows(); ++t)
    if (mesh.domain.size() != mesh.T.rows() || mesh.domain[t] == 0)
      centre.push_back(0.25 * (mesh.V.row(mesh.T(t, 0)) + mesh.V.row(mesh.T(t, 1)) + mesh.V.row(mesh.T(t, 2)) +
                               mesh.V.row(mesh.T(t, 3))));
  std::vector<double> pairs(static_cast<size_t>(bins), 0.0);
  const size_t n = centre.size();
  if (n == 0 || !(radius > 0)) return pairs;
  const size_t samples = std::min<size_t>(64, n);
  for (size_t k = 0; k < samples; ++k) {
    const Eigen::RowVector3d& p = centre[(n * (2 * k + 1)) / (2 * samples)];
    for (const auto& q : centre) {
      const double d = (q - p).norm();
      if (d < radius) pairs[std::min(static_cast<size_t>(d / radius * bins), static_cast<size_t>(bins - 1))] += 1;
    }
  }
  const double scale = static_cast<double>(n) / static_cast<double>(samples);
  double sum = 0;
  for (double& p : pairs) p = (sum += p) * scale;
  return pairs;
}

double estimated_filter_pairs(const TetMesh& mesh, double radius) { return filter_pairs_within(mesh, radius, 1)[0]; }

namespace {

/// Bins of the radius in which the filter's pairs are counted (filter_pairs_within).
constexpr int kRadiusBins = 200;

/// The neighbour pairs an explicit filter may hold: half of `memory_bytes` (unknown: no limit).
double pairs_budget(double memory_bytes) { return memory_bytes > 0 ? 0.5 * memory_bytes / kBytesPerPair : 1e300; }

void check_radius_within_part(const TetMesh& mesh, double radius, bool given) {
  const Eigen::RowVector3d lo = mesh.V.colwise().minCoeff(), hi = mesh.V.colwise().maxCoeff();
  const double diagonal = (hi - lo).norm();
  if (given && radius > diagonal)
    throw Error(ErrorCode::InvalidParameter,
                "job file: 'optimization.filter_radius' (" + number(radius) + " mm) is larger than the part (its " +
                    "diagonal is " + number(diagonal) + " mm), so the filter would blur the whole design into one " +
                    "grey: give about twice the mesh size, or the thinnest member you want");
}

/// Throws TooLarge when the pairs within the radius (`within`: filter_pairs_within with
/// kRadiusBins) exceed `budget`, naming the largest radius that fits or a coarser mesh.
void check_filter_memory(const std::vector<double>& within, double radius, bool given, double budget) {
  const double pairs = within.back();
  if (pairs <= budget) return;
  int fits = 0;  // the largest radius k/bins * radius whose pairs fit
  while (fits < kRadiusBins && within[fits] <= budget) ++fits;
  const std::string need = "the density filter of radius " + number(radius) + " mm would hold about " + number(pairs) +
                           " neighbour pairs (" + number(pairs * kBytesPerPair / 1e9) +
                           " GB), more than this machine's memory allows: ";
  const std::string pde = ", or \"filter\": \"helmholtz\" (its memory does not grow with the radius)";
  if (given)
    throw Error(ErrorCode::TooLarge, need + "give 'optimization.filter_radius' at most " +
                                         number(radius * fits / kRadiusBins) + " mm" + pde);
  throw Error(ErrorCode::TooLarge, need + "use a coarser mesh size (the automatic radius is 1.5 mean edges)" + pde);
}

}  // namespace

void check_filter_radius(const TetMesh& mesh, double radius, bool given, double memory_bytes) {
  check_radius_within_part(mesh, radius, given);
  if (!(memory_bytes > 0)) return;
  check_filter_memory(filter_pairs_within(mesh, radius, kRadiusBins), radius, given, pairs_budget(memory_bytes));
}

simp::FilterParams chosen_filter(const TetMesh& mesh, const simp::FilterParams& requested, bool automatic,
                                 double memory_bytes, std::string* note) {
  simp::FilterParams p = requested;
  p.radius = simp::filter_radius(mesh, requested);
  const bool given = requested.radius > 0;
  check_radius_within_part(mesh, p.radius, given);
  long design = 0;
  for (long t = 0; t < mesh.T.rows(); ++t) design += mesh.domain.size() != mesh.T.rows() || mesh.domain[t] == 0;
  // counted once: the pairs decide the kind and, for an explicit filter, its memory check
  const std::vector<double> within = filter_pairs_within(mesh, p.radius, kRadiusBins);
  const double pairs = within.back(), budget = pairs_budget(memory_bytes);
  p.kind = simp::choose_filter_kind(requested.kind, automatic, pairs, static_cast<double>(design), budget);
  if (p.kind != simp::FilterKind::Helmholtz) {
    check_filter_memory(within, p.radius, given, budget);
  } else {
    p.like_gaussian = automatic;
    if (automatic && note)
      *note = "filter: the Helmholtz (PDE) filter in place of the Gaussian one, which would hold " + number(pairs) +
              " neighbour pairs (" + number(pairs / std::max<long>(1, design)) + " per element)";
  }
  return p;
}

double physical_memory_bytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? static_cast<double>(pages) * static_cast<double>(page) : 0.0;
}

std::string not_crisp_warning(const simp::SimpResult& result, const simp::SimpParams& params) {
  if (result.converged || result.history.empty()) return {};
  const simp::IterationRecord& last = result.history.back();
  const double beta_max = simp::update_settings(params).projection.beta_max;  // lower under a stress limit
  const bool short_of_beta = params.projection.enabled && last.beta < beta_max;
  const double grey_limit = 0.03;  // issue 19: a crisp design has at most 3 % grey volume
  if (!short_of_beta && last.grey <= grey_limit) return {};
  std::ostringstream m;
  m << std::setprecision(3) << "the optimisation stopped at its iteration cap (" << params.max_iterations
    << ") before the design was crisp: ";
  if (short_of_beta) m << "the projection reached β = " << last.beta << " of " << beta_max << ", ";
  m << 100 * last.grey << " % of the design volume is grey (0.1 < ρ < 0.9); the result surface cuts through "
    << "material the optimiser had not decided on. Raise 'optimization.max_iterations' (MaxIterations in the "
    << "study) and run again";
  return m.str();
}

}  // namespace topopt::pipeline
