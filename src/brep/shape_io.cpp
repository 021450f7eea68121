#include "brep/shape_io.h"

#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <IGESControl_Reader.hxx>
#include <STEPControl_Reader.hxx>
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <sstream>

#include "common/error.h"

namespace topopt::brep {
namespace {

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

template <class Reader>
TopoDS_Shape read_with(Reader& reader, const std::string& path, const char* format) {
  if (reader.ReadFile(path.c_str()) != IFSelect_RetDone)
    throw Error(ErrorCode::Io,
                "cannot read '" + path + "' as " + format + ": the file is damaged or not in that format");
  reader.TransferRoots();
  TopoDS_Shape shape = reader.OneShape();
  if (shape.IsNull()) throw Error(ErrorCode::Io, "'" + path + "' holds no shape that can be transferred");
  return shape;
}

}  // namespace

TopoDS_Shape read_shape_file(const std::string& path) {
  if (!std::filesystem::exists(path)) throw Error(ErrorCode::Io, "file not found: '" + path + "'");
  const std::string ext = lower_extension(path);
  if (ext == ".step" || ext == ".stp") {
    STEPControl_Reader reader;
    return read_with(reader, path, "STEP");
  }
  if (ext == ".iges" || ext == ".igs") {
    IGESControl_Reader reader;
    return read_with(reader, path, "IGES");
  }
  if (ext == ".brep" || ext == ".brp") {
    TopoDS_Shape shape;
    BRep_Builder builder;
    if (!BRepTools::Read(shape, path.c_str(), builder) || shape.IsNull())
      throw Error(ErrorCode::Io, "cannot read '" + path + "' as BREP");
    return shape;
  }
  throw Error(ErrorCode::Io, "unknown file type '" + ext + "' for '" + path + "': use .step/.stp, .iges/.igs or .brep");
}

TopoDS_Shape read_brep_string(const std::string& text, const std::string& what) {
  std::istringstream in(text);
  TopoDS_Shape shape;
  BRep_Builder builder;
  try {
    BRepTools::Read(shape, in, builder);
  } catch (const Standard_Failure& e) {
    throw Error(ErrorCode::Io,
                "the " + what + " is not a valid BREP text: " + (e.GetMessageString() ? e.GetMessageString() : "?"));
  }
  if (shape.IsNull()) throw Error(ErrorCode::Io, "the " + what + " is not a valid BREP text (empty shape)");
  return shape;
}

std::string write_brep_string(const TopoDS_Shape& shape) {
  std::ostringstream out;
  BRepTools::Write(shape, out);
  return out.str();
}

}  // namespace topopt::brep
