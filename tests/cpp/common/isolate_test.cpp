// run_isolated: answers, errors, crashes, aborts, hangs and cancels of the child reach the
// caller as values or named errors, and the caller keeps running.
#include "common/isolate.h"

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <thread>

namespace topopt {
namespace {

ErrorCode code_of(const std::function<std::string()>& work, double seconds = 5, const Progress& p = {}) {
  try {
    run_isolated("the test's work", seconds, work, p);
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("the test's work"), std::string::npos) << e.what();
    return e.code();
  }
  ADD_FAILURE() << "no error";
  return ErrorCode::Internal;
}

TEST(Isolate, ReturnsTheChildsBytesLargeOnesToo) {
  EXPECT_EQ(run_isolated("x", 5, [] { return std::string("abc\0def", 7); }), std::string("abc\0def", 7));
  std::string big(50 << 20, 'q');  // larger than any pipe buffer: read while written
  big[12345] = 'z';
  EXPECT_EQ(run_isolated("x", 30, [&] { return big; }), big);
}

TEST(Isolate, CarriesTheChildsErrorWithItsCode) {
  try {
    run_isolated("x", 5, []() -> std::string { throw Error(ErrorCode::FaceNotFound, "no Face99 here"); });
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::FaceNotFound);
    EXPECT_STREQ(e.what(), "no Face99 here");
  }
}

TEST(Isolate, ASegfaultAnAbortOrASilentExitIsNamedCrashed) {
  EXPECT_EQ(code_of([]() -> std::string {
              std::raise(SIGSEGV);
              return "";
            }),
            ErrorCode::Crashed);
  EXPECT_EQ(code_of([]() -> std::string { std::abort(); }), ErrorCode::Crashed);
  EXPECT_EQ(code_of([]() -> std::string { std::_Exit(0); }), ErrorCode::Crashed);
  EXPECT_EQ(code_of([]() -> std::string { throw std::string("thrown like Gmsh does"); }), ErrorCode::Internal);
}

TEST(Isolate, AHangIsStoppedAtTheDeadline) {
  auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(code_of(
                []() -> std::string {
                  for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));
                },
                0.5),
            ErrorCode::Timeout);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
}

TEST(Isolate, ACancelEndsTheChildAtOnce) {
  Progress p;
  auto t0 = std::chrono::steady_clock::now();
  p.cancelled = [&] { return std::chrono::steady_clock::now() - t0 > std::chrono::milliseconds(300); };
  EXPECT_EQ(code_of(
                []() -> std::string {
                  for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));
                },
                60, p),
            ErrorCode::Cancelled);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
}

}  // namespace
}  // namespace topopt
