// The minimum member size held on the crisp design (see member_enforce.h).
#include "result/member_enforce.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "common/number_text.h"
#include "mesh/core/spatial_grid.h"
#include "result/design_hygiene.h"
#include "result/iso_surface.h"
#include "simp/controls/member_measure.h"

namespace topopt::result {
namespace {

using Point = Eigen::Vector3d;

bool is_design(const TetMesh& mesh, long t) { return mesh.domain.size() != mesh.T.rows() || mesh.domain[t] == 0; }

/// The tets' centres in the product's spatial grid (mesh/core/spatial_grid.h), cells of `cell`
/// (mm, the mesh size), to visit those within a distance of a point.
struct Centres {
  std::vector<Point> centre;  // #T
  mesh::SpatialGrid<3> grid;
  Centres(const TetMesh& mesh, double cell) : centre(mesh.T.rows()), grid(origin(mesh).data(), cell > 0 ? cell : 1) {
    for (long t = 0; t < mesh.T.rows(); ++t) {
      centre[t] = tet_centre(mesh, t);
      grid.insert(static_cast<int>(t), centre[t].data(), centre[t].data());
    }
  }
  /// Calls fn(t) for every tet whose centre lies within r of p.
  template <class Fn>
  void within(const Point& p, double r, Fn fn) const {
    const Point lo = p.array() - r, hi = p.array() + r;
    grid.for_each(lo.data(), hi.data(), [&](int t) {
      if ((centre[t] - p).norm() <= r) fn(static_cast<long>(t));
    });
  }

 private:
  static Point origin(const TetMesh& mesh) { return mesh.V.rows() ? Point(mesh.V.colwise().minCoeff()) : Point::Zero(); }
};

/// The crisp design of density at threshold as 0/1 densities (#T).
VecXd crisp_of(const TetMesh& mesh, const VecXd& density, double threshold) {
  const std::vector<char> solid = crisp_tets(mesh, node_densities(mesh, density), threshold);
  VecXd c(static_cast<long>(solid.size()));
  for (size_t t = 0; t < solid.size(); ++t) c[static_cast<long>(t)] = solid[t];
  return c;
}

/// The thin tets of one measurement: (tet, thickness) of the solid design tets held to the size
/// and thinner than it; `smallest` gets the smallest member of the tets held, `at` its tet (-1: none).
std::vector<std::pair<long, double>> thin_tets(const TetMesh& mesh, const VecXd& crisp, const std::vector<char>& attached,
                                               double size, double cell, double& smallest, long& at) {
  simp::MemberMeasureParams mp;
  mp.reach = cell;
  const simp::MemberMeasure m = simp::measure_members(mesh, crisp, mp);
  std::vector<std::pair<long, double>> thin;
  smallest = std::numeric_limits<double>::infinity(), at = -1;
  for (long t = 0; t < mesh.T.rows(); ++t) {
    if (crisp[t] < 0.5 || !is_design(mesh, t) || attached[t]) continue;
    if (m.thickness[t] < smallest) smallest = m.thickness[t], at = t;
    if (m.thickness[t] < size) thin.emplace_back(t, m.thickness[t]);
  }
  if (at < 0) smallest = 0;
  return thin;
}

/// Sets solid the design tets within (size − w)/2 + margin of each thin tet's centre (w its
/// thickness: a plate grows by the shortfall's half on either side); adds what it did to
/// `report`. Returns the number of tets set solid.
long thicken(const TetMesh& mesh, const Centres& index, const std::vector<std::pair<long, double>>& thin, double size,
             double margin, VecXd& density, MemberEnforcement& report) {
  long added = 0;
  for (const auto& [t, w] : thin)
    index.within(index.centre[t], (size - w) / 2 + margin, [&](long j) {
      if (!is_design(mesh, j) || density[j] >= 1) return;
      report.volume_added += tet_volume(mesh, j) * (1 - std::max(0.0, density[j]));
      density[j] = 1;
      const bool first = report.tets_added + added == 0;
      for (int a = 0; a < 3; ++a) {
        const double c = index.centre[j][a];
        report.added_lo[a] = first ? c : std::min(report.added_lo[a], c);
        report.added_hi[a] = first ? c : std::max(report.added_hi[a], c);
      }
      ++added;
    });
  report.tets_added += added;
  return added;
}

std::string mm(double v, int precision = 3) { return number_text(v, precision); }

}  // namespace

double member_cell(const TetMesh& mesh) {
  double sum = 0;
  long n = 0;
  for (int pass = 0; pass < 2 && n == 0; ++pass)
    for (long t = 0; t < mesh.T.rows(); ++t)
      if (pass == 1 || is_design(mesh, t)) sum += std::cbrt(6 * std::sqrt(2.0) * tet_volume(mesh, t)), ++n;
  return n ? sum / n : 0;
}

std::vector<char> member_attachments(const TetMesh& mesh, const std::vector<char>& anchors, double cell) {
  const long nt = mesh.T.rows();
  std::vector<char> attached(nt, 0);
  for (long t = 0; t < nt && !anchors.empty(); ++t)
    for (int a = 0; a < 4; ++a)
      if (is_design(mesh, t) && anchors[mesh.T(t, a)]) attached[t] = 1;
  if (mesh.domain.size() != nt) return attached;
  const Centres index(mesh, cell);
  for (long t = 0; t < nt; ++t)
    if (mesh.domain[t] != 0)
      index.within(index.centre[t], cell, [&](long j) { attached[j] |= mesh.domain[j] == 0; });
  return attached;
}

VecXd enforce_min_member(const TetMesh& mesh, const VecXd& density, double threshold, const std::vector<char>& anchors,
                         const MemberEnforceParams& params, MemberEnforcement& report) {
  report = MemberEnforcement{};
  report.size = params.size;
  if (params.size <= 0) return density;
  report.cell = member_cell(mesh);
  for (long t = 0; t < mesh.T.rows(); ++t)
    if (is_design(mesh, t)) report.design_volume += tet_volume(mesh, t);
  const std::vector<char> attached = member_attachments(mesh, anchors, report.cell);
  const Centres index(mesh, report.cell);
  VecXd out = density;
  // The crisp design lies up to about half a cell inside the tets set solid (its tets are those
  // whose node densities average the threshold), so a dilation by the shortfall alone can add
  // nothing the crisp design keeps: the margin then grows by a quarter of a cell, up to a cell
  // (from 0 again every round: a margin kept would thicken every later round's members by it).
  for (int round = 0;; ++round) {
    double margin = 0;
    double smallest = 0;
    long at = -1;
    const auto thin = thin_tets(mesh, crisp_of(mesh, out, threshold), attached, params.size, report.cell, smallest, at);
    if (round == 0) {
      report.measured = at >= 0;
      report.smallest_before = smallest;
      if (at >= 0)
        for (int a = 0; a < 3; ++a) report.thinnest_at[a] = index.centre[at][a];
    }
    report.smallest_after = smallest;
    if (thin.empty() || round == params.rounds) break;
    while (margin <= report.cell && thicken(mesh, index, thin, params.size, margin, out, report) == 0)
      margin += report.cell / 4;
    if (margin > report.cell) break;
    report.rounds = round + 1;
  }
  return out;
}

std::string member_warning(const MemberEnforcement& r) {
  if (!r.measured || (r.tets_added == 0 && r.met())) return "";
  std::ostringstream w;
  w << "controls.min_member_size " << mm(r.size) << " mm: the optimised design held members down to "
    << mm(r.smallest_before) << " mm (thinnest at " << mm(r.thinnest_at[0]) << ", " << mm(r.thinnest_at[1]) << ", "
    << mm(r.thinnest_at[2]) << ")";
  if (r.tets_added > 0)
    w << "; they were thickened to the size: " << mm(r.volume_added) << " mm3 added ("
      << mm(100 * r.volume_added / std::max(r.design_volume, 1e-300), 2) << " % of the design domain, " << r.tets_added
      << " tets within x " << mm(r.added_lo[0]) << ".." << mm(r.added_hi[0]) << ", y " << mm(r.added_lo[1]) << ".."
      << mm(r.added_hi[1]) << ", z " << mm(r.added_lo[2]) << ".." << mm(r.added_hi[2])
      << " mm), so the result holds more than the volume fraction";
  w << "; smallest member now " << mm(r.smallest_after) << " mm, measured to a mesh size (" << mm(r.cell)
    << " mm) beyond the faces where supports and loads act and a mesh size off the non-design solids";
  if (!r.met()) w << ": NOT the size less a mesh size — raise the volume fraction, lower the size or refine the mesh";
  return w.str();
}

}  // namespace topopt::result
