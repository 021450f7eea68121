// Tests of common/huge_pages.h and the executables' operator new (src/cli/large_allocations.cpp,
// linked into the test binary as into build/topopt): a large std::vector is backed by
// transparent huge pages where the kernel gives them on request.
#include "common/huge_pages.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace topopt {
namespace {

/// The kernel's THP mode ("always", "madvise", "never"), or "" where it has none.
std::string thp_mode() {
  std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string line;
  std::getline(in, line);
  const size_t a = line.find('['), b = line.find(']');
  return a == std::string::npos || b == std::string::npos ? "" : line.substr(a + 1, b - a - 1);
}

/// kB of anonymous huge pages in this process's mappings that overlap [p, p + bytes)
/// (/proc/self/smaps: each mapping's "lo-hi" line, then its AnonHugePages).
long huge_kb_in(const void* p, size_t bytes) {
  const auto lo = reinterpret_cast<std::uintptr_t>(p), hi = lo + bytes;
  std::ifstream in("/proc/self/smaps");
  std::string line;
  bool inside = false;
  long kb = 0;
  while (std::getline(in, line)) {
    std::uintptr_t a = 0, b = 0;
    char dash = 0;
    std::istringstream s(line);
    if (line.find(':') == std::string::npos || line.find('-') < line.find(':')) {
      if (s >> std::hex >> a >> dash >> b && dash == '-') inside = a < hi && b > lo;
      continue;
    }
    if (inside && line.rfind("AnonHugePages:", 0) == 0) kb += std::stol(line.substr(14));
  }
  return kb;
}

/// Whether the kernel gives huge pages on request here (THP "always" or "madvise").
bool huge_pages_on_request() {
  const std::string mode = thp_mode();
  return mode == "always" || mode == "madvise";
}

// 31 or 32 of a 64 MB block's 2 MB pages can be huge; a fragmented memory may give fewer, not
// under 8
constexpr long kLeastHugeKb = 8 * 2048;

TEST(HugePages, LargeVectorsAreBackedByHugePages) {
  if (!huge_pages_on_request()) GTEST_SKIP() << "no transparent huge pages on request here";
  std::vector<double> v(size_t{8} << 20, 1.0);  // 64 MB, touched by the fill
  EXPECT_GE(huge_kb_in(v.data(), v.size() * sizeof(double)), kLeastHugeKb) << "THP mode " << thp_mode();
}

TEST(HugePages, CallocAdvisedBlocksAreBackedByHugePages) {
  // CHOLMOD's calloc in the executables (the coarse level's factor)
  if (!huge_pages_on_request()) GTEST_SKIP() << "no transparent huge pages on request here";
  const size_t n = size_t{8} << 20;
  auto* x = static_cast<double*>(calloc_advised(n, sizeof(double)));
  ASSERT_NE(x, nullptr);
  double sum = 0;
  for (size_t i = 0; i < n; i += 512) x[i] = 1, sum += x[i];  // touch every 4 KB page
  EXPECT_EQ(sum, static_cast<double>(n / 512));
  EXPECT_GE(huge_kb_in(x, n * sizeof(double)), kLeastHugeKb) << "THP mode " << thp_mode();
  std::free(x);
}

}  // namespace
}  // namespace topopt
