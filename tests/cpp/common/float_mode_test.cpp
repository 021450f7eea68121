// The flush-to-zero guard: subnormals vanish inside its scope and come back after it, also
// when the scope is left by an exception, and nested guards restore what they found.
#include "common/float_mode.h"

#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>

namespace topopt {
namespace {

/// Half of the smallest normal double: a subnormal result (opaque to the optimiser).
double half_of_smallest_normal() {
  volatile double smallest = std::numeric_limits<double>::min();
  volatile double half = 0.5;
  return smallest * half;
}

TEST(FlushSubnormals, FlushesInsideItsScopeAndRestoresAfterIt) {
  if (!FlushSubnormals::supported()) GTEST_SKIP() << "no flush-to-zero switch on this target";
  ASSERT_GT(half_of_smallest_normal(), 0.0);  // the default mode keeps subnormals
  {
    FlushSubnormals flush;
    EXPECT_EQ(half_of_smallest_normal(), 0.0);
    {
      FlushSubnormals nested;
      EXPECT_EQ(half_of_smallest_normal(), 0.0);
    }
    EXPECT_EQ(half_of_smallest_normal(), 0.0);  // the inner guard restored the flushing mode
  }
  EXPECT_GT(half_of_smallest_normal(), 0.0);
}

TEST(FlushSubnormals, RestoresTheModeWhenAnExceptionLeavesTheScope) {
  if (!FlushSubnormals::supported()) GTEST_SKIP() << "no flush-to-zero switch on this target";
  try {
    FlushSubnormals flush;
    ASSERT_EQ(half_of_smallest_normal(), 0.0);
    throw std::runtime_error("leaving");
  } catch (const std::runtime_error&) {
  }
  EXPECT_GT(half_of_smallest_normal(), 0.0);
}

}  // namespace
}  // namespace topopt
