// Binary STL writer (see stl.h).
#include "io/stl.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>

#include "common/error.h"

namespace topopt::io {

void write_stl(const std::string& path, const MatX3d& V, const MatX3i& F, const std::string& header,
               const VecXi* tags) {
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) throw Error(ErrorCode::Io, "cannot write " + path);
  char head[80] = {};
  std::strncpy(head, header.c_str(), sizeof(head) - 1);
  std::fwrite(head, 1, 80, f);
  uint32_t n = static_cast<uint32_t>(F.rows());
  std::fwrite(&n, 4, 1, f);
  for (long t = 0; t < F.rows(); ++t) {
    Eigen::Vector3d a = V.row(F(t, 0)), b = V.row(F(t, 1)), c = V.row(F(t, 2));
    Eigen::Vector3d nrm = (b - a).cross(c - a);
    if (nrm.norm() > 0) nrm.normalize();
    float rec[12];
    for (int k = 0; k < 3; ++k) rec[k] = static_cast<float>(nrm[k]);
    for (int v = 0; v < 3; ++v)
      for (int k = 0; k < 3; ++k) rec[3 + 3 * v + k] = static_cast<float>(V(F(t, v), k));
    std::fwrite(rec, 4, 12, f);
    const uint16_t attr = tags ? static_cast<uint16_t>(std::clamp((*tags)[t], 0, 65535)) : 0;
    std::fwrite(&attr, 2, 1, f);
  }
  bool ok = std::ferror(f) == 0;
  ok &= std::fclose(f) == 0;
  if (!ok) throw Error(ErrorCode::Io, "error while writing " + path + " (disk full?)");
}

}  // namespace topopt::io
