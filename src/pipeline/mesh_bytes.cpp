// TetMesh to bytes and back (see mesh_bytes.h): a tag, then each array as rows, columns and
// its row-major values.
#include "pipeline/mesh_bytes.h"

#include <cstdint>
#include <cstring>

#include "common/error.h"

namespace topopt::pipeline {
namespace {

constexpr char kTag[8] = {'T', 'O', 'P', 'M', 'E', 'S', 'H', '1'};

template <class Matrix>
void put(std::string& out, const Matrix& a) {
  const std::int64_t shape[2] = {static_cast<std::int64_t>(a.rows()), static_cast<std::int64_t>(a.cols())};
  out.append(reinterpret_cast<const char*>(shape), sizeof shape);
  out.append(reinterpret_cast<const char*>(a.data()), sizeof(typename Matrix::Scalar) * a.size());
}

/// Reads the bytes of one array from `at` on, checking that they are all there.
class Reader {
 public:
  explicit Reader(const std::string& bytes) : bytes_(bytes) {}
  void take(void* to, size_t n) {
    if (n > bytes_.size() - at_) throw Error(ErrorCode::Internal, "a mesh passed between processes was cut short");
    std::memcpy(to, bytes_.data() + at_, n);
    at_ += n;
  }
  template <class Matrix>
  void get(Matrix& a) {
    std::int64_t shape[2];
    take(shape, sizeof shape);
    const bool fixed_cols = Matrix::ColsAtCompileTime != Eigen::Dynamic;
    if (shape[0] < 0 || shape[1] < 0 || (fixed_cols && shape[1] != Matrix::ColsAtCompileTime) ||
        shape[0] * shape[1] > static_cast<std::int64_t>(bytes_.size()))
      throw Error(ErrorCode::Internal, "a mesh passed between processes is malformed");
    a.resize(shape[0], shape[1]);
    take(a.data(), sizeof(typename Matrix::Scalar) * a.size());
  }
  bool done() const { return at_ == bytes_.size(); }

 private:
  const std::string& bytes_;
  size_t at_ = 0;
};

}  // namespace

std::string mesh_to_bytes(const TetMesh& m) {
  std::string out(kTag, sizeof kTag);
  put(out, m.V);
  put(out, m.T);
  put(out, m.domain);
  put(out, m.F);
  put(out, m.face);
  put(out, m.nd_face);
  return out;
}

TetMesh mesh_from_bytes(const std::string& bytes) {
  Reader in(bytes);
  char tag[sizeof kTag];
  in.take(tag, sizeof tag);
  if (std::memcmp(tag, kTag, sizeof kTag) != 0)
    throw Error(ErrorCode::Internal, "bytes passed between processes are not a mesh");
  TetMesh m;
  in.get(m.V);
  in.get(m.T);
  in.get(m.domain);
  in.get(m.F);
  in.get(m.face);
  in.get(m.nd_face);
  if (!in.done()) throw Error(ErrorCode::Internal, "a mesh passed between processes has bytes left over");
  return m;
}

}  // namespace topopt::pipeline
