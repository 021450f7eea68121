// Foreign geometry in a child process (see foreign.h).
#include "brep/foreign.h"

#include <fcntl.h>
#include <sys/resource.h>
#include <unistd.h>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <BinTools.hxx>
#include <Standard_Failure.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>

#include <algorithm>
#include <cfenv>
#include <csignal>
#include <fstream>
#include <sstream>

#include "brep/occt_guard.h"
#include "common/error.h"
#include "common/isolate.h"
#include "common/number_text.h"

namespace topopt::brep {
namespace {

constexpr double kMB = 1024.0 * 1024.0;

std::string seconds_text(double s) { return number_text(s, 3) + " s"; }

/// Address space in use now (bytes), from /proc/self/statm; 0 if unknown.
double address_space_now() {
  std::ifstream statm("/proc/self/statm");
  double pages = 0;
  statm >> pages;
  return pages * static_cast<double>(::sysconf(_SC_PAGESIZE));
}

/// What a child does first: faults end it (the caller's handlers, OCCT's in the CLI or
/// FreeCAD's, would recover inside OCCT or call exit() in a copy of the caller), no
/// floating-point traps, stdout to /dev/null (OCCT's reader prints there, and a flush would
/// also repeat what the caller had buffered), and an address-space limit of what it has plus
/// `memory` bytes.
void enter_child(double memory) {
  for (int sig : {SIGSEGV, SIGBUS, SIGILL, SIGFPE, SIGABRT}) std::signal(sig, SIG_DFL);
  const int null = ::open("/dev/null", O_WRONLY);
  if (null >= 0) ::dup2(null, STDOUT_FILENO), ::close(null);
  std::feclearexcept(FE_ALL_EXCEPT);
  fedisableexcept(FE_ALL_EXCEPT);
  const double now = address_space_now();
  if (now > 0) {
    rlimit limit{};
    limit.rlim_cur = limit.rlim_max = static_cast<rlim_t>(now + memory);
    ::setrlimit(RLIMIT_AS, &limit);
  }
}

double foreign_memory(double bytes, const ForeignParams& p) {
  return p.memory_gb > 0 ? p.memory_gb * 1024 * kMB : std::max(4 * 1024 * kMB, 50 * bytes);
}

/// Runs `work` in the child, OCCT's exceptions and a failed allocation turned into words.
std::string child_work(const ForeignInput& input, const std::string& doing, double memory,
                       const std::function<std::string()>& work) {
  try {
    return work();
  } catch (const Standard_Failure& f) {
    throw Error(input.code, input.subject + " is damaged: OCCT could not finish " + doing + " it (" +
                                occt_failure_kind(f) + "); " + input.advice);
  } catch (const std::bad_alloc&) {
    throw Error(input.code, input.subject + " is damaged or too large: " + doing + " it needed more than " +
                                std::to_string(static_cast<long>(memory / kMB / 1024 + 0.5)) + " GB of memory; " +
                                input.advice);
  }
}

/// The signal in run_isolated's message on a crash ("... crashed with Segmentation fault
/// (signal 11) and was stopped ..."), as " (Segmentation fault, signal 11)"; empty if absent.
std::string signal_detail(const std::string& message) {
  const size_t from = message.find(" crashed with "), to = message.find(" and was stopped");
  if (from == std::string::npos || to == std::string::npos || to < from) return "";
  std::string detail = message.substr(from + 14, to - from - 14);
  const size_t paren = detail.find(" (signal ");
  if (paren != std::string::npos && detail.back() == ')')
    detail = detail.substr(0, paren) + ", " + detail.substr(paren + 2, detail.size() - paren - 3);
  return " (" + detail + ")";
}

long line_at(const std::string& text, std::streamoff pos) {
  if (pos < 0 || static_cast<size_t>(pos) > text.size()) pos = static_cast<std::streamoff>(text.size());
  return 1 + std::count(text.begin(), text.begin() + pos, '\n');
}

}  // namespace

double foreign_seconds(double bytes, const ForeignParams& p) {
  return p.seconds > 0 ? p.seconds : p.base_seconds + p.seconds_per_mb * bytes / kMB;
}

double shape_bytes(const TopoDS_Shape& shape) {
  TopTools_IndexedMapOfShape faces;
  if (!shape.IsNull()) TopExp::MapShapes(shape, TopAbs_FACE, faces);
  return 4096.0 * faces.Extent();
}

std::string run_foreign(const ForeignInput& input, const std::string& doing, const ForeignParams& params,
                        const std::function<std::string()>& work, const Progress& progress) {
  const double seconds = foreign_seconds(input.bytes, params), memory = foreign_memory(input.bytes, params);
  const pid_t caller = ::getpid();
  const std::string what = "OCCT " + doing + " " + input.subject;  // run_isolated's own messages start so
  try {
    return run_isolated(
        what, seconds,
        [&] {
          if (::getpid() != caller) enter_child(memory);
          return child_work(input, doing, memory, work);
        },
        progress);
  } catch (const Error& e) {
    const bool own = std::string(e.what()).rfind(what, 0) == 0;
    if (own && e.code() == ErrorCode::Crashed)
      throw Error(ErrorCode::Crashed, input.subject + " is damaged: OCCT crashed " + doing + " it" +
                                          signal_detail(e.what()) + "; " + input.advice);
    if (own && e.code() == ErrorCode::Timeout)
      throw Error(ErrorCode::Timeout, input.subject + " is damaged or very large: OCCT did not finish " + doing +
                                          " it within " + seconds_text(seconds) + "; " + input.advice +
                                          ", or allow more time (--time-budget) if it is large and sound");
    throw;
  }
}

void precheck_brep_text(const std::string& text, const ForeignInput& input) {
  const size_t header = text.substr(0, 4096).find("CASCADE Topology V");
  if (header == std::string::npos)
    throw Error(
        ErrorCode::Io,
        input.subject + " is not BREP text: it lacks the 'CASCADE Topology' header at its start; " + input.advice);
  if (text.find("TShapes", header) == std::string::npos)
    throw Error(ErrorCode::Io,
                input.subject + " is cut short: its text ends before the list of shapes ('TShapes', line " +
                    std::to_string(line_at(text, static_cast<std::streamoff>(text.size()))) + "); " + input.advice);
}

TopoDS_Shape parse_brep_text(const std::string& text, const ForeignInput& input) {
  std::istringstream in(text);
  in.exceptions(std::ios::failbit | std::ios::badbit);
  TopoDS_Shape shape;
  BRep_Builder builder;
  try {
    BRepTools::Read(shape, in, builder);
  } catch (const std::ios_base::failure&) {
    const std::streamoff pos = in.rdbuf()->pubseekoff(0, std::ios::cur, std::ios::in);
    throw Error(ErrorCode::Io, input.subject + " is damaged or cut short: reading it failed at line " +
                                   std::to_string(line_at(text, pos)) + " of " +
                                   std::to_string(line_at(text, static_cast<std::streamoff>(text.size()))) + "; " +
                                   input.advice);
  }
  if (shape.IsNull()) throw Error(ErrorCode::Io, input.subject + " holds no shape; " + input.advice);
  return shape;
}

std::string handover_bytes(const TopoDS_Shape& shape, const ForeignInput& input) {
  std::ostringstream out(std::ios::binary);
  BinTools::Write(shape, out);
  std::string bytes = out.str();
  shape_from_handover(bytes, input);
  return bytes;
}

TopoDS_Shape shape_from_handover(const std::string& bytes, const ForeignInput& input) {
  return guard_occt("reading the shape OCCT wrote for " + input.subject, [&] {
    std::istringstream in(bytes, std::ios::binary);
    TopoDS_Shape shape;
    BinTools::Read(shape, in);
    if (shape.IsNull()) throw Error(ErrorCode::Internal, "the shape OCCT wrote for " + input.subject + " is empty");
    return shape;
  });
}

}  // namespace topopt::brep
