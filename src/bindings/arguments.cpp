// Argument checks of the bindings (see arguments.h).
#include "bindings/arguments.h"

#include <pybind11/numpy.h>

#include <cmath>
#include <sstream>

#include "common/error.h"

namespace topopt::py {
namespace pyb = pybind11;
namespace {

[[noreturn]] void refuse(const std::string& message) { throw Error(ErrorCode::InvalidParameter, message); }

std::string number_text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

std::string type_name(const pyb::handle& value) { return pyb::str(pyb::type::handle_of(value).attr("__name__")); }

/// `value` as a NumPy array of numbers (bool, complex, text and objects refused).
pyb::array numeric_array(const pyb::handle& value, const char* name, const std::string& wanted) {
  pyb::array a = pyb::array::ensure(value);
  const char kind = a ? a.dtype().kind() : '?';
  if (kind != 'f' && kind != 'i' && kind != 'u')
    refuse(std::string(name) + " must be " + wanted + ", not " +
           (pyb::isinstance<pyb::array>(value) ? "an array of " + std::string(pyb::str(a.dtype().attr("name")))
                                               : "a " + type_name(value)));
  return a;
}

std::string shape_text(const pyb::array& a) {
  std::string s = "(";
  for (pyb::ssize_t d = 0; d < a.ndim(); ++d) s += (d ? ", " : "") + std::to_string(a.shape(d));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

/// A #n by `cols` array of doubles (n >= 1), in row-major order.
pyb::array_t<double, pyb::array::c_style> table(const pyb::handle& value, const char* name, long cols,
                                                const std::string& wanted) {
  pyb::array a = numeric_array(value, name, wanted);
  if (a.ndim() != 2 || a.shape(1) != cols)
    refuse(std::string(name) + " must be " + wanted + ", not of shape " + shape_text(a));
  if (a.shape(0) == 0) refuse(std::string(name) + " is empty: give at least one row");
  return pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>::ensure(a);
}

/// A 1-D array of doubles with `expected` entries (0 allowed when `optional`).
pyb::array_t<double, pyb::array::c_style> column(const pyb::handle& value, const char* name, long expected,
                                                 const char* per, bool optional) {
  const std::string wanted = "one number per " + std::string(per) + " (" + std::to_string(expected) + ")";
  pyb::array a = numeric_array(value, name, wanted);
  if (a.ndim() != 1) refuse(std::string(name) + " must be " + wanted + ", not of shape " + shape_text(a));
  if (a.shape(0) != expected && !(optional && a.shape(0) == 0))
    refuse(std::string(name) + " has " + std::to_string(a.shape(0)) + " entries but there are " +
           std::to_string(expected) + " " + per + "s: give one per " + per);
  return pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>::ensure(a);
}

void check_whole(double v, const std::string& where) {
  if (!std::isfinite(v) || v != std::floor(v)) refuse(where + " = " + number_text(v) + " is not a whole number");
}

}  // namespace

std::string text_arg(const pyb::handle& value, const char* name) {
  if (!pyb::isinstance<pyb::str>(value)) refuse(std::string(name) + " must be a str, not a " + type_name(value));
  return value.cast<std::string>();
}

double number_arg(const pyb::handle& value, const char* name, double lo, double hi) {
  if (pyb::isinstance<pyb::bool_>(value) || !(pyb::isinstance<pyb::float_>(value) || pyb::isinstance<pyb::int_>(value)))
    refuse(std::string(name) + " must be a number, not a " + type_name(value));
  const double v = pyb::float_(pyb::reinterpret_borrow<pyb::object>(value));
  if (!std::isfinite(v)) refuse(std::string(name) + " is " + number_text(v) + ": give a finite number");
  if (v < lo) refuse(std::string(name) + " = " + number_text(v) + " but it must be at least " + number_text(lo));
  if (v > hi) refuse(std::string(name) + " = " + number_text(v) + " but it must be at most " + number_text(hi));
  return v;
}

int int_arg(const pyb::handle& value, const char* name, int lo, int hi) {
  const double v = number_arg(value, name, lo, hi);
  check_whole(v, name);
  return static_cast<int>(v);
}

MatX3d points_arg(const pyb::handle& value, const char* name, const char* rows_name) {
  const auto a = table(value, name, 3, std::string("an array of ") + rows_name + " by 3 coordinates");
  const long n = a.shape(0);
  MatX3d P = Eigen::Map<const MatX3d>(a.data(), n, 3);
  for (long i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c)
      if (!std::isfinite(P(i, c)))
        refuse(std::string(name) + "[" + std::to_string(i) + ", " + std::to_string(c) + "] is " + number_text(P(i, c)) +
               ": every coordinate must be a finite number");
  return P;
}

template <int Cols>
Eigen::Matrix<int, Eigen::Dynamic, Cols, Eigen::RowMajor> index_arg(const pyb::handle& value, const char* name,
                                                                    long count, const char* counted) {
  const auto a = table(value, name, Cols, "an array of #n by " + std::to_string(Cols) + " indices into the " + counted);
  const long n = a.shape(0);
  Eigen::Matrix<int, Eigen::Dynamic, Cols, Eigen::RowMajor> M(n, Cols);
  for (long i = 0; i < n; ++i)
    for (int c = 0; c < Cols; ++c) {
      const double v = a.at(i, c);
      const std::string where = std::string(name) + "[" + std::to_string(i) + ", " + std::to_string(c) + "]";
      check_whole(v, where);
      if (v < 0 || v >= static_cast<double>(count))
        refuse(where + " = " + number_text(v) + " but there are " + std::to_string(count) + " " + counted +
               " (indices 0 to " + std::to_string(count - 1) + ")");
      M(i, c) = static_cast<int>(v);
    }
  return M;
}

template MatX3i index_arg<3>(const pyb::handle&, const char*, long, const char*);
template MatX4i index_arg<4>(const pyb::handle&, const char*, long, const char*);

VecXi tags_arg(const pyb::handle& value, const char* name, long expected, const char* per, int lo, bool optional) {
  if (optional && value.is_none()) return VecXi();
  const auto a = column(value, name, expected, per, optional);
  VecXi tags(a.shape(0));
  for (long i = 0; i < tags.size(); ++i) {
    const std::string where = std::string(name) + "[" + std::to_string(i) + "]";
    const double v = a.at(i);
    check_whole(v, where);
    if (v < lo || v > 1e9) refuse(where + " = " + number_text(v) + " but tags start at " + std::to_string(lo));
    tags[i] = static_cast<int>(v);
  }
  return tags;
}

VecXd values_arg(const pyb::handle& value, const char* name, long expected, const char* per, double lo, double hi) {
  const auto a = column(value, name, expected, per, false);
  VecXd values = Eigen::Map<const VecXd>(a.data(), a.shape(0));
  for (long i = 0; i < values.size(); ++i) {
    const std::string where = std::string(name) + "[" + std::to_string(i) + "]";
    if (!std::isfinite(values[i]))
      refuse(where + " is " + number_text(values[i]) + ": every value must be a finite number");
    if (values[i] < lo || values[i] > hi)
      refuse(where + " = " + number_text(values[i]) + " is outside [" + number_text(lo) + ", " + number_text(hi) + "]");
  }
  return values;
}

TetMesh tet_mesh_arg(const pyb::handle& nodes, const pyb::handle& tets, const pyb::handle& domain) {
  TetMesh mesh;
  mesh.V = points_arg(nodes, "nodes", "#V");
  mesh.T = index_arg<4>(tets, "tets", mesh.V.rows(), "nodes");
  mesh.domain = tags_arg(domain, "domain", mesh.T.rows(), "tet", 0, true);
  if (mesh.domain.size() == 0) mesh.domain = VecXi::Zero(mesh.T.rows());
  return mesh;
}

}  // namespace topopt::py
