// Result files: the output folder made and tested first, a folder that cannot be made named
// with the setting to change, every file written under a temporary name and renamed, a
// symlink at the final name replaced and its target left alone.
#include "pipeline/output_files.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/error.h"

namespace topopt::pipeline {
namespace {
namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("topopt_out_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string text_of(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(OutputFiles, TheFolderIsMadeAndTestedFirst) {
  const fs::path d = scratch("folder");
  EXPECT_NO_THROW(prepare_output_folder((d / "a" / "b").string(), "'output.directory'"));
  EXPECT_TRUE(fs::is_directory(d / "a" / "b"));
  EXPECT_TRUE(fs::is_empty(d / "a" / "b"));  // the test file is gone
  std::ofstream(d / "file") << "x";
  try {
    prepare_output_folder((d / "file" / "out").string(), "'output.directory' (or --out-dir)");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Io);
    const std::string m = e.what();
    EXPECT_NE(m.find("cannot create the output folder " + (d / "file" / "out").string()), std::string::npos) << m;
    EXPECT_NE(m.find("with 'output.directory' (or --out-dir)"), std::string::npos) << m;
  }
  EXPECT_THROW(prepare_output_folder((d / "file").string(), "--out-dir"), Error);  // a file, not a folder
  fs::remove_all(d);
}

TEST(OutputFiles, ASymlinkAtTheFinalNameIsReplacedNotFollowed) {
  const fs::path d = scratch("link");
  std::ofstream(d / "precious.txt") << "keep me";
  fs::create_symlink(d / "precious.txt", d / "result.stl");
  write_replacing((d / "result.stl").string(), [](const std::string& p) { std::ofstream(p) << "the result"; });
  EXPECT_EQ(text_of(d / "precious.txt"), "keep me");
  EXPECT_FALSE(fs::is_symlink(d / "result.stl"));
  EXPECT_EQ(text_of(d / "result.stl"), "the result");
  // a plain file created by us has the permissions a plainly created file gets
  struct stat st;
  ASSERT_EQ(::stat((d / "result.stl").c_str(), &st), 0);
  const mode_t mask = ::umask(022);
  ::umask(mask);
  EXPECT_EQ(st.st_mode & 0777, 0666 & ~mask);
  fs::remove_all(d);
}

TEST(OutputFiles, AFailedWriteLeavesTheOldFileAndNoTemporary) {
  const fs::path d = scratch("fail");
  std::ofstream(d / "history.csv") << "old";
  EXPECT_THROW(write_replacing((d / "history.csv").string(),
                               [](const std::string& p) {
                                 std::ofstream(p) << "half";
                                 throw Error(ErrorCode::Io, "disk full");
                               }),
               Error);
  EXPECT_EQ(text_of(d / "history.csv"), "old");
  size_t files = 0;
  for (const auto& e : fs::directory_iterator(d)) files += e.is_regular_file();
  EXPECT_EQ(files, 1u);
  fs::remove_all(d);
}

}  // namespace
}  // namespace topopt::pipeline
