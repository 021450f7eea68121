// VTK XML unstructured grid writer (see vtu.h).
#include "io/vtu.h"

#include <cstdio>
#include <fstream>
#include <sstream>

#include "common/error.h"

namespace topopt::io {
namespace {

void write_field(FILE* f, const VtuField& field, long count, const std::string& path) {
  if (field.components < 1 || static_cast<long>(field.values.size()) != count * field.components)
    throw Error(ErrorCode::Internal, "VTU field " + field.name + " has the wrong size for " + path);
  std::fprintf(f, "        <DataArray type=\"Float64\" Name=\"%s\" NumberOfComponents=\"%d\" format=\"ascii\">\n",
               field.name.c_str(), field.components);
  for (long i = 0; i < count; ++i) {
    for (int c = 0; c < field.components; ++c) std::fprintf(f, " %.9g", field.values[i * field.components + c]);
    std::fputc('\n', f);
  }
  std::fprintf(f, "        </DataArray>\n");
}

}  // namespace

void write_vtu(const std::string& path, const TetMesh& mesh, const std::vector<VtuField>& point_data,
               const std::vector<VtuField>& cell_data) {
  FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw Error(ErrorCode::Io, "cannot write " + path);
  const long nv = mesh.V.rows(), nt = mesh.T.rows();
  std::fprintf(f,
               "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" "
               "byte_order=\"LittleEndian\">\n  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"%ld\" "
               "NumberOfCells=\"%ld\">\n      <Points>\n        <DataArray type=\"Float64\" "
               "NumberOfComponents=\"3\" format=\"ascii\">\n",
               nv, nt);
  for (long i = 0; i < nv; ++i) std::fprintf(f, " %.12g %.12g %.12g\n", mesh.V(i, 0), mesh.V(i, 1), mesh.V(i, 2));
  std::fprintf(f,
               "        </DataArray>\n      </Points>\n      <Cells>\n"
               "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
  for (long t = 0; t < nt; ++t)
    std::fprintf(f, " %d %d %d %d\n", mesh.T(t, 0), mesh.T(t, 1), mesh.T(t, 2), mesh.T(t, 3));
  std::fprintf(f, "        </DataArray>\n        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
  for (long t = 0; t < nt; ++t) std::fprintf(f, " %ld", 4 * (t + 1));
  std::fprintf(f, "\n        </DataArray>\n        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
  for (long t = 0; t < nt; ++t) std::fprintf(f, " 10");
  std::fprintf(f, "\n        </DataArray>\n      </Cells>\n      <PointData>\n");
  for (const auto& fd : point_data) write_field(f, fd, nv, path);
  std::fprintf(f,
               "      </PointData>\n      <CellData>\n"
               "        <DataArray type=\"Int32\" Name=\"domain\" format=\"ascii\">\n");
  for (long t = 0; t < nt; ++t) std::fprintf(f, " %d", mesh.domain.size() == nt ? mesh.domain[t] : 0);
  std::fprintf(f, "\n        </DataArray>\n");
  for (const auto& fd : cell_data) write_field(f, fd, nt, path);
  std::fprintf(f, "      </CellData>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n");
  bool ok = std::ferror(f) == 0;
  ok &= std::fclose(f) == 0;
  if (!ok) throw Error(ErrorCode::Io, "error while writing " + path + " (disk full?)");
}

namespace {
/// The whole number after `key="` in `text` from `from` on (-1 when absent).
long attribute_number(const std::string& text, const std::string& key, size_t from = 0) {
  const size_t at = text.find(key + "=\"", from);
  return at == std::string::npos ? -1 : std::atol(text.c_str() + at + key.size() + 2);
}
}  // namespace

std::vector<double> read_vtu_cell_field(const std::string& path, const std::string& name, long* points) {
  std::ifstream in(path);
  if (!in) throw Error(ErrorCode::Io, "cannot read '" + path + "' (missing or not readable)");
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  const long cells = attribute_number(text, "NumberOfCells");
  if (points) *points = attribute_number(text, "NumberOfPoints");
  const size_t cell_data = text.find("<CellData");
  const size_t field = cell_data == std::string::npos ? cell_data : text.find("Name=\"" + name + "\"", cell_data);
  const size_t start = field == std::string::npos ? field : text.find('>', field);
  const size_t end = start == std::string::npos ? start : text.find("</DataArray>", start);
  if (cells < 0 || end == std::string::npos)
    throw Error(ErrorCode::Io,
                "'" + path + "' holds no cell field \"" + name + "\" (not a density.vtu of topopt optimize?)");
  std::istringstream numbers(text.substr(start + 1, end - start - 1));
  std::vector<double> values;
  for (double v; numbers >> v;) values.push_back(v);
  if (static_cast<long>(values.size()) != cells)
    throw Error(ErrorCode::Io, "'" + path + "': the field \"" + name + "\" holds " + std::to_string(values.size()) +
                                   " values for " + std::to_string(cells) + " cells (file cut short?)");
  return values;
}

}  // namespace topopt::io
