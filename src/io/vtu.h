// VTK XML unstructured grid (.vtu, ASCII) for ParaView: the tet mesh with point and cell data.
#pragma once
#include <string>
#include <vector>

#include "common/types.h"

namespace topopt::io {

/// A named field: `values` holds `components` numbers per point (or cell), entity-major.
struct VtuField {
  std::string name;
  int components = 1;
  std::vector<double> values;
};

/// Writes the tets of `mesh` with the cell field "domain" plus the given fields.
/// Throws Error(Io) if the file cannot be written.
void write_vtu(const std::string& path, const TetMesh& mesh, const std::vector<VtuField>& point_data,
               const std::vector<VtuField>& cell_data);

/// The cell field `name` of a .vtu that write_vtu wrote (ASCII): one number per cell,
/// NumberOfCells of them; `points` (optional) gets NumberOfPoints. Throws Error(Io) when the
/// file cannot be read, lacks the field or holds fewer or more numbers than cells.
std::vector<double> read_vtu_cell_field(const std::string& path, const std::string& name, long* points = nullptr);

}  // namespace topopt::io
