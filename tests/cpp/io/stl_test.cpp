// Binary STL: the record layout, outward normals from the vertex order, and the face tags in
// each triangle's attribute bytes.
#include "io/stl.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

namespace topopt::io {
namespace {

TEST(Stl, RecordsHoldNormalsVerticesAndTags) {
  // a tetrahedron's surface, outward, tagged 1..3 and one tag too large for 16 bits
  MatX3d V(4, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  MatX3i F(4, 3);
  F << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
  VecXi tags(4);
  tags << 1, 2, 3, 70000;
  const auto path = std::filesystem::temp_directory_path() / ("topopt_stl_" + std::to_string(::getpid()) + ".stl");
  write_stl(path.string(), V, F, "test", &tags);
  std::ifstream in(path, std::ios::binary);
  const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::filesystem::remove(path);
  ASSERT_EQ(bytes.size(), 84u + 4 * 50);
  uint32_t n;
  std::memcpy(&n, bytes.data() + 80, 4);
  EXPECT_EQ(n, 4u);
  const uint16_t expected_tag[4] = {1, 2, 3, 65535};
  for (int t = 0; t < 4; ++t) {
    const char* rec = bytes.data() + 84 + 50 * t;
    float f[12];
    std::memcpy(f, rec, sizeof f);
    const Eigen::Vector3d normal(f[0], f[1], f[2]), a(f[3], f[4], f[5]);
    const Eigen::Vector3d centre = V.colwise().mean().transpose();
    EXPECT_NEAR(normal.norm(), 1.0, 1e-6);
    EXPECT_GT(normal.dot(a - centre), 0) << "triangle " << t << " faces inwards";
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d) EXPECT_EQ(f[3 + 3 * k + d], static_cast<float>(V(F(t, k), d)));
    uint16_t tag;
    std::memcpy(&tag, rec + 48, 2);
    EXPECT_EQ(tag, expected_tag[t]);
  }
}

}  // namespace
}  // namespace topopt::io
