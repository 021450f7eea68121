// What the bindings accept from Python, decided in one place: every argument of every
// binding goes through these before the core sees it, so that a wrong shape, an index out
// of range (negative too), a NaN or a missing value is a TopOptError naming the argument
// ("tets[12, 3] = 9999 but there are 6122 nodes") and never a crash or garbage. Arrays may
// be NumPy arrays or nested sequences NumPy can read.
#pragma once
#include <pybind11/pybind11.h>

#include <string>

#include "common/types.h"

namespace topopt::py {

/// A str argument. Throws Error(InvalidParameter) naming `name` for anything else.
std::string text_arg(const pybind11::handle& value, const char* name);

/// A finite number in [lo, hi] (ints accepted). Throws Error(InvalidParameter) naming `name`
/// and the range for a non-number, NaN, an infinity or a value outside it.
double number_arg(const pybind11::handle& value, const char* name, double lo, double hi);

/// A whole number in [lo, hi]; as number_arg, and 2.5 is refused.
int int_arg(const pybind11::handle& value, const char* name, int lo, int hi);

/// #n by 3 finite coordinates, n >= 1 (`rows_name` "#V" for the message on a wrong shape).
MatX3d points_arg(const pybind11::handle& value, const char* name, const char* rows_name);

/// #n by `Cols` integer indices into `count` things (`counted`: "nodes"), each in [0, count),
/// n >= 1. Whole-valued floats are accepted, 2.5 or True are not.
template <int Cols>
Eigen::Matrix<int, Eigen::Dynamic, Cols, Eigen::RowMajor> index_arg(const pybind11::handle& value, const char* name,
                                                                    long count, const char* counted);

/// One integer tag per row of something (`per`: "tet", `expected` of them), each >= lo; None
/// or an empty array gives an empty vector when `optional`.
VecXi tags_arg(const pybind11::handle& value, const char* name, long expected, const char* per, int lo,
               bool optional = false);

/// One finite number per row of something (`per`: "tet", `expected` of them), each in [lo, hi]
/// (NaN and infinities named as such).
VecXd values_arg(const pybind11::handle& value, const char* name, long expected, const char* per, double lo, double hi);

/// A tet mesh from the arguments "nodes" (#V by 3), "tets" (#T by 4 indices into nodes) and
/// "domain" (#T tags >= 0; None or empty: every tet design), each checked as above.
TetMesh tet_mesh_arg(const pybind11::handle& nodes, const pybind11::handle& tets, const pybind11::handle& domain);

}  // namespace topopt::py
