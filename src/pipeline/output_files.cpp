// Output folder checks and write-then-rename (see output_files.h).
#include "pipeline/output_files.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include "common/error.h"

namespace topopt::pipeline {
namespace fs = std::filesystem;

namespace {

/// The process's umask as the kernel reports it (reading it with umask() would change it
/// for a moment under other threads); 022 where /proc does not say.
mode_t current_umask() {
  std::ifstream status("/proc/self/status");
  std::string key;
  while (status >> key)
    if (key == "Umask:") {
      std::string octal;
      status >> octal;
      return static_cast<mode_t>(std::strtol(octal.c_str(), nullptr, 8));
    }
  return 022;
}

/// A new empty file named after `name` in `dir` (mkstemp: created here, never an existing
/// file or link), with the permissions a plainly created file gets. Returns its path, or ""
/// with errno set.
std::string fresh_file(const fs::path& dir, const std::string& name) {
  std::string pattern = (dir / ("." + name + ".tmp-XXXXXX")).string();
  std::vector<char> buf(pattern.begin(), pattern.end());
  buf.push_back('\0');
  const int fd = ::mkstemp(buf.data());
  if (fd < 0) return "";
  ::fchmod(fd, 0666 & ~current_umask());
  ::close(fd);
  return std::string(buf.data());
}

}  // namespace

void prepare_output_folder(const std::string& dir, const std::string& setting) {
  const std::string fix = ": choose a folder you can write to with " + setting;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw Error(ErrorCode::Io, "cannot create the output folder " + dir + " (" + ec.message() + ")" + fix);
  if (!fs::is_directory(dir, ec))
    throw Error(ErrorCode::Io, "the output folder " + dir + " is a file, not a folder" + fix);
  const std::string probe = fresh_file(dir, "write-test");
  if (probe.empty())
    throw Error(ErrorCode::Io, "cannot write in the output folder " + dir + " (" + std::strerror(errno) + ")" + fix);
  fs::remove(probe, ec);
}

std::string write_replacing(const std::string& path, const std::function<void(const std::string&)>& write) {
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  const std::string temporary = fresh_file(dir, target.filename().string());
  if (temporary.empty())
    throw Error(ErrorCode::Io, "cannot write " + path + " (" + std::strerror(errno) + "): check the folder");
  try {
    write(temporary);
  } catch (...) {
    std::error_code ec;
    fs::remove(temporary, ec);
    throw;
  }
  std::error_code ec;
  fs::rename(temporary, target, ec);  // replaces a file or symlink named `path`; never follows it
  if (ec) {
    const std::string reason = ec.message();
    fs::remove(temporary, ec);
    throw Error(ErrorCode::Io, "cannot write " + path + " (" + reason + ")");
  }
  return path;
}

}  // namespace topopt::pipeline
