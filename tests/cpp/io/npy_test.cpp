// NPY files: what write_npy writes reads back bit for bit with numpy's header layout, files
// as numpy.save writes them are read, and what the reader does not take is a named error.
#include "io/npy.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>

#include "common/error.h"

namespace topopt::io {
namespace {

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("topopt_npy_" + std::to_string(::getpid()) + "_" + name)).string();
}

std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

void spit(const std::string& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }

/// A file laid out as numpy.save (format 1.0) lays it out: the header padded with spaces to
/// `header_length` bytes (numpy 1.24 uses 118 for these small arrays: 10 + 118 = 128), then `data`.
std::string numpy_file(const std::string& dict, size_t header_length, const std::string& data) {
  std::string header = dict;
  header.append(header_length - header.size() - 1, ' ');
  header += '\n';
  std::string out = "\x93NUMPY";
  out += '\x01';
  out += '\x00';
  out += static_cast<char>(header_length & 0xff);
  out += static_cast<char>(header_length >> 8);
  return out + header + data;
}

template <typename T>
std::string raw(std::initializer_list<T> values) {
  std::string s;
  for (T v : values) s.append(reinterpret_cast<const char*>(&v), sizeof v);
  return s;
}

/// Expects `f` to throw an Error with `code` whose message contains `words`.
void expect_error(const std::function<void()>& f, ErrorCode code, const std::string& words) {
  try {
    f();
    ADD_FAILURE() << "no error; expected one saying: " << words;
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), code) << e.what();
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  }
}

TEST(Npy, RoundTripKeepsShapeTypeAndValues) {
  MatX3d V(3, 3);
  V << 0.1, -2, 3e300, 4, 5.5, -6, 7, 8, 1e-300;
  MatX4i T(2, 4);
  T << 0, 1, 2, 3, 7, -1, 2147483647, 5;
  VecXd d(4);
  d << 0.25, 1, 0, 0.5;
  const std::string pv = temp_path("v.npy"), pt = temp_path("t.npy"), pd = temp_path("d.npy");
  write_npy(pv, V);
  write_npy(pt, T);
  write_npy(pd, d);
  NpyArray a = read_npy(pv), b = read_npy(pt), c = read_npy(pd);
  EXPECT_EQ(a.shape, (std::vector<long>{3, 3}));
  EXPECT_FALSE(a.is_integer);
  EXPECT_EQ(b.shape, (std::vector<long>{2, 4}));
  EXPECT_TRUE(b.is_integer);
  EXPECT_EQ(c.shape, (std::vector<long>{4}));
  EXPECT_EQ(MatX3d(npy_real(a, 3, "V")), V);
  EXPECT_EQ(MatX4i(npy_integer(b, 4, "T").cast<int>()), T);
  EXPECT_EQ(VecXd(npy_real(c, 1, "d")), d);
  // numpy's layout: the magic, version 1.0, and the values starting at a multiple of 64
  const std::string bytes = slurp(pv);
  ASSERT_GT(bytes.size(), 10u);
  EXPECT_EQ(bytes.substr(0, 8), std::string("\x93NUMPY\x01\x00", 8));
  const size_t header = static_cast<unsigned char>(bytes[8]) | static_cast<unsigned char>(bytes[9]) << 8;
  EXPECT_EQ((10 + header) % 64, 0u);
  EXPECT_EQ(bytes.size(), 10 + header + 9 * sizeof(double));
  EXPECT_EQ(bytes[10 + header - 1], '\n');
  EXPECT_NE(bytes.find("'descr': '<f8', 'fortran_order': False, 'shape': (3, 3), }"), std::string::npos);
  EXPECT_NE(slurp(pd).find("'shape': (4,), }"), std::string::npos);
  for (const auto& p : {pv, pt, pd}) std::filesystem::remove(p);
}

TEST(Npy, EmptyArraysRoundTrip) {
  const std::string p = temp_path("empty.npy");
  write_npy(p, MatX3i(0, 3));
  NpyArray a = read_npy(p);
  EXPECT_EQ(a.shape, (std::vector<long>{0, 3}));
  EXPECT_EQ(npy_integer(a, 3, "F").rows(), 0);
  std::filesystem::remove(p);
}

TEST(Npy, ReadsWhatNumpySaves) {
  const std::string pi = temp_path("i8.npy"), pf = temp_path("f4.npy");
  spit(pi, numpy_file("{'descr': '<i8', 'fortran_order': False, 'shape': (2, 2), }", 118, raw<int64_t>({1, -2, 3, 4})));
  spit(pf, numpy_file("{'descr': '<f4', 'fortran_order': False, 'shape': (3,), }", 118, raw<float>({1.5f, -2, 3.25f})));
  RowMatXl m = npy_integer(read_npy(pi), 2, "m");
  EXPECT_EQ(m(0, 1), -2);
  EXPECT_EQ(m(1, 0), 3);
  RowMatXd f = npy_real(read_npy(pf), 1, "f");
  EXPECT_EQ(f.rows(), 3);
  EXPECT_EQ(f(2, 0), 3.25);
  // integers are taken where reals are asked for
  EXPECT_EQ(npy_real(read_npy(pi), 2, "m")(1, 1), 4.0);
  std::filesystem::remove(pi);
  std::filesystem::remove(pf);
}

TEST(Npy, WhatIsNotTakenIsANamedError) {
  const std::string p = temp_path("bad.npy");
  expect_error([&] { read_npy(p + ".missing"); }, ErrorCode::Io, "file not found: " + p + ".missing");
  spit(p, "PK\x03\x04 not an npy file at all");
  expect_error([&] { read_npy(p); }, ErrorCode::Io, p + " is not an NPY file");
  spit(p, numpy_file("{'descr': '<f8', 'fortran_order': True, 'shape': (1, 1), }", 118, raw<double>({1})));
  expect_error([&] { read_npy(p); }, ErrorCode::Io, "Fortran-ordered NPY arrays are not read");
  spit(p, numpy_file("{'descr': '>f8', 'fortran_order': False, 'shape': (1,), }", 118, raw<double>({1})));
  expect_error([&] { read_npy(p); }, ErrorCode::Io, "NPY dtype '>f8' is not read");
  spit(p, numpy_file("{'descr': '<f8', 'fortran_order': False, 'shape': (1, 1, 1), }", 118, raw<double>({1})));
  expect_error([&] { read_npy(p); }, ErrorCode::Io, "an NPY array of 3 dimensions; 1 or 2 expected");
  spit(p, numpy_file("{'descr': '<f8', 'fortran_order': False, 'shape': (4,), }", 118, raw<double>({1, 2})));
  expect_error([&] { read_npy(p); }, ErrorCode::Io, "NPY data cut short (4 values expected)");
  spit(p, numpy_file("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 2), }", 118, raw<double>({1, NAN, 3, 4})));
  expect_error([&] { npy_real(read_npy(p), 2, "nodes"); }, ErrorCode::InvalidParameter,
               "nodes: value 1 is not a finite number");
  expect_error([&] { npy_real(read_npy(p), 3, "nodes"); }, ErrorCode::InvalidParameter,
               "nodes: 3 columns expected, the array is 2 x 2");
  expect_error([&] { npy_integer(read_npy(p), 2, "tets"); }, ErrorCode::InvalidParameter,
               "tets: integers expected, the array holds floats");
  std::filesystem::remove(p);
}

}  // namespace
}  // namespace topopt::io
