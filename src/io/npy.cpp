// NPY reading and writing (see npy.h). The format: "\x93NUMPY", two version bytes, the
// header's length (2 bytes in version 1, 4 in versions 2 and 3), a Python dict literal
// {'descr': '<f8', 'fortran_order': False, 'shape': (R, C), } padded with spaces to a
// multiple of 64 bytes and ended by '\n', then the values.
#include "io/npy.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>

#include "common/error.h"

namespace topopt::io {
namespace {

const char kMagic[] = "\x93NUMPY";

/// The value of `key` in the header dict: the text after "'key':" up to the next comma at
/// depth 0 (a tuple's commas stay inside it).
std::string header_value(const std::string& header, const std::string& key, const std::string& path) {
  size_t at = header.find("'" + key + "'");
  if (at == std::string::npos) throw Error(ErrorCode::Io, path + ": NPY header without '" + key + "'");
  size_t colon = header.find(':', at);
  if (colon == std::string::npos) throw Error(ErrorCode::Io, path + ": malformed NPY header");
  size_t end = colon + 1;
  for (int depth = 0; end < header.size(); ++end) {
    char c = header[end];
    if (c == '(') ++depth;
    if (c == ')') --depth;
    if ((c == ',' && depth == 0) || c == '}') break;
  }
  std::string v = header.substr(colon + 1, end - colon - 1);
  const auto first = v.find_first_not_of(" \t'\""), last = v.find_last_not_of(" \t'\"");
  return first == std::string::npos ? "" : v.substr(first, last - first + 1);
}

std::vector<long> parse_shape(const std::string& text, const std::string& path) {
  if (text.size() < 2 || text.front() != '(' || text.back() != ')')
    throw Error(ErrorCode::Io, path + ": NPY shape '" + text + "' is not a tuple");
  std::vector<long> shape;
  std::stringstream items(text.substr(1, text.size() - 2));
  std::string item;
  while (std::getline(items, item, ',')) {
    if (item.find_first_not_of(" ") == std::string::npos) continue;
    char* end = nullptr;
    long n = std::strtol(item.c_str(), &end, 10);
    if (n < 0 || end == item.c_str()) throw Error(ErrorCode::Io, path + ": bad NPY shape '" + text + "'");
    shape.push_back(n);
  }
  if (shape.size() > 2)
    throw Error(ErrorCode::Io,
                path + ": an NPY array of " + std::to_string(shape.size()) + " dimensions; 1 or 2 expected");
  if (shape.empty()) shape.push_back(1);  // a scalar: one value
  return shape;
}

/// Reads the header; returns it and leaves `f` at the first value.
std::string read_header(std::ifstream& f, const std::string& path) {
  char magic[8] = {};
  f.read(magic, 8);
  if (!f || std::memcmp(magic, kMagic, 6) != 0) throw Error(ErrorCode::Io, path + " is not an NPY file");
  const int major = static_cast<unsigned char>(magic[6]);
  uint32_t length = 0;
  unsigned char b[4] = {};
  f.read(reinterpret_cast<char*>(b), major == 1 ? 2 : 4);
  if (!f || major < 1 || major > 3) throw Error(ErrorCode::Io, path + ": unknown NPY version " + std::to_string(major));
  length = b[0] | (b[1] << 8) | (static_cast<uint32_t>(b[2]) << 16) | (static_cast<uint32_t>(b[3]) << 24);
  std::string header(length, '\0');
  f.read(header.data(), length);
  if (!f) throw Error(ErrorCode::Io, path + ": NPY header cut short");
  return header;
}

template <typename T, typename Out>
void read_values(std::ifstream& f, size_t n, std::vector<Out>& out, const std::string& path) {
  std::vector<T> raw(n);
  f.read(reinterpret_cast<char*>(raw.data()), static_cast<std::streamsize>(n * sizeof(T)));
  if (!f) throw Error(ErrorCode::Io, path + ": NPY data cut short (" + std::to_string(n) + " values expected)");
  out.assign(raw.begin(), raw.end());
}

void write_array(const std::string& path, const char* descr, const void* data, size_t bytes, long rows, long cols) {
  std::string shape =
      cols > 0 ? "(" + std::to_string(rows) + ", " + std::to_string(cols) + ")" : "(" + std::to_string(rows) + ",)";
  std::string header = std::string("{'descr': '") + descr + "', 'fortran_order': False, 'shape': " + shape + ", }";
  const size_t preamble = 10;  // magic, version, 2-byte length
  header.append((64 - (preamble + header.size() + 1) % 64) % 64, ' ');
  header += '\n';
  std::ofstream f(path, std::ios::binary);
  if (!f) throw Error(ErrorCode::Io, "cannot write " + path);
  const uint16_t length = static_cast<uint16_t>(header.size());
  const char version[2] = {1, 0};
  const char len[2] = {static_cast<char>(length & 0xff), static_cast<char>(length >> 8)};
  f.write(kMagic, 6).write(version, 2).write(len, 2).write(header.data(), static_cast<std::streamsize>(header.size()));
  f.write(static_cast<const char*>(data), static_cast<std::streamsize>(bytes));
  if (!f) throw Error(ErrorCode::Io, "error while writing " + path + " (disk full?)");
}

std::string shape_text(const NpyArray& a) {
  return a.shape.size() == 1 ? std::to_string(a.rows()) : std::to_string(a.rows()) + " x " + std::to_string(a.cols());
}

void check_columns(const NpyArray& a, long cols, const std::string& what) {
  if (cols >= 0 && a.cols() != cols)
    throw Error(ErrorCode::InvalidParameter,
                what + ": " + std::to_string(cols) + " columns expected, the array is " + shape_text(a));
}

}  // namespace

NpyArray read_npy(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw Error(ErrorCode::Io, "file not found: " + path);
  const std::string header = read_header(f, path);
  const std::string descr = header_value(header, "descr", path);
  if (header_value(header, "fortran_order", path) != "False")
    throw Error(ErrorCode::Io, path + ": Fortran-ordered NPY arrays are not read; save a C-ordered copy");
  NpyArray a;
  a.shape = parse_shape(header_value(header, "shape", path), path);
  const size_t n = static_cast<size_t>(a.rows()) * static_cast<size_t>(a.cols());
  if (descr == "<f8")
    read_values<double>(f, n, a.real, path);
  else if (descr == "<f4")
    read_values<float>(f, n, a.real, path);
  else if (descr == "<i8")
    read_values<int64_t>(f, n, a.integer, path), a.is_integer = true;
  else if (descr == "<i4")
    read_values<int32_t>(f, n, a.integer, path), a.is_integer = true;
  else
    throw Error(ErrorCode::Io, path + ": NPY dtype '" + descr + "' is not read (float32/64 or int32/64 expected)");
  return a;
}

RowMatXd npy_real(const NpyArray& a, long cols, const std::string& what) {
  check_columns(a, cols, what);
  RowMatXd m(a.rows(), a.cols());
  for (size_t i = 0; i < static_cast<size_t>(m.size()); ++i) {
    const double v = a.is_integer ? static_cast<double>(a.integer[i]) : a.real[i];
    if (!std::isfinite(v))
      throw Error(ErrorCode::InvalidParameter,
                  what + ": value " + std::to_string(i) + " is not a finite number (NaN or infinite)");
    m.data()[i] = v;
  }
  return m;
}

RowMatXl npy_integer(const NpyArray& a, long cols, const std::string& what) {
  check_columns(a, cols, what);
  if (!a.is_integer) throw Error(ErrorCode::InvalidParameter, what + ": integers expected, the array holds floats");
  RowMatXl m(a.rows(), a.cols());
  std::copy(a.integer.begin(), a.integer.end(), m.data());
  return m;
}

void write_npy(const std::string& path, const double* data, long rows, long cols) {
  write_array(path, "<f8", data, sizeof(double) * rows * std::max(1L, cols), rows, cols);
}

void write_npy(const std::string& path, const int* data, long rows, long cols) {
  static_assert(sizeof(int) == 4, "NPY '<i4' is written from int");
  write_array(path, "<i4", data, sizeof(int) * rows * std::max(1L, cols), rows, cols);
}

}  // namespace topopt::io
