#include "brep/shape_io.h"

#include <BRepTools.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <IGESControl_Reader.hxx>
#include <STEPControl_Reader.hxx>
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "brep/occt_guard.h"
#include "common/error.h"

namespace topopt::brep {
namespace {

const char* kFileAdvice = "re-export it from your CAD system";
const char* kTextAdvice = "re-import or rebuild it (the document may have been damaged)";

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

/// Runs in the child: STEP or IGES through OCCT's reader, handed back as binary BREP.
template <class Reader>
std::string read_with(const std::string& path, const char* format, const ForeignInput& input) {
  Reader reader;
  if (reader.ReadFile(path.c_str()) != IFSelect_RetDone)
    throw Error(ErrorCode::Io, "cannot read " + input.subject + " as " + format +
                                   ": the file is damaged or not in that format; " + input.advice);
  reader.TransferRoots();
  TopoDS_Shape shape = reader.OneShape();
  if (shape.IsNull()) throw Error(ErrorCode::Io, input.subject + " holds no shape that can be transferred");
  return handover_bytes(shape, input);
}

std::string file_text(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  if (!f) throw Error(ErrorCode::Io, "cannot read the file '" + path + "'");
  return s.str();
}

/// BREP text through the child: pre-checked here, parsed there, handed back as binary BREP.
TopoDS_Shape read_brep_text(const std::string& text, const ForeignInput& input, const ForeignParams& params,
                            const Progress& progress) {
  precheck_brep_text(text, input);
  const std::string clean = run_foreign(
      input, "reading", params, [&] { return handover_bytes(parse_brep_text(text, input), input); }, progress);
  return shape_from_handover(clean, input);
}

}  // namespace

TopoDS_Shape read_shape_file(const std::string& path, const std::string& what, const ForeignParams& params,
                             const Progress& progress) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw Error(ErrorCode::Io, "file not found: '" + path + "'");
  const std::string ext = lower_extension(path);
  ForeignInput input{(what.empty() ? "the file '" : "the " + what + "'s file '") + path + "'", kFileAdvice,
                     static_cast<double>(std::filesystem::file_size(path, ec))};
  if (ext == ".brep" || ext == ".brp") return read_brep_text(file_text(path), input, params, progress);
  std::string clean;
  if (ext == ".step" || ext == ".stp")
    clean = run_foreign(
        input, "reading", params, [&] { return read_with<STEPControl_Reader>(path, "STEP", input); }, progress);
  else if (ext == ".iges" || ext == ".igs")
    clean = run_foreign(
        input, "reading", params, [&] { return read_with<IGESControl_Reader>(path, "IGES", input); }, progress);
  else
    throw Error(ErrorCode::Io,
                "unknown file type '" + ext + "' for '" + path + "': use .step/.stp, .iges/.igs or .brep");
  return shape_from_handover(clean, input);
}

TopoDS_Shape read_brep_string(const std::string& text, const std::string& what, const ForeignParams& params,
                              const Progress& progress) {
  ForeignInput input{"the " + what + " (its BREP text)", kTextAdvice, static_cast<double>(text.size())};
  return read_brep_text(text, input, params, progress);
}

std::string write_brep_string(const TopoDS_Shape& shape) {
  std::ostringstream out;
  BRepTools::Write(shape, out);
  return out.str();
}

}  // namespace topopt::brep
