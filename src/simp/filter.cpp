// make_filter: the one place that builds the filter kind the parameters name (see filter.h).
#include "simp/filter.h"

#include <algorithm>
#include <cmath>

#include "simp/density_filter.h"
#include "simp/helmholtz_filter.h"

namespace topopt::simp {

double helmholtz_length(double radius, bool like_gaussian) {
  return like_gaussian ? radius / (3.0 * std::sqrt(2.0)) : radius / (2.0 * std::sqrt(3.0));
}

double mean_edge_length(const TetMesh& mesh, const std::vector<int>& tets) {
  const long n = tets.empty() ? mesh.T.rows() : static_cast<long>(tets.size());
  double sum = 0;
  long edges = 0;
  for (long i = 0; i < n; i += std::max<long>(1, n / 20000)) {
    const long t = tets.empty() ? i : tets[i];
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) sum += (mesh.V.row(mesh.T(t, a)) - mesh.V.row(mesh.T(t, b))).norm(), ++edges;
  }
  return edges ? sum / static_cast<double>(edges) : 0;
}

FilterKind choose_filter_kind(FilterKind requested, bool automatic, double pairs, double design_elements,
                              double pairs_budget) {
  if (!automatic) return requested;
  const bool dense = pairs > kHelmholtzAboveNeighbours * design_elements;
  return dense || pairs > pairs_budget ? FilterKind::Helmholtz : FilterKind::Gaussian;
}

std::unique_ptr<Filter> make_filter(const TetMesh& mesh, const std::vector<int>& design, const VecXd& volume,
                                    const FilterParams& params, const Progress& progress,
                                    const std::vector<char>& held) {
  if (params.kind == FilterKind::Helmholtz && params.radius > 0)
    return std::make_unique<HelmholtzFilter>(mesh, design, volume, params, progress, held);
  return std::make_unique<DensityFilter>(mesh, design, volume, params, held);
}

}  // namespace topopt::simp
