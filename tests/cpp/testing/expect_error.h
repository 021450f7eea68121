// A check shared by the tests: a call must throw a topopt::Error of a given code whose
// message says given things (tests assert what the user reads, not only that it failed).
#pragma once
#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

#include "common/error.h"

namespace topopt::testing {

/// f must throw a topopt::Error with `code` whose message contains every fragment.
/// Returns the message ("" when nothing or something else was thrown).
inline std::string expect_error(const std::function<void()>& f, ErrorCode code,
                                const std::vector<std::string>& fragments) {
  try {
    f();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), code) << e.what();
    for (const auto& s : fragments) EXPECT_NE(std::string(e.what()).find(s), std::string::npos) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "expected an error" << (fragments.empty() ? "" : " containing \"" + fragments[0] + "\"");
  return "";
}

}  // namespace topopt::testing
