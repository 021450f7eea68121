// NPY files (NumPy's array format: a short text header, then the raw values in C order), the
// form in which the worker process and the FreeCAD workbench hand arrays to each other.
// numpy.load reads what write_npy writes; read_npy reads what numpy.save writes.
#pragma once
#include <Eigen/Dense>
#include <string>
#include <vector>

#include "common/types.h"

namespace topopt::io {

/// Row-major dynamic matrices: what read_npy hands back before the caller picks its shape.
using RowMatXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using RowMatXl = Eigen::Matrix<long long, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// An array read from an NPY file: its shape (one entry for a 1-D array, two for a 2-D one)
/// and its values in C order, as doubles (`real`, dtype float32/float64) or as 64-bit
/// integers (`integer`, dtype int32/int64).
struct NpyArray {
  std::vector<long> shape;
  bool is_integer = false;
  std::vector<double> real;
  std::vector<long long> integer;
  long rows() const { return shape.empty() ? 0 : shape[0]; }
  long cols() const { return shape.size() < 2 ? 1 : shape[1]; }
};

/// Reads an NPY file (format versions 1 to 3, little-endian float32/float64/int32/int64,
/// C order, 1 or 2 dimensions). Throws Error(Io) naming the file when it is missing, not an
/// NPY file, or holds a layout this reader does not take (the message names the layout).
NpyArray read_npy(const std::string& path);

/// The array as #rows by `cols` doubles. `what` names it in messages ("nodes"). A 1-D array
/// is taken as one column. Throws Error(InvalidParameter) if its column count is not `cols`
/// (cols < 0: any) or a value is not finite.
RowMatXd npy_real(const NpyArray& a, long cols, const std::string& what);

/// The array as #rows by `cols` integers; floats are refused. Throws
/// Error(InvalidParameter) naming `what` if the column count is wrong (cols < 0: any).
RowMatXl npy_integer(const NpyArray& a, long cols, const std::string& what);

/// Writes `data` (#rows by `cols` in C order; cols = 0: a 1-D array of #rows) as NPY 1.0,
/// dtype float64. Throws Error(Io) naming the file on failure.
void write_npy(const std::string& path, const double* data, long rows, long cols);

/// The same for int32 values.
void write_npy(const std::string& path, const int* data, long rows, long cols);

/// Eigen conveniences: row-major #rows by 3 / 4 matrices as 2-D arrays, vectors as 1-D.
inline void write_npy(const std::string& path, const MatX3d& m) { write_npy(path, m.data(), m.rows(), 3); }
inline void write_npy(const std::string& path, const MatX3i& m) { write_npy(path, m.data(), m.rows(), 3); }
inline void write_npy(const std::string& path, const MatX4i& m) { write_npy(path, m.data(), m.rows(), 4); }
inline void write_npy(const std::string& path, const VecXi& v) { write_npy(path, v.data(), v.size(), 0); }
inline void write_npy(const std::string& path, const VecXd& v) { write_npy(path, v.data(), v.size(), 0); }

}  // namespace topopt::io
