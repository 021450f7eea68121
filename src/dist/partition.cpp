// The tet partition (see partition.h).
#include "dist/partition.h"

#include <petscmat.h>

#include <algorithm>
#include <array>

namespace topopt::dist {

DualGraph tet_dual_graph(const MatX4i& T) {
  // every face as (its sorted corners, its tet); a face listed twice joins two tets
  struct Face {
    std::array<int, 3> key;
    int tet;
  };
  std::vector<Face> faces;
  faces.reserve(4 * static_cast<size_t>(T.rows()));
  for (int t = 0; t < static_cast<int>(T.rows()); ++t)
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int, 3> k{};
      for (int a = 0, j = 0; a < 4; ++a)
        if (a != skip) k[j++] = T(t, a);
      std::sort(k.begin(), k.end());
      faces.push_back({k, t});
    }
  std::sort(faces.begin(), faces.end(), [](const Face& a, const Face& b) { return a.key < b.key; });
  std::vector<std::pair<int, int>> edges;
  for (size_t i = 0; i + 1 < faces.size(); ++i)
    if (faces[i].key == faces[i + 1].key) {
      edges.emplace_back(faces[i].tet, faces[i + 1].tet);
      edges.emplace_back(faces[i + 1].tet, faces[i].tet);
    }
  std::sort(edges.begin(), edges.end());
  DualGraph g;
  g.ptr.assign(T.rows() + 1, 0);
  g.adj.reserve(edges.size());
  for (const auto& [a, b] : edges) ++g.ptr[a + 1], g.adj.push_back(b);
  for (long t = 0; t < T.rows(); ++t) g.ptr[t + 1] += g.ptr[t];
  return g;
}

std::vector<int> partition_tets(const MpiSession& session, const MatX4i& T) {
  if (session.size() == 1) return std::vector<int>(T.rows(), 0);
  long total = T.rows();
  MPI_Bcast(&total, 1, MPI_LONG, 0, session.comm());
  // rank 0 holds every row of the graph; MatCreateMPIAdj takes ownership of ia and ja
  const PetscInt rows = session.rank() == 0 ? static_cast<PetscInt>(total) : 0;
  PetscInt *ia = nullptr, *ja = nullptr;
  DualGraph g;
  if (session.rank() == 0) g = tet_dual_graph(T);
  check_petsc(PetscMalloc1(rows + 1, &ia), "PetscMalloc1");
  check_petsc(PetscMalloc1(std::max<size_t>(1, g.adj.size()), &ja), "PetscMalloc1");
  ia[0] = 0;
  for (PetscInt r = 0; r < rows; ++r) ia[r + 1] = g.ptr[r + 1];
  std::copy(g.adj.begin(), g.adj.end(), ja);
  g = {};
  Mat adjacency;
  check_petsc(MatCreateMPIAdj(session.comm(), rows, static_cast<PetscInt>(total), ia, ja, nullptr, &adjacency),
              "MatCreateMPIAdj");
  MatPartitioning part;
  check_petsc(MatPartitioningCreate(session.comm(), &part), "MatPartitioningCreate");
  check_petsc(MatPartitioningSetAdjacency(part, adjacency), "MatPartitioningSetAdjacency");
  check_petsc(MatPartitioningSetNParts(part, session.size()), "MatPartitioningSetNParts");
  check_petsc(MatPartitioningSetType(part, MATPARTITIONINGPTSCOTCH), "MatPartitioningSetType");
  check_petsc(MatPartitioningSetFromOptions(part), "MatPartitioningSetFromOptions");
  IS owners;
  check_petsc(MatPartitioningApply(part, &owners), "MatPartitioningApply (PT-Scotch)");
  std::vector<int> result(static_cast<size_t>(rows));
  const PetscInt* idx = nullptr;
  check_petsc(ISGetIndices(owners, &idx), "ISGetIndices");
  for (PetscInt r = 0; r < rows; ++r) result[r] = static_cast<int>(idx[r]);
  ISRestoreIndices(owners, &idx);
  ISDestroy(&owners);
  MatPartitioningDestroy(&part);
  MatDestroy(&adjacency);
  return result;
}

}  // namespace topopt::dist
